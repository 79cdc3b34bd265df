"""JCAMP-DX: the compressed forms (SQZ, DIF, DUP, PAC) decoded against hand-encoded values and
the ``jcamp`` package, LINK files, the XYPOINTS table, units, and refusal of corrupt counts.

Real files come from ../shared/real-exports through the ``real_exports`` fixture (skipped
when absent); every spot value is quoted from the file line it was checked against. The
synthetic files are built by the small writers here: each writes a valid file, and the
error tests break one thing at a time and check the AdapterError names the file and the
line (text) or byte offset (binary) and what was expected.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
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


def test_jcamp_link_file_five_pac_blocks(real_exports: Path, value_at, check_spectrum) -> None:
    m = read_jcamp(real_exports / "jcamp-dx" / "blckpac1.jdx")
    check_spectrum(m, "absorbance", 5 * 176, 350.0, 700.0)
    titles = [f"Aquation of trans-[Co(en)2Cl2]+ (t{k})" for k in range(1, 6)]
    assert list(m.data["sample"].unique()) == titles
    yfactor = 0.00000011920928955078  # "##YFACTOR= .00000011920928955078"
    # line 28: "  700.000000  -51473   -43386 ..."; line 63: "  350.000000  1622710"
    assert value_at(m, 700, titles[0]) == pytest.approx(-51473 * yfactor, rel=1e-15)
    assert value_at(m, 698, titles[0]) == pytest.approx(-43386 * yfactor, rel=1e-15)
    assert value_at(m, 350, titles[0]) == pytest.approx(1622710 * yfactor, rel=1e-15)
    # line 299: "  350.000000  1483643" (block 5)
    assert value_at(m, 350, titles[4]) == pytest.approx(1483643 * yfactor, rel=1e-15)
    assert m.meta["link"]["BLOCKS"] == "5" and len(m.meta["blocks"]) == 5


def test_jcamp_sqz_dif_dup_with_y_checks(real_exports: Path, value_at, check_spectrum) -> None:
    m = read_jcamp(real_exports / "jcamp-dx" / "dupinc1.jdx")
    check_spectrum(m, "absorbance", 440, 250.0, 469.5)
    # line 19 "2500A1663l68k60..." with XFACTOR .1, YFACTOR .0001: 1.1663, 1.1295, 1.1035
    assert value_at(m, 250.0) == pytest.approx(1.1663, rel=1e-12)
    assert value_at(m, 250.5) == pytest.approx(1.1295, rel=1e-12)
    assert value_at(m, 251.0) == pytest.approx(1.1035, rel=1e-12)
    # last line "4695A626" is the Y check of the point at 469.5 nm: 1626 * .0001
    assert value_at(m, 469.5) == pytest.approx(0.1626, rel=1e-12)


def test_jcamp_against_the_jcamp_package(real_exports: Path) -> None:
    jcamp = pytest.importorskip("jcamp")
    for name in ("blckpac1.jdx", "dupinc1.jdx"):
        ours = read_jcamp(real_exports / "jcamp-dx" / name).data
        read = getattr(jcamp, "jcamp_readfile", None) or jcamp.readfile
        theirs = read(str(real_exports / "jcamp-dx" / name))
        parts = theirs.get("children", [theirs])
        y = np.concatenate([np.asarray(p["y"], float) for p in parts])
        np.testing.assert_allclose(ours["value"], y, rtol=1e-12)


def jdx(
    table: str = "1A00JK%T\n5A03j\n6A02\n",
    *,
    extra: str = "",
    head: str = "##TITLE= t\n##JCAMP-DX= 4.24\n##DATA TYPE= UV/VIS SPECTRUM\n",
    npoints: str = "6",
    yunits: str = "ABSORBANCE",
    end: str = "##END=\n",
) -> bytes:
    return (
        head + f"##XUNITS= NANOMETERS\n##YUNITS= {yunits}\n##XFACTOR= 1\n##YFACTOR= 0.01\n"
        f"##FIRSTX= 1\n##LASTX= 6\n##NPOINTS= {npoints}\n{extra}"
        f"##XYDATA= (X++(Y..Y)) $$ comment\n{table}{end}"
    ).encode("ascii")


def test_jcamp_decodes_sqz_dif_dup_and_y_checks(tmp_path: Path, write) -> None:
    # 1A00 = 100; J +1; K +2; % +0; T repeats the last DIF twice in all -> 100 101 103 103 103
    # line 2: A03 is the Y check of 103, j -1 -> 102; line 3 "6A02" checks 102
    m = read_jcamp(write(tmp_path, "a.jdx", jdx()))
    assert list(m.data["value"]) == pytest.approx([1.0, 1.01, 1.03, 1.03, 1.03, 1.02])
    assert list(m.data["wavelength_nm"]) == [1, 2, 3, 4, 5, 6]


def test_jcamp_decodes_affn_pac_negative_sqz_and_missing(tmp_path: Path, write) -> None:
    table = "1 100+101-5\n4 a5 ? 7.5E+01\n"
    m = read_jcamp(write(tmp_path, "a.jdx", jdx(table, yunits="%T")))
    assert list(m.data["value"]) == pytest.approx([0.01, 0.0101, -0.0005, -0.0015, 0.0075])
    assert set(m.data["quantity"].astype(str)) == {"transmittance"}
    assert m.meta["dropped_points"] == 1


def test_jcamp_reflectance_with_sphere_record(tmp_path: Path, write) -> None:
    extra = "##SAMPLING PROCEDURE= integrating sphere, 8 deg\n"
    table = "1 10 11 12 13 14 15\n"
    m = read_jcamp(write(tmp_path, "a.jdx", jdx(table, yunits="REFLECTANCE", extra=extra)))
    assert set(m.data["quantity"].astype(str)) == {"hemispherical_reflectance"}


LINK = "##TITLE= outer\n##JCAMP-DX= 4.24\n##DATA TYPE= LINK\n##BLOCKS= 2\n"


@pytest.mark.parametrize(
    ("data", "match"),
    [
        (jdx("1A00JK%T\n5A04j\n6A02\n"), r"line 13: Y check value 104 differs from the last"),
        (jdx("1A00JK%T\n6A03j\n"), r"line 13: X checkpoint 6 does not match the abscissa 5"),
        (jdx("1 1 2 3 4 5\n"), r"line 12: NPOINTS is 6 but the table decodes to 5"),
        (jdx("1A00JK%T\n5A03j\n6A02\n", npoints="6.5"), r"NPOINTS '6.5': expected an integer"),
        (jdx(end=""), r"the block opened at line 1 has no ##END= \(truncated\?\)"),
        (jdx(end="##END=\nstray\n"), r"line 16: text after the last ##END="),
        (jdx(end="##END=\n##TITLE= again\n##END=\n"), r"line 16: a second top-level block"),
        (jdx(extra="##TITLE= inner\n"), r"line 11: ##TITLE= inside the block opened at line 1"),
        (jdx(extra="##XUNITS= NM\n"), r"line 11: label ##XUNITS= repeated in one block"),
        (jdx(extra="##DELTAX= 2\n"), r"DELTAX 2 disagrees with \(LASTX - FIRSTX\)"),
        (jdx(yunits="COUNTS"), r"YUNITS 'COUNTS': expected one of"),
        (jdx().replace(b"NANOMETERS", b"SECONDS"), r"line 4: XUNITS 'SECONDS': expected a wave"),
        (jdx().replace(b"(X++(Y..Y))", b"(XY..XY)"), r"only \(X\+\+\(Y..Y\)\) is supported"),
        (jdx().replace(b"##XYDATA", b"##PEAK TABLE"), r"block has no ##XYDATA= table"),
        (jdx().replace(b"##NPOINTS= 6\n", b""), r"block has no ##NPOINTS= record"),
        (jdx("1A00JK%T\n5A03j\n6A0~2\n"), r"line 14: character '~' at column 4 is not"),
        (jdx("1 K5\n"), r"line 12: DIF value 'K5' without a preceding ordinate"),
        (jdx("1 S\n"), r"line 12: DUP count 'S' without a value to repeat"),
        (jdx("J1 10\n"), r"line 12: a data line must start with its X value"),
        (jdx("1 1" + "9" * 400 + "\n"), r"line 12: value '1999.*overflows a float"),
        (b"##ORIGIN= x\n", r"line 1: record ##ORIGIN= before ##TITLE="),
        (b"hello\n", r"line 1: expected a '##LABEL=' record"),
        (b"##TITLE x\n", r"line 1: expected '##LABEL= value'"),
        (LINK.encode() + jdx(head="##TITLE= a\n") + b"##END=\n", r"line 1: ##BLOCKS= 2 but"),
        (LINK.replace("2", "0").encode() + b"##END=\n", r"line 1: LINK block without"),
    ],
)
def test_jcamp_errors(tmp_path: Path, data: bytes, match: str, write) -> None:
    p = write(tmp_path, "bad.jdx", data)
    with pytest.raises(AdapterError, match=match) as exc:
        read_jcamp(p)
    assert str(p) in str(exc.value)


def test_jcamp_link_with_two_blocks_and_label_spellings(tmp_path: Path, write) -> None:
    b1 = jdx(head="##TITLE= a\n##BLOCK_ID= 1\n", table="1 1 2 3 4 5 6\n")
    b2 = jdx(head="##TITLE= b\n##BLOCK-ID = 2\n", table="1 6 5 4 3 2 1\n")
    data = LINK.encode() + b1 + b2 + b"##END= $$ all\n"
    m = read_jcamp(write(tmp_path, "a.jdx", data))
    assert list(m.data["sample"].unique()) == ["a", "b"]
    assert m.meta["blocks"][1]["header"]["BLOCK-ID"] == "2"


def test_utf16_jcamp_text_is_refused_as_the_wrong_encoding(tmp_path: Path, write) -> None:
    p = write(tmp_path, "utf16.txt", jdx().decode("latin-1").encode("utf-16"))
    with pytest.raises(AdapterError, match=r"line 1: binary content \(NUL byte\)"):
        read_jcamp(p)


def test_jcamp_comment_record_and_continuation_lines(tmp_path: Path, write) -> None:
    extra = "##= a comment record\n##$NOTE= first\nsecond line of the note\n"
    m = read_jcamp(write(tmp_path, "a.jdx", jdx(extra=extra)))
    assert m.meta["blocks"][0]["header"]["$NOTE"] == "first\nsecond line of the note"


NESTED = LINK.replace("2", "1") + "##TITLE= inner link\n##DATA TYPE= LINK\n"


@pytest.mark.parametrize(
    ("data", "match"),
    [
        (b"$$ only a comment\n", r"no ##TITLE= record: not a JCAMP-DX file"),
        (jdx("1A00JK%T\n5\n"), r"line 13: expected the Y check value of the DIF line before"),
        (jdx().replace(b"##LASTX= 6", b"##LASTX= 1"), r"FIRSTX equals LASTX or XFACTOR is 0"),
        (jdx("1 A" + "9" * 307 + ("R" + "9" * 307) * 2 + "\n"), r"DIF accumulation overflows"),
        (NESTED.encode() + jdx(head="##TITLE= a\n") + b"##END=\n##END=\n", r"nested LINK"),
    ],
)
def test_jcamp_rarer_errors(tmp_path: Path, data: bytes, match: str, write) -> None:
    with pytest.raises(AdapterError, match=match):
        read_jcamp(write(tmp_path, "bad.jdx", data))
