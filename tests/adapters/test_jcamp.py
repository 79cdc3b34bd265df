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
