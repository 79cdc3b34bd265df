"""JCAMP-DX: hardening against corrupt counts, and the XYPOINTS table."""

from __future__ import annotations

from pathlib import Path

import pytest

from labbrdf.adapters import AdapterError
from labbrdf.adapters.jcamp import read_jcamp

JDX = "jcamp-dx"


def _dupinc(real_exports: Path) -> bytes:
    return (real_exports / JDX / "dupinc1.jdx").read_bytes()


def test_dup_count_past_npoints_is_refused_before_expansion(
    real_exports: Path, tmp_path: Path
) -> None:
    raw = _dupinc(real_exports)
    i = raw.index(b"Tk69")  # line 19: "2500A1663l68...j79Tk69j04..." (T = repeat twice)
    bad = tmp_path / "dup.jdx"
    bad.write_bytes(raw[: i + 1] + b"0000000" + raw[i + 1 :])  # T0000000: 2e7 repeats
    with pytest.raises(AdapterError, match=r"line 19: DUP count 'T0000000'.*NPOINTS"):
        read_jcamp(bad)


def test_npoints_above_the_hard_cap_is_refused(real_exports: Path, tmp_path: Path) -> None:
    raw = _dupinc(real_exports).replace(b"##NPOINTS=  440", b"##NPOINTS=  4000000000")
    bad = tmp_path / "npoints.jdx"
    bad.write_bytes(raw)
    with pytest.raises(AdapterError, match=r"NPOINTS = 4000000000 exceeds the limit"):
        read_jcamp(bad)


# ----------------------------------------------------------------------------- XYPOINTS


def _as_xypoints(real_exports: Path, *, pairs_per_line: int = 3) -> tuple[bytes, list[float]]:
    """dupinc1.jdx with its table rewritten as AFFN (XY..XY) pairs in file units."""
    ref = read_jcamp(real_exports / JDX / "dupinc1.jdx").data
    x = [round(v / 0.1) for v in ref["wavelength_nm"]]  # XFACTOR .1
    y = [round(v / 0.0001) for v in ref["value"]]  # YFACTOR .0001
    head = _dupinc(real_exports).split(b"##XYDATA=")[0].replace(b"##DELTAX=   .5\r\n", b"")
    rows = []
    k = pairs_per_line
    for i in range(0, len(x), k):
        rows.append(
            "; ".join(f"{a}, {b}" for a, b in zip(x[i : i + k], y[i : i + k], strict=True))
        )
    table = "##XYPOINTS= (XY..XY)\r\n" + "\r\n".join(rows) + "\r\n##END=\r\n"
    return head + table.encode("ascii"), list(ref["value"])


def test_xypoints_table_reads_the_same_spectrum_as_the_xydata_original(
    real_exports: Path, tmp_path: Path
) -> None:
    raw, values = _as_xypoints(real_exports)
    p = tmp_path / "points.jdx"
    p.write_bytes(raw)
    d = read_jcamp(p).data
    assert len(d) == 440
    assert list(d["value"]) == pytest.approx(values, rel=1e-12)
    assert d["wavelength_nm"].iloc[0] == pytest.approx(250.0, rel=1e-12)
    assert d["wavelength_nm"].iloc[-1] == pytest.approx(469.5, rel=1e-12)


def _points(table: str, npoints: str = "3") -> bytes:
    return (
        "##TITLE= t\n##JCAMP-DX= 4.24\n##DATA TYPE= UV/VIS SPECTRUM\n##XUNITS= NANOMETERS\n"
        "##YUNITS= ABSORBANCE\n##XFACTOR= 1\n##YFACTOR= 0.01\n##FIRSTX= 400\n##LASTX= 420\n"
        f"##NPOINTS= {npoints}\n##XYPOINTS= (XY..XY)\n{table}##END=\n"
    ).encode("ascii")


@pytest.mark.parametrize(
    ("data", "match"),
    [
        (_points("400, 10; 410, 20\n420, 30; 430, 40\n"), r"line 13: .*more than NPOINTS = 3"),
        (_points("400, 10; 410, 20\n"), r"line 12: NPOINTS is 3 but the table has 2 points"),
        (_points("400, 10; 410\n420, 30\n"), r"line 12: .*odd number of values"),
        (_points("400, 10; 410, 20; 410, 30\n"), r"line 12: X 410 .*not strictly monotonic"),
        (_points("400, 10; 410, 20; 421, 30\n"), r"line 12: LASTX 420 .*last X 421"),
        (_points("400, 10; 410, 2~0; 420, 30\n"), r"line 12: .*'2~0'"),
        (
            _points("400 10 410 20 420 30\n", npoints="3000000000"),
            r"line 10: NPOINTS = 3000000000",
        ),
        (
            _points("400, 10; 410, 20; 420, 30\n").replace(b"(XY..XY)", b"(XYW..XYW)"),
            r"line 11: ##XYPOINTS= '\(XYW..XYW\)': only \(XY..XY\)",
        ),
    ],
)
def test_xypoints_errors_name_the_line(tmp_path: Path, data: bytes, match: str) -> None:
    p = tmp_path / "bad.jdx"
    p.write_bytes(data)
    with pytest.raises(AdapterError, match=match):
        read_jcamp(p)


def test_xypoints_with_spaces_and_missing_y(tmp_path: Path) -> None:
    p = tmp_path / "ok.jdx"
    p.write_bytes(_points("400 10\n410 ?\n420 30\n"))
    m = read_jcamp(p)
    assert list(m.data["wavelength_nm"]) == [400.0, 420.0]
    assert list(m.data["value"]) == pytest.approx([0.1, 0.3], rel=1e-12)
    assert m.meta["dropped_points"] == 1


def test_unsupported_peak_table_is_refused_at_its_line(tmp_path: Path) -> None:
    p = tmp_path / "peaks.jdx"
    p.write_bytes(_points("400, 10\n").replace(b"##XYPOINTS= (XY..XY)", b"##PEAK TABLE= (XY..XY)"))
    with pytest.raises(AdapterError, match=r"line 11: .*##PEAK TABLE= is not supported"):
        read_jcamp(p)


# ----------------------------------------------------------------- units and end of file


def _xypoints(xunits: str, yunits: str, pairs: str = "10,1\n20,2\n", tail: str = "") -> bytes:
    return (
        f"##TITLE= t\n##JCAMP-DX= 5.01\n##XUNITS= {xunits}\n##YUNITS= {yunits}\n"
        f"##NPOINTS= 2\n##XYPOINTS= (XY..XY)\n{pairs}##END=\n{tail}"
    ).encode()


@pytest.mark.parametrize(
    ("xunits", "factor"),
    [
        ("Wavelength (nm)", 1.0),
        ("wavelength [nm]", 1.0),
        ("Nanometers", 1.0),
        ("Wavelength (µm)", 1000.0),
        ("MICRONS", 1000.0),
    ],
)
def test_spelled_out_wavelength_units_are_recognised(
    tmp_path: Path, xunits: str, factor: float
) -> None:
    p = tmp_path / "u.jdx"
    p.write_bytes(_xypoints(xunits, "ABSORBANCE"))
    m = read_jcamp(p)
    assert list(m.data["wavelength_nm"]) == [10 * factor, 20 * factor]


@pytest.mark.parametrize("xunits", ["1/CM", "Wavenumber (cm-1)", "cm-1"])
def test_wavenumbers_are_converted_to_wavelength(tmp_path: Path, xunits: str) -> None:
    """lambda [nm] = 1e7 / nu [1/cm]: 4000 1/cm is 2500 nm, 10000 1/cm is 1000 nm."""
    p = tmp_path / "ir.jdx"
    p.write_bytes(_xypoints(xunits, "TRANSMITTANCE", "4000,0.5\n10000,0.25\n"))
    m = read_jcamp(p)
    assert list(m.data["wavelength_nm"]) == pytest.approx([2500.0, 1000.0], rel=1e-15)
    assert list(m.data["value"]) == [0.5, 0.25]


def test_spelled_out_percent_transmittance_is_divided_by_100(tmp_path: Path) -> None:
    p = tmp_path / "t.jdx"
    p.write_bytes(_xypoints("NANOMETERS", "Transmittance (%)", "10,50\n20,25\n"))
    m = read_jcamp(p)
    assert m.quantities == ["transmittance"]
    assert list(m.data["value"]) == [0.5, 0.25]


@pytest.mark.parametrize(
    ("xunits", "yunits", "match"),
    [
        ("Time (s)", "ABSORBANCE", r"line 3: XUNITS 'Time \(s\)': expected a wavelength"),
        ("NANOMETERS", "Absorbance (%)", r"line 4: YUNITS 'Absorbance \(%\)': expected one of"),
        ("NANOMETERS", "COUNTS", r"line 4: YUNITS 'COUNTS'"),
    ],
)
def test_unknown_units_are_refused_at_their_line(
    tmp_path: Path, xunits: str, yunits: str, match: str
) -> None:
    p = tmp_path / "bad.jdx"
    p.write_bytes(_xypoints(xunits, yunits))
    with pytest.raises(AdapterError, match=match) as exc:
        read_jcamp(p)
    assert str(p) in str(exc.value)


def test_zero_wavenumber_is_refused(tmp_path: Path) -> None:
    p = tmp_path / "zero.jdx"
    p.write_bytes(_xypoints("1/CM", "ABSORBANCE", "0,1\n10,2\n"))
    with pytest.raises(AdapterError, match=r"line 6: a wavenumber \[1/cm\] <= 0"):
        read_jcamp(p)


@pytest.mark.parametrize("tail", ["\x1a", "\x1a\r\n", "\r\n\x1a"])
def test_dos_end_of_file_byte_after_end_is_accepted(tmp_path: Path, tail: str) -> None:
    p = tmp_path / "eof.jdx"
    p.write_bytes(_xypoints("NANOMETERS", "ABSORBANCE", tail=tail))
    assert len(read_jcamp(p)) == 2


def test_dos_end_of_file_byte_on_the_real_file(real_exports: Path, tmp_path: Path) -> None:
    p = tmp_path / "dupinc1.jdx"
    p.write_bytes(_dupinc(real_exports) + b"\x1a")
    assert read_jcamp(p).data.equals(read_jcamp(real_exports / JDX / "dupinc1.jdx").data)


@pytest.mark.parametrize(
    ("tail", "match"),
    [("\x1ajunk\n", r"line 10: text after the last ##END="), ("\x1a\x1a", r"line 10: text after")],
)
def test_text_or_two_eof_bytes_after_end_are_still_refused(
    tmp_path: Path, tail: str, match: str
) -> None:
    p = tmp_path / "tail.jdx"
    p.write_bytes(_xypoints("NANOMETERS", "ABSORBANCE", tail=tail))
    with pytest.raises(AdapterError, match=match):
        read_jcamp(p)
