"""labbrdf's own CSV layouts: specular scan and hemispherical-reflectance spectrum."""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
import pytest

import labbrdf
from labbrdf.adapters import AdapterError, AdapterWarning
from labbrdf.adapters.labbrdf_csv import read_hemispherical, read_specular_scan

SPEC = "# labbrdf specular-scan v1\n"
HEMI = "# labbrdf hemispherical-reflectance v1\n"


def write(tmp_path: Path, text: str, name: str = "scan.csv", encoding: str = "utf-8") -> Path:
    p = tmp_path / name
    p.write_bytes(text.encode(encoding))
    return p


def spec(rows: str = "632.8,45,43,12.5,0.4\n632.8,45,45,180.2,3.1\n", **keys: str) -> str:
    keys = {"sample": "Al mirror", "quantity": "brdf", **keys}
    head = "".join(f"# {k}: {v}\n" for k, v in keys.items() if v is not None)
    return SPEC + head + "wavelength_nm,theta_i_deg,theta_r_deg,value,sigma\n" + rows


def test_specular_scan_docstring_example(tmp_path: Path) -> None:
    text = (
        "\ufeff# labbrdf specular-scan v1,,,\r\n# sample: Al mirror M3\r\n"
        "# instrument: goniometer-A\r\n# quantity: brdf\r\n# unit: sr-1\r\n"
        "# notes: s-polarised source, 2 deg detector aperture\r\n# a free comment\r\n\r\n"
        "wavelength_nm,theta_i_deg,theta_r_deg,value,sigma\r\n"
        "632.8,45,43,12.5,0.4\r\n632.8,45,45,180.2,3.1,\r\n"
    )
    m = labbrdf.read(write(tmp_path, text))  # dispatch: .csv and the magic line
    d = m.data
    assert list(d["value"]) == [12.5, 180.2] and list(d["sigma"]) == [0.4, 3.1]
    assert list(d["theta_r_deg"]) == [43.0, 45.0] and (d["phi_r_deg"] == 180.0).all()
    assert (d["theta_i_deg"] == 45.0).all() and (d["unit"] == "sr-1").all()
    assert set(d["quantity"].astype(str)) == {"brdf"} and set(d["sample"]) == {"Al mirror M3"}
    assert set(d["instrument"]) == {"goniometer-A"}
    assert m.meta["header"] == {"notes": "s-polarised source, 2 deg detector aperture"}
    assert m.meta["comments"] == ["a free comment"]


def test_specular_scan_signed_in_plane_scan_is_converted(tmp_path: Path) -> None:
    rows = "500,30,-20,0.5,\n500,30,30,9.0,\n"
    m = read_specular_scan(write(tmp_path, spec(rows, quantity="specular_intensity", unit="%")))
    d = m.data
    assert list(d["theta_r_deg"]) == [20.0, 30.0] and list(d["phi_r_deg"]) == [0.0, 180.0]
    assert list(d["value"]) == [0.005, 0.09] and (d["unit"] == "1").all()
    assert d["sigma"].isna().all() and m.meta["signed_theta_r_converted"] == 1


def test_specular_scan_columns_in_any_order_with_phi(tmp_path: Path) -> None:
    text = SPEC + "# quantity: brdf\nVALUE,phi_r_deg,theta_r_deg,theta_i_deg,wavelength_nm\n"
    text += "3.5,90,10,20,550\n,180,20,20,550\nnan,180,30,20,550\n"
    m = read_specular_scan(write(tmp_path, text))
    d = m.data
    assert len(d) == 1 and m.meta["dropped_points"] == 2
    row = d.iloc[0]
    assert (row["value"], row["phi_r_deg"], row["theta_r_deg"]) == (3.5, 90.0, 10.0)
    assert (row["theta_i_deg"], row["wavelength_nm"]) == (20.0, 550.0)
    assert set(d["sample"]) == {"scan"}  # no '# sample:' -> the file stem


def test_hemispherical_percent_with_port_angle(tmp_path: Path) -> None:
    text = HEMI + "# sample: OSR tile 7\n# unit: %\n# theta_i_deg: 8\nwavelength_nm,value,sigma\n"
    text += "250,8.12,0.05\n255,8.30,\n"
    m = labbrdf.read(write(tmp_path, text))
    d = m.data
    assert list(d["value"]) == pytest.approx([0.0812, 0.083], rel=1e-15)
    assert d["sigma"].iloc[0] == pytest.approx(0.0005, rel=1e-15) and math.isnan(d["sigma"][1])
    assert (d["theta_i_deg"] == 8.0).all() and d["theta_r_deg"].isna().all()
    assert set(d["quantity"].astype(str)) == {"hemispherical_reflectance"}
    assert m.meta["theta_i_deg"] == 8.0 and m.meta["unit_in_file"] == "%"


def test_hemispherical_fraction_without_port_angle(tmp_path: Path) -> None:
    m = read_hemispherical(write(tmp_path, HEMI + "# unit: 1\nwavelength_nm,value\n400,0.9\n"))
    assert m.data["theta_i_deg"].isna().all() and list(m.data["value"]) == [0.9]


def test_dispatch_separates_the_two_layouts_and_cary(tmp_path: Path) -> None:
    from labbrdf.adapters import sniff

    a = write(tmp_path, spec(), "a.csv")
    b = write(tmp_path, HEMI + "# unit: 1\nwavelength_nm,value\n400,0.9\n", "b.csv")
    assert "labbrdf-specular-scan" in sniff(a) and "labbrdf-hemispherical-reflectance" in sniff(b)
    assert "labbrdf-hemispherical-reflectance" not in sniff(a)
    with pytest.raises(AdapterError, match=r"line 1: expected the first line '# labbrdf hemi"):
        labbrdf.read(a, format="labbrdf-hemispherical-reflectance")


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ("wavelength_nm,value\n", r"line 1: expected the first line '# labbrdf specular-scan v1'"),
        (SPEC.replace("v1", "v2") + "x\n", r"line 1: version v2 of the specular-scan layout"),
        (spec(quantity=None), r"'# quantity:' must be 'brdf' or 'specular_intensity'"),
        (spec(quantity="reflectance"), r"found 'reflectance'"),
        (spec(unit="%"), r"'# unit: %' does not fit brdf; use \['sr-1'\]"),
        (spec(sample="a", SAMPLE="b"), r"line 4: header key 'sample' given twice"),
        (SPEC + "# quantity: brdf\n", r"no column header line"),
        (spec(""), r"no data rows after the column header"),
        (spec().replace(",sigma", ",sigma,colour"), r"line 4: unknown column\(s\) \['colour'\]"),
        (spec().replace(",sigma", ",value"), r"line 4: column\(s\) \['value'\] given twice"),
        (spec().replace("theta_r_deg,", ""), r"line 4: missing column\(s\) \['theta_r_deg'\]"),
        (spec("632.8,45,43,12.5\n"), r"line 5: expected 5 cells .* found 4"),
        (spec("632.8,45,43,12.5,0.4,1,2\n"), r"line 5: expected 5 cells"),
        (spec("632.8,45,4x3,12.5,0.4\n"), r"line 5: theta_r_deg: expected a number, found '4x3'"),
        (spec("632.8,45,43,inf,0.4\n"), r"line 5: value: expected a number, found 'inf'"),
        (
            spec("1,45,43,1,0.4\n-632.8,45,43,1,0.4\n"),
            r"line 6: wavelength_nm -632.8: expected > 0",
        ),
        (spec("632.8,632.8,43,1,0.4\n"), r"line 5: theta_i_deg 632.8 is outside \[0, 90\]"),
        (spec("632.8,45,95,1,0.4\n"), r"line 5: theta_r_deg 95 is outside \[-90, 90\]"),
        (spec("632.8,45,43,1,-0.4\n"), r"line 5: sigma -0.4: expected >= 0"),
        (
            spec("1,4,4,1,360\n").replace("sigma", "phi_r_deg"),
            r"line 5: phi_r_deg 360 is outside \[0, 360\)",
        ),
        (spec("500,30,-20,0.5,180\n").replace("sigma", "phi_r_deg"), r"theta_r_deg -20 is out"),
        (spec(",45,43,1,0.4\n"), r"line 5: wavelength_nm: expected a number, found ''"),
        (spec(",,,,\n"), r"line 5|no data rows"),
        (spec("632.8,45,43,,\n"), r"no valid data points"),
    ],
)
def test_specular_scan_errors(tmp_path: Path, text: str, match: str) -> None:
    p = write(tmp_path, text)
    with pytest.raises(AdapterError, match=match) as exc:
        read_specular_scan(p)
    assert str(p) in str(exc.value)


@pytest.mark.parametrize(
    ("text", "match"),
    [
        (HEMI + "wavelength_nm,value\n400,0.9\n", r"missing '# unit:' header line"),
        (HEMI + "# unit: sr-1\nwavelength_nm,value\n400,0.9\n", r"'# unit: sr-1': expected one"),
        (HEMI + "# unit: 1\n# theta_i_deg: 95\nwavelength_nm,value\n1,1\n", r"outside \[0, 90\]"),
        (HEMI + "# unit: 1\n# theta_i_deg: eight\nwavelength_nm,value\n1,1\n", r"expected a num"),
        (
            HEMI + "# unit: 1\nvalue,theta_i_deg\n",
            r"line 3: unknown column\(s\) \['theta_i_deg'\]",
        ),
        (HEMI + "# unit: 1\nvalue\n0.9\n", r"line 3: missing column\(s\) \['wavelength_nm'\]"),
        (HEMI + "# unit: 1\nwavelength_nm,value\n0,0.9\n", r"line 4: wavelength_nm 0: expected"),
        (HEMI + "# unit: 1\nwavelength_nm,value,sigma\n4,1,-1\n", r"line 4: sigma -1: expected"),
    ],
)
def test_hemispherical_errors(tmp_path: Path, text: str, match: str) -> None:
    p = write(tmp_path, text)
    with pytest.raises(AdapterError, match=match) as exc:
        read_hemispherical(p)
    assert str(p) in str(exc.value)


def test_wrong_encoding_and_binary_are_refused(tmp_path: Path) -> None:
    text = HEMI + "# unit: 1\n# sample: Probe für Öl\nwavelength_nm,value\n400,0.9\n"
    with pytest.raises(AdapterError, match=r"line 3: byte 0xfc is not valid in utf-8"):
        read_hemispherical(write(tmp_path, text, encoding="latin-1"))
    with pytest.raises(AdapterError, match=r"binary content"):
        read_hemispherical(write(tmp_path, HEMI + "\x00\x01"))


def test_values_round_trip_exactly(tmp_path: Path) -> None:
    """Numbers written with repr() come back bit-identical (no unit scaling for brdf)."""
    rng = np.random.default_rng(3)
    v = rng.lognormal(size=50)
    rows = "".join(
        f"550,10,{float(t)!r},{float(x)!r},\n"
        for t, x in zip(np.linspace(0, 80, 50), v, strict=True)
    )
    m = read_specular_scan(write(tmp_path, spec(rows)))
    np.testing.assert_array_equal(m.data["value"].to_numpy(), v)


def test_trailing_header_comma_missing_value_and_overflow(tmp_path: Path) -> None:
    text = HEMI + "# unit: 1\nwavelength_nm,value,\n400,0.9\n410,\n"
    m = read_hemispherical(write(tmp_path, text))
    assert len(m) == 1 and m.meta["dropped_points"] == 1
    text = HEMI + "# unit: 1\nwavelength_nm,value\n400,1e999\n"
    with pytest.raises(AdapterError, match=r"line 4: value: '1e999' overflows a float"):
        read_hemispherical(write(tmp_path, text))


# ------------------------------------------------------------------ a file cut short

#: six rows whose sigma is written with 2 decimals (a column with a precision of its own)
_ROWS = "".join(f"632.8,45,{t},{10 + t}.5,0.{t}1\n" for t in range(40, 46))


@pytest.mark.parametrize(
    ("tail", "match"),
    [
        ("632.8,45,46,56.5,0.", r"field 5 '0\.' on the last line, .* ends without its digits"),
        ("632.8,45,46,56.5,0.4", r"field 5 '0\.4' .* has 1 decimal where every other row"),
        (
            "632.8,45,46,56.5,",
            r"the last line, .* stops after 4 field\(s\) where every other row has at least 5",
        ),
    ],
)
def test_specular_scan_cut_in_its_last_row_is_refused(
    tmp_path: Path, tail: str, match: str
) -> None:
    """A copy stopped mid-number gave sigma 0 or 0.4 for 0.41, or no sigma at all."""
    p = write(tmp_path, spec(_ROWS + tail))
    line = len(spec(_ROWS + tail).splitlines())
    with pytest.raises(AdapterError, match=rf"scan.csv, line {line}: {match}"):
        read_specular_scan(p)


def test_hemispherical_last_value_written_shorter_is_warned_about(tmp_path: Path) -> None:
    """Values written with 1 to 3 decimals: a shorter last one may be real, so a warning
    naming the line, kept in the metadata; with its line end the row is complete."""
    rows = "300,8.12\n305,8.3\n310,8.475\n315,8.5\n320,8.6"
    text = HEMI + "# unit: %\nwavelength_nm,value\n" + rows
    with pytest.warns(AdapterWarning, match=r"scan.csv, line 8: field 2 '8\.6' .* shorter"):
        m = read_hemispherical(write(tmp_path, text))
    assert len(m) == 5 and "line 8" in m.meta["warnings"][0]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        m = read_hemispherical(write(tmp_path, text + "\n"))
    assert "warnings" not in m.meta
