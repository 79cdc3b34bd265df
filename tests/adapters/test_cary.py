"""Agilent Cary WinUV CSV exports: one sample and eleven ragged samples of mixed modes,
missing values and sphere, and the errors of bad input.

Real files come from ../shared/real-exports through the ``real_exports`` fixture (skipped
when absent); every spot value is quoted from the file line it was checked against. The
synthetic files are built by the small writers here: each writes a valid file, and the
error tests break one thing at a time and check the AdapterError names the file and the
line (text) or byte offset (binary) and what was expected.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import pytest

import labbrdf
from labbrdf.adapters import AdapterError, AdapterWarning
from labbrdf.adapters.cary import read_cary_csv

FIXTURES = Path(labbrdf.__file__).parent / "data" / "fixtures"


def test_cary_single_sample(real_exports: Path, value_at, check_spectrum) -> None:
    m = read_cary_csv(real_exports / "agilent-cary-winuv-csv" / "CuPCtS_H2O_vis.csv")
    check_spectrum(m, "absorbance", 141, 200.0188751, 899.9957886)
    assert value_at(m, 899.9957886) == 0.03348613903  # line 3: "899.9957886,0.03348613903,"
    assert value_at(m, 200.0188751) == 0.6591586471  # line 143: "200.0188751,0.6591586471,"
    (s,) = m.meta["samples"]
    assert s["name"] == "sample1" and s["collection_time"] == "2014-01-15T16:59:54"
    assert s["parameters"]["Instrument"] == "Cary 50"
    assert s["parameters"]["UV-Vis Data Interval (nm)"] == "5.00"


FILTER_POINTS = {
    "600LP": 121,
    "600LP1": 196,  # scan stopped at 455 nm of 450 ("<Current Wavelength> , 455.0")
    "600LP2": 301,
    "550LP": 301,
    "600SP800N": 301,
    "600SP800N1": 301,
    "530SP": 301,
    "GSBS": 301,
    "550LP2": 301,
    "530SP2": 401,
    "530SP_HI": 101,
}


def test_cary_eleven_samples_ragged_mixed_modes(real_exports: Path, value_at) -> None:
    m = read_cary_csv(real_exports / "agilent-cary-winuv-csv" / "filters.csv")
    d = m.data
    assert d.groupby("sample", sort=False).size().to_dict() == FILTER_POINTS
    q = d.groupby("sample", sort=False)["quantity"].first().astype(str)
    assert q["600LP"] == "absorbance" and (q.drop("600LP") == "transmittance").all()
    # line 3: "800.0541382,0.02885507233,650.0537109,93.92353058,..."
    assert value_at(m, 800.0541382, "600LP") == 0.02885507233
    assert value_at(m, 650.0537109, "600LP1") == pytest.approx(0.9392353058, rel=1e-15)
    meta = {s["name"]: s for s in m.meta["samples"]}
    assert meta["600LP1"]["padding_rows"] == 401 - 196  # the longest column has 401 rows
    assert meta["600LP"]["collection_time"] == "2018-05-10T17:14:12"  # line 407
    assert meta["530SP_HI"]["collection_time"] == "2018-05-10T17:26:59"  # line 803
    assert m.meta["dropped_points"] == 0
    assert d["wavelength_nm"].min() == pytest.approx(199.9654236)


def cary_block(name: str, interval: str = "1.00") -> str:
    return (
        f"{name},\r\n{name}\r\nCollection Time: 5/10/2018 5:14:12 PM\r\n"
        "Parameter List :\r\nInstrument                        Cary 50\r\n"
        f"UV-Vis Data Interval (nm)         {interval}\r\n"
        "Accessory                         DRA-2500\r\nMethod Log     :\r\n"
        "Y mode Changed: 5/10/2018 5:17:29 PM, Old:Abs, New:%T\r\n"
        "<Current Wavelength> , 455.0\r\n"
    )


def cary(
    rows: str = "500.1,50,500.0,1.5,\r\n499.0,51,,,\r\n498.1,,,,\r\n",
    *,
    modes: str = "%R,Wavelength (nm),Abs",
    blocks: str | None = None,
) -> bytes:
    head = f"S1,,S2,,\r\nWavelength (nm),{modes},\r\n"
    if blocks is None:
        blocks = cary_block("S1") + "\r\n" + cary_block("S2")
    return (head + rows + "\r\n" + blocks).encode("ascii")


def test_cary_ragged_missing_and_sphere(tmp_path: Path, write) -> None:
    m = read_cary_csv(write(tmp_path, "a.csv", cary()))
    s1 = m.data[m.data["sample"] == "S1"]
    assert list(s1["value"]) == [0.5, 0.51]  # 498.1 has no y: dropped and counted
    assert set(s1["quantity"].astype(str)) == {"hemispherical_reflectance"}  # DRA
    s2 = m.data[m.data["sample"] == "S2"]
    assert list(s2["value"]) == [1.5] and set(s2["quantity"].astype(str)) == {"absorbance"}
    assert m.meta["dropped_points"] == 1
    meta = {s["name"]: s for s in m.meta["samples"]}
    assert meta["S1"]["missing_points"] == 1 and meta["S2"]["padding_rows"] == 2
    assert meta["S1"]["collection_time"] == "2018-05-10T17:14:12"
    assert meta["S2"]["method_changes"] == [
        "Y mode Changed: 5/10/2018 5:17:29 PM, Old:Abs, New:%T"
    ]


@pytest.mark.parametrize(
    ("data", "match"),
    [
        (b"S1,,\r\nWavelength (nm),%T,\r\n", r"expected sample names, column titles and data"),
        (b"S1,,\r\n%T,Wavelength (nm),\r\n1,2,\r\n", r"line 2: row 2, column 1: expected"),
        (cary(modes="%R,Wavenumber (cm-1),Abs"), r"line 2: row 2, column 3: expected 'Wave"),
        (cary(modes="%R,Wavelength (nm),Counts"), r"line 2: row 2, column 4: Y mode 'Counts'"),
        (
            cary(modes="%R,Wavelength (nm)"),
            r"line 2: row 2: expected .Wavelength",
        ),
        (cary().replace(b"S1,,S2,,", b"S1,,S2,x,"), r"line 1: row 1: expected a sample name"),
        (cary().replace(b"S1,,S2,,", b"S1,,"), r"line 1: row 1: expected 2 sample names"),
        (cary("500.1,50,500.0,1.5,1,\r\n"), r"line 3: expected 4 cells"),
        (cary("500.1,5x,500.0,1.5,\r\n"), r"line 3: S1 %R: expected a number"),
        (cary(",nan,500.0,1.5,\r\n"), r"line 3: S1 %R: expected a number, found 'nan'"),
        (cary(""), r"line 3: no data rows after the column titles"),
        (cary().split(b"\r\n\r\n")[0], r"line 5: the data are not followed by a blank line"),
        (cary(blocks=cary_block("S1")), r"line 6: the 1 metadata blocks after the data"),
        (cary("500.1,50,500.0,1.5,\r\n498.0,51,,,\r\n"), r"line 4: sample 'S1': wavelength"),
        (cary("500.1,50,500.0,1.5,\r\n500.1,51,,,\r\n"), r"line 4: sample 'S1': wavelength"),
        (cary("500.1,50,500.0,1.5,\r\n499.1,51,,,\r\n500.1,51,,,\r\n"), r"line 5: sample 'S1'"),
    ],
)
def test_cary_errors(tmp_path: Path, data: bytes, match: str, write) -> None:
    p = write(tmp_path, "bad.csv", data)
    with pytest.raises(AdapterError, match=match) as exc:
        read_cary_csv(p)
    assert str(p) in str(exc.value)


def test_cary_without_metadata_blocks_skips_the_step_check(tmp_path: Path, write) -> None:
    p = write(tmp_path, "a.csv", cary("500.1,50,500.0,1.5,\r\n", blocks=""))
    with pytest.warns(AdapterWarning, match=r"a.csv, line 4: the data end without the metadata"):
        m = read_cary_csv(p)
    assert len(m.data) == 2 and "parameters" not in m.meta["samples"][0]
    assert "'S1'" in m.meta["warnings"][0] and "specular 'reflectance'" in m.meta["warnings"][0]


def test_cary_without_metadata_blocks_and_no_r_sample_reads_without_a_doubt(
    tmp_path: Path, write
) -> None:
    p = write(
        tmp_path,
        "a.csv",
        cary("500.1,50,500.0,1.5,\r\n", modes="%T,Wavelength (nm),Abs", blocks=""),
    )
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        m = read_cary_csv(p)
    assert "warnings" not in m.meta


def test_cary_sphere_fixture_cut_inside_its_footer_is_refused(tmp_path: Path) -> None:
    """Cut before the parameter that names the DRA sphere, the %R sample would read as
    specular reflectance: every cut inside the footer is refused naming the last line."""
    raw = (FIXTURES / "spectrophotometer" / "osr_sphere_cary.csv").read_bytes()
    start = raw.index(b"\r\n\r\n") + 4  # the first metadata block
    p = tmp_path / "cut.csv"
    for cut in range(start + 1, len(raw) - 3):  # up to "360.0" before its CR LF
        p.write_bytes(raw[:cut])
        line = len(raw[:cut].decode("ascii").splitlines())
        with pytest.raises(AdapterError, match=rf"cut.csv, line {line}: ") as exc:
            read_cary_csv(p)
        assert "truncated" in str(exc.value), cut
    p.write_bytes(raw[: len(raw) - 2])  # only the trailing blank line missing: complete
    m = read_cary_csv(p)
    assert set(m.data["quantity"].astype(str)) == {"hemispherical_reflectance"}


@pytest.mark.parametrize(
    ("cut", "match"),
    [
        ("Accessory ", r"line 24: the metadata block of sample .S2. ends without its .<Cur"),
        ("<Current Wavelength> , 45", r"line 27: the last line .* has no line end"),
    ],
)
def test_cary_last_block_cut_short_is_refused(tmp_path: Path, write, cut: str, match: str) -> None:
    raw = cary()
    p = write(tmp_path, "a.csv", raw[: raw.rindex(cut.encode()) + len(cut)])
    with pytest.raises(AdapterError, match=match):
        read_cary_csv(p)


def test_utf16_cary_text_is_refused_as_the_wrong_encoding(tmp_path: Path, write) -> None:
    p = write(tmp_path, "utf16.txt", cary().decode("latin-1").encode("utf-16"))
    with pytest.raises(AdapterError, match=r"line 1: binary content \(NUL byte\)"):
        read_cary_csv(p)


def test_cary_unusable_interval_and_time_are_kept_raw(tmp_path: Path, write) -> None:
    blocks = cary_block("S1", "n/a").replace("5/10/2018 5:14:12 PM", "yesterday")
    blocks += "\r\n" + cary_block("S2", "0")
    m = read_cary_csv(
        write(tmp_path, "a.csv", cary("500,50,500,1,\r\n400,51,400,2,\r\n", blocks=blocks))
    )
    s1 = m.meta["samples"][0]
    assert s1["collection_time"] is None and s1["collection_time_raw"] == "yesterday"
    assert len(m) == 4  # no step check without a usable interval (100 nm steps pass)
