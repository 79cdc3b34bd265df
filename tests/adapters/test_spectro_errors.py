"""Synthetic files for every parse and error path of the spectrophotometer adapters.

Each builder writes a small valid file; the tests break one thing at a time and check the
AdapterError names the file and the line (text) or byte offset (binary) and what was
expected. Decoding of the compressed JCAMP forms and of the SPC variants is checked on
hand-encoded values.
"""

from __future__ import annotations

import struct
from pathlib import Path

import numpy as np
import pytest

from labbrdf.adapters import AdapterError
from labbrdf.adapters.cary import read_cary_csv
from labbrdf.adapters.jasco import read_jasco_jws, read_jasco_text
from labbrdf.adapters.jcamp import read_jcamp
from labbrdf.adapters.perkinelmer import read_perkinelmer_asc
from labbrdf.adapters.spc import read_spc

# ------------------------------------------------------------------ JASCO text


def jasco_text(
    rows: str = "700\t50.0\r\n695\t51.0\r\n690\t52.0\r\n",
    *,
    yunits: str = "%R",
    xunits: str = "NANOMETERS",
    npoints: str = "3",
    footer: str = "",
) -> bytes:
    head = (
        "TITLE\tmy title\r\nORIGIN\tJASCO\r\nDELTAX\t-5\r\n"
        f"XUNITS\t{xunits}\r\nYUNITS\t{yunits}\r\nFIRSTX\t700\r\nLASTX\t690\r\n"
        f"NPOINTS\t{npoints}\r\nXYDATA\r\n"
    )
    return (head + rows).encode("ascii") + footer.encode("cp932")


def write(tmp_path: Path, name: str, data: bytes) -> Path:
    p = tmp_path / name
    p.write_bytes(data)
    return p


def test_jasco_text_percent_reflectance_and_title(tmp_path: Path) -> None:
    m = read_jasco_text(write(tmp_path, "a.txt", jasco_text()))
    assert list(m.data["value"]) == [0.5, 0.51, 0.52]
    assert set(m.data["quantity"].astype(str)) == {"reflectance"}
    assert set(m.data["sample"]) == {"my title"}


def test_jasco_text_sphere_accessory_gives_hemispherical(tmp_path: Path) -> None:
    footer = "\r\n\r\n[コメント情報]\r\n試料名\tOSR-1\r\n[付属品情報]\r\n付属品名\tISV-922\r\n"
    m = read_jasco_text(write(tmp_path, "a.txt", jasco_text(footer=footer)))
    assert set(m.data["quantity"].astype(str)) == {"hemispherical_reflectance"}
    assert set(m.data["sample"]) == {"OSR-1"} and m.meta["encoding"] == "cp932"


def test_jasco_text_comma_separated_transmittance(tmp_path: Path) -> None:
    data = jasco_text(yunits="TRANSMITTANCE").replace(b"\t", b",").replace(b"XYDATA", b"XYDATA,")
    m = read_jasco_text(write(tmp_path, "a.csv", data))
    assert set(m.data["quantity"].astype(str)) == {"transmittance"}
    assert list(m.data["value"]) == [0.5, 0.51, 0.52]


def test_jasco_text_footer_right_after_the_data(tmp_path: Path) -> None:
    footer = "[コメント情報]\r\n試料名\tS\r\n"
    m = read_jasco_text(write(tmp_path, "a.txt", jasco_text(footer=footer)))
    assert len(m) == 3 and set(m.data["sample"]) == {"S"}


@pytest.mark.parametrize(
    ("data", "match"),
    [
        (b"TITLE\tx\r\nXUNITS\tNANOMETERS\r\n", r"no 'XYDATA' line"),
        (b"HELLO\r\n", r"line 1: expected a JASCO text export"),
        (jasco_text(xunits="1/CM"), r"XUNITS '1/CM': only wavelength in NANOMETERS"),
        (jasco_text(yunits="INTENSITY"), r"YUNITS 'INTENSITY' is not one of"),
        (jasco_text(npoints="4"), r"line 12: NPOINTS says 4 but the data has 3 rows"),
        (jasco_text("700\t50.0\r\n695\tx1\r\n"), r"line 11: Y: expected a number, found 'x1'"),
        (jasco_text("700\t50.0\t1\r\n"), r"line 10: expected 2 cells"),
        (jasco_text("700\t50\r\n690\t51\r\n685\t52\r\n"), r"line 11: X 690.0 is not on the"),
        (jasco_text("700\t50\r\n695\t51\r\n690\t52\r\n\r\njunk\r\n"), r"line 14: unexpected"),
        (jasco_text(""), r"line 9: no data rows after XYDATA"),
        (b"TITLE\tx\r\nNOSEPARATOR\r\nXYDATA\r\n", r"line 2: expected 'KEY"),
        (
            jasco_text() + b"\r\n\r\n[\x81\x5c]\r\n\x85\x40\r\n",
            r"line 16: byte 0x85 is not valid",
        ),
        (jasco_text().replace(b"695", b"6\x0095"), r"binary content \(NUL byte\)"),
    ],
)
def test_jasco_text_errors(tmp_path: Path, data: bytes, match: str) -> None:
    p = write(tmp_path, "bad.txt", data)
    with pytest.raises(AdapterError, match=match) as exc:
        read_jasco_text(p)
    assert str(p) in str(exc.value)


# ------------------------------------------------------------------ JASCO .jws


def jws(
    y: list[float] | np.ndarray = (50.0, 51.0, 52.0),
    *,
    npoints: int | None = None,
    block: int | None = None,
    ymode: int = 0,
    xcode: int = 3,
    firstx: float = 700.0,
    deltax: float = -5.0,
    accessory: bytes = b"USE-753",
    extra: int = 0,
) -> bytes:
    y = np.asarray(y, dtype="<f4")
    n = len(y) if npoints is None else npoints
    h = bytearray(0x740)
    h[0:4] = b"L~S "
    h[8:15] = b"SPECMAN"
    struct.pack_into("<i3d", h, 0x84, n, firstx, firstx + deltax * (n - 1), deltax)
    h[0xA0], h[0xA4] = xcode, ymode
    struct.pack_into("<q", h, 0xC8, 4 * n if block is None else block)
    h[0x140:0x145] = b"V-730"
    h[0x180:0x186] = b"sample"
    h[0x484 : 0x484 + len(accessory)] = accessory
    struct.pack_into("<I", h, 0x2C0, 1_780_556_881)
    return bytes(h) + y.tobytes() + b"\x00" * extra


def test_jws_modes_and_invalid_marker(tmp_path: Path) -> None:
    invalid = np.frombuffer(struct.pack("<I", 0x80800000), "<f4")[0]  # -FLT_MIN
    m = read_jasco_jws(write(tmp_path, "a.jws", jws([10.0, invalid, np.nan, 20.0], ymode=3)))
    assert list(m.data["value"]) == [10.0, 20.0]
    assert list(m.data["wavelength_nm"]) == [700.0, 685.0]
    assert m.meta["dropped_points"] == 2 and m.meta["invalid_marker_points"] == 1
    assert set(m.data["quantity"].astype(str)) == {"absorbance"}
    m = read_jasco_jws(write(tmp_path, "b.jws", jws(ymode=2, accessory=b"ISN-923")))
    assert set(m.data["quantity"].astype(str)) == {"hemispherical_reflectance"}
    assert list(m.data["value"]) == [0.5, 0.51, 0.52]


@pytest.mark.parametrize(
    ("data", "match"),
    [
        (
            b"\xd0\xcf\x11\xe0\xa1\xb1\x1a\xe1" + b"\x00" * 600,
            r"Spectra Manager 1.x .jws: the OLE2 container is corrupt or truncated",
        ),
        (b"MZ" + b"\x00" * 2000, r"byte 0: expected the JASCO magic"),
        (jws()[:0x500], r"byte 1280: file is 1280 bytes, shorter than the 1856-byte header"),
        (jws()[:-1], r"byte 132: file is 1867 bytes but NPOINTS 3 needs 1868"),
        (jws(extra=4), r"byte 132: .*truncated or NPOINTS wrong"),
        (jws(block=8), r"byte 200: data-block length 8 bytes disagrees with NPOINTS 3"),
        (jws([], npoints=0), r"byte 132: NPOINTS 0: expected a positive count"),
        (jws(xcode=0), r"byte 160: x-unit code 0: only 3 \(nm\)"),
        (jws(ymode=9), r"byte 164: y-mode 9 is a single-beam intensity"),
        (jws(ymode=5), r"byte 164: unknown y-mode code 5"),
        (jws(deltax=0.0), r"byte 152: DELTAX 0.0"),
        (jws(firstx=-1.0), r"byte 136: FIRSTX -1.0"),
        (jws(firstx=10.0), r"byte 152: FIRSTX 10.0 \+ i \* DELTAX -5.0 reaches"),
        (jws([np.nan, np.nan]), r"no valid data points"),
    ],
)
def test_jws_errors(tmp_path: Path, data: bytes, match: str) -> None:
    p = write(tmp_path, "bad.jws", data)
    with pytest.raises(AdapterError, match=match) as exc:
        read_jasco_jws(p)
    assert str(p) in str(exc.value)


# ------------------------------------------------------------------ PerkinElmer


def pe(
    rows: str = "600.000000\t50.0\r\n590.000000\t51.0\r\n",
    *,
    accessory: str = "uv/vis/nir detector",
    gr: tuple[str, ...] = ("nm", "%R", "1.0", "0.0", "600.000000", "-10.000000", "2"),
) -> bytes:
    lines = ["PE UV       SUBTECH     SPECTRUM    ASCII       PEDS        4.00        "]
    lines += ["   -1", "MySample.Sample.Raw.asc", "24/02/27", "14:41:25.00"]
    lines += ["x"] * 19 + [accessory] + ["0"] * 5
    lines += ["#HDR", "-1", "-1", "#GR", *gr, "8", "52.0", "50.0", "#DATA"]
    return ("\r\n".join(lines) + "\r\n" + rows).encode("ascii")


def test_perkinelmer_reflectance_sphere_absorbance_scale(tmp_path: Path) -> None:
    m = read_perkinelmer_asc(write(tmp_path, "a.asc", pe()))
    assert set(m.data["quantity"].astype(str)) == {"reflectance"}
    assert list(m.data["value"]) == [0.5, 0.51] and set(m.data["sample"]) == {"MySample"}
    m = read_perkinelmer_asc(write(tmp_path, "b.asc", pe(accessory="150mm sphere / down")))
    assert set(m.data["quantity"].astype(str)) == {"hemispherical_reflectance"}
    gr = ("nm", "A", "2.0", "0.5", "600", "-10", "2")
    m = read_perkinelmer_asc(write(tmp_path, "c.asc", pe(gr=gr)))
    assert set(m.data["quantity"].astype(str)) == {"absorbance"}
    assert list(m.data["value"]) == [100.5, 102.5]  # y * scale + offset, no percent


@pytest.mark.parametrize(
    ("data", "match"),
    [
        (b"PE IR SPECTRUM\r\n", r"line 1: expected the magic 'PE UV SUBTECH"),
        (pe().replace(b"#GR", b"#GX"), r"no '#GR' line found"),
        (pe().replace(b"#DATA", b"#DAT"), r"no '#DATA' line found"),
        (pe(gr=("nm", "%R")), r"line 34: the #GR block has 5 lines"),
        (pe(gr=("%R", "nm", "1", "0", "600", "-10", "2")), r"line 35: x unit '%R'"),
        (pe(gr=("cm-1", "%R", "1", "0", "600", "-10", "2")), r"line 35: x unit 'cm-1'"),
        (pe(gr=("nm", "%Q", "1", "0", "600", "-10", "2")), r"line 36: y unit '%Q'"),
        (pe(gr=("nm", "%R", "1", "0", "600", "-10", "2.5")), r"NPOINTS '2.5': expected a"),
        (pe(gr=("nm", "%R", "1", "0", "600", "-10", "3")), r"NPOINTS is 3 but #DATA has 2"),
        (pe("600.000000\t50.0\t1\r\n"), r"line 46: expected 'x<TAB>y'"),
        (pe("600\t50\r\n580\t51\r\n"), r"line 47: X 580.0 is not on the FIRSTX"),
        (pe("600\t50\r\n590\tabc\r\n"), r"line 47: Y: expected a number"),
    ],
)
def test_perkinelmer_errors(tmp_path: Path, data: bytes, match: str) -> None:
    p = write(tmp_path, "bad.asc", data)
    with pytest.raises(AdapterError, match=match) as exc:
        read_perkinelmer_asc(p)
    assert str(p) in str(exc.value)


# ------------------------------------------------------------------ Cary


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


def test_cary_ragged_missing_and_sphere(tmp_path: Path) -> None:
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
def test_cary_errors(tmp_path: Path, data: bytes, match: str) -> None:
    p = write(tmp_path, "bad.csv", data)
    with pytest.raises(AdapterError, match=match) as exc:
        read_cary_csv(p)
    assert str(p) in str(exc.value)


def test_cary_without_metadata_blocks_skips_the_step_check(tmp_path: Path) -> None:
    m = read_cary_csv(write(tmp_path, "a.csv", cary("500.1,50,500.0,1.5,\r\n", blocks="")))
    assert len(m.data) == 2 and "parameters" not in m.meta["samples"][0]


# ------------------------------------------------------------------ JCAMP-DX


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


def test_jcamp_decodes_sqz_dif_dup_and_y_checks(tmp_path: Path) -> None:
    # 1A00 = 100; J +1; K +2; % +0; T repeats the last DIF twice in all -> 100 101 103 103 103
    # line 2: A03 is the Y check of 103, j -1 -> 102; line 3 "6A02" checks 102
    m = read_jcamp(write(tmp_path, "a.jdx", jdx()))
    assert list(m.data["value"]) == pytest.approx([1.0, 1.01, 1.03, 1.03, 1.03, 1.02])
    assert list(m.data["wavelength_nm"]) == [1, 2, 3, 4, 5, 6]


def test_jcamp_decodes_affn_pac_negative_sqz_and_missing(tmp_path: Path) -> None:
    table = "1 100+101-5\n4 a5 ? 7.5E+01\n"
    m = read_jcamp(write(tmp_path, "a.jdx", jdx(table, yunits="%T")))
    assert list(m.data["value"]) == pytest.approx([0.01, 0.0101, -0.0005, -0.0015, 0.0075])
    assert set(m.data["quantity"].astype(str)) == {"transmittance"}
    assert m.meta["dropped_points"] == 1


def test_jcamp_reflectance_with_sphere_record(tmp_path: Path) -> None:
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
def test_jcamp_errors(tmp_path: Path, data: bytes, match: str) -> None:
    p = write(tmp_path, "bad.jdx", data)
    with pytest.raises(AdapterError, match=match) as exc:
        read_jcamp(p)
    assert str(p) in str(exc.value)


def test_jcamp_link_with_two_blocks_and_label_spellings(tmp_path: Path) -> None:
    b1 = jdx(head="##TITLE= a\n##BLOCK_ID= 1\n", table="1 1 2 3 4 5 6\n")
    b2 = jdx(head="##TITLE= b\n##BLOCK-ID = 2\n", table="1 6 5 4 3 2 1\n")
    data = LINK.encode() + b1 + b2 + b"##END= $$ all\n"
    m = read_jcamp(write(tmp_path, "a.jdx", data))
    assert list(m.data["sample"].unique()) == ["a", "b"]
    assert m.meta["blocks"][1]["header"]["BLOCK-ID"] == "2"


# ------------------------------------------------------------------ SPC


def spc(
    y: np.ndarray | None = None,
    *,
    flags: int = 0,
    version: int = 0x4B,
    fexp: int = 16,
    xtype: int = 3,
    ytype: int = 2,
    nsub: int = 1,
    x: np.ndarray | None = None,
    tail: bytes = b"",
    logoff: int = 0,
    npts: int | None = None,
) -> bytes:
    y = np.array([65536, 131072, -65536], "<i4") if y is None else y
    n = len(y) if npts is None else npts
    h = bytearray(512)
    h[0], h[1] = flags, version
    struct.pack_into("<b", h, 3, fexp)
    struct.pack_into("<iddi", h, 4, n, 400.0, 500.0, nsub)
    h[28], h[29] = xtype, ytype
    struct.pack_into("<I", h, 32, (2001 << 20) | (2 << 16) | (3 << 11) | (4 << 6) | 5)
    h[88:92] = b"demo"
    struct.pack_into("<i", h, 248, logoff)
    body = b"" if x is None else np.asarray(x, "<f4").tobytes()
    for _ in range(nsub):
        sub = bytearray(32)
        struct.pack_into("<b", sub, 1, fexp)
        body += bytes(sub) + y.tobytes()
    return bytes(h) + body + tail


def test_spc_integer_float_16bit_explicit_x_and_multifile(tmp_path: Path) -> None:
    m = read_spc(write(tmp_path, "a.spc", spc()))  # int32 * 2**(16 - 32)
    assert list(m.data["value"]) == [1.0, 2.0, -1.0]
    assert list(m.data["wavelength_nm"]) == [400.0, 450.0, 500.0]
    assert m.meta["date"] == "2001-02-03T04:05:00" and set(m.data["sample"]) == {"demo"}
    m = read_spc(write(tmp_path, "b.spc", spc(np.array([0.5, np.nan], "<f4"), fexp=-128)))
    assert list(m.data["value"]) == [0.5] and m.meta["dropped_points"] == 1
    m = read_spc(write(tmp_path, "c.spc", spc(np.array([256, -512], "<i2"), flags=1, fexp=8)))
    assert list(m.data["value"]) == [1.0, -2.0]  # int16 * 2**(8 - 16)
    x = np.array([0.5, 0.6, 0.7])
    m = read_spc(write(tmp_path, "d.spc", spc(flags=0x80, x=x, xtype=2)))
    np.testing.assert_allclose(m.data["wavelength_nm"], np.float32(x) * 1000.0)
    m = read_spc(write(tmp_path, "e.spc", spc(flags=0x04, nsub=2)))
    assert list(m.data["sample"].unique()) == ["demo #0", "demo #1"] and len(m) == 6
    m = read_spc(write(tmp_path, "f.spc", spc(logoff=512 + 32 + 12, tail=b"LOG")))
    assert m.meta["log_offset"] == 556


@pytest.mark.parametrize(
    ("data", "match"),
    [
        (b"\x00K" + b"\x00" * 100, r"byte 102: file is 102 bytes, shorter than the 512"),
        (spc(version=0x4D), r"byte 1: old-format \(0x4D\) SPC files are not supported"),
        (spc(version=0x4C), r"byte 1: big-endian \(0x4C\) SPC files are not supported"),
        (spc(version=0x33), r"byte 1: version byte 0x33: expected 0x4B"),
        (spc(flags=0x40), r"byte 0: subfiles with their own X arrays \(TXYXYS\)"),
        (spc(npts=0), r"byte 4: fnpts 0: expected a positive point count"),
        (spc(flags=0x04, nsub=0), r"byte 24: fnsub 0: expected a positive number"),
        (spc(xtype=1), r"byte 28: x type 1: only nm \(3\) and micrometers \(2\)"),
        (spc(ytype=130), r"byte 29: y type 130 \(.*\): only absorbance \(2\)"),
        (spc()[:-1], r"byte 4: file is 555 bytes but 1 subfile\(s\) of 3 points need 556"),
        (spc(tail=b"xx"), r"byte 556: file is 558 bytes, expected 556"),
        (spc(logoff=100, tail=b"LOG"), r"byte 248: log block offset 100 is outside"),
        (spc(flags=0x80, x=np.array([1.0, -1.0, 2.0])), r"byte 8: the X axis has non-finite"),
    ],
)
def test_spc_errors(tmp_path: Path, data: bytes, match: str) -> None:
    p = write(tmp_path, "bad.spc", data)
    with pytest.raises(AdapterError, match=match) as exc:
        read_spc(p)
    assert str(p) in str(exc.value)


def test_spc_subheader_point_count_is_not_checked_with_a_shared_x_axis(tmp_path: Path) -> None:
    """Galactic's specification uses subnpts only for TXYXYS files (each subfile its own X).

    With one shared X axis a writer may leave any value there; the file size, checked
    against fnpts, is what says the data are whole.
    """
    good = read_spc(write(tmp_path, "good.spc", spc()))
    data = bytearray(spc())
    struct.pack_into("<i", data, 512 + 16, 7)
    odd = read_spc(write(tmp_path, "odd.spc", bytes(data)))
    cols = ["value", "wavelength_nm", "quantity", "sample"]
    assert odd.data[cols].equals(good.data[cols])
    assert odd.meta["subfiles"][0]["subnpts"] == 7
    # the size still decides: one byte less is refused
    with pytest.raises(AdapterError, match=r"bad.spc, byte \d+: file is"):
        read_spc(write(tmp_path, "bad.spc", bytes(data[:-1])))


@pytest.mark.parametrize(
    ("reader", "data"),
    [
        (read_jasco_text, jasco_text()),
        (read_perkinelmer_asc, pe()),
        (read_cary_csv, cary()),
        (read_jcamp, jdx()),
    ],
)
def test_utf16_text_is_refused_as_the_wrong_encoding(tmp_path, reader, data: bytes) -> None:
    p = write(tmp_path, "utf16.txt", data.decode("latin-1").encode("utf-16"))
    with pytest.raises(AdapterError, match=r"line 1: binary content \(NUL byte\)"):
        reader(p)


# ------------------------------------------------------------------ rarer paths


def test_perkinelmer_blank_line_in_data_and_negative_wavelength(tmp_path: Path) -> None:
    m = read_perkinelmer_asc(write(tmp_path, "a.asc", pe("600\t50\r\n\r\n590\t51\r\n")))
    assert len(m) == 2
    gr = ("nm", "%R", "1", "0", "-10", "-10", "2")
    bad = write(tmp_path, "b.asc", pe("-10\t50\r\n-20\t51\r\n", gr=gr))
    with pytest.raises(AdapterError, match=r"invalid data: column 'wavelength_nm': expected"):
        read_perkinelmer_asc(bad)


def test_cary_unusable_interval_and_time_are_kept_raw(tmp_path: Path) -> None:
    blocks = cary_block("S1", "n/a").replace("5/10/2018 5:14:12 PM", "yesterday")
    blocks += "\r\n" + cary_block("S2", "0")
    m = read_cary_csv(
        write(tmp_path, "a.csv", cary("500,50,500,1,\r\n400,51,400,2,\r\n", blocks=blocks))
    )
    s1 = m.meta["samples"][0]
    assert s1["collection_time"] is None and s1["collection_time_raw"] == "yesterday"
    assert len(m) == 4  # no step check without a usable interval (100 nm steps pass)


def test_jws_string_fields_fall_back_to_latin1(tmp_path: Path) -> None:
    data = bytearray(jws())
    data[0x180:0x187] = b"\x81\x20abcd\x00"  # neither UTF-8 nor cp932
    m = read_jasco_jws(write(tmp_path, "a.jws", bytes(data)))
    assert m.meta["title"] == "\x81 abcd"


def test_jcamp_comment_record_and_continuation_lines(tmp_path: Path) -> None:
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
def test_jcamp_rarer_errors(tmp_path: Path, data: bytes, match: str) -> None:
    with pytest.raises(AdapterError, match=match):
        read_jcamp(write(tmp_path, "bad.jdx", data))


def test_spc_without_a_valid_date_and_with_non_finite_x_range(tmp_path: Path) -> None:
    data = bytearray(spc())
    struct.pack_into("<I", data, 32, 0)
    assert read_spc(write(tmp_path, "a.spc", bytes(data))).meta["date"] is None
    struct.pack_into("<d", data, 16, float("inf"))
    with pytest.raises(AdapterError, match=r"byte 8: first/last X 400.0, inf: expected finite"):
        read_spc(write(tmp_path, "b.spc", bytes(data)))
