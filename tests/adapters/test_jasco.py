"""JASCO Spectra Manager exports: the text export (V-570, V-730; BOM, CR-only line ends,
footer) and the binary ``.jws``, both the current layout and the legacy OLE2 one.

Real files come from ../shared/real-exports through the ``real_exports`` fixture (skipped
when absent); every spot value is quoted from the file line it was checked against. The
synthetic files are built by the small writers here: each writes a valid file, and the
error tests break one thing at a time and check the AdapterError names the file and the
line (text) or byte offset (binary) and what was expected.
"""

from __future__ import annotations

import struct
from pathlib import Path

import numpy as np
import pytest

import labbrdf
from labbrdf.adapters import AdapterError, sniff
from labbrdf.adapters.jasco import read_jasco_jws, read_jasco_text

# float32 holds 24 bits: relative round-off of one stored value
F32 = 2.0**-24

TXT = "jasco-spectramanager-text"


@pytest.mark.parametrize("variant", ["bom", "cr", "bom+cr"])
def test_bom_and_cr_only_line_ends_are_recognised(
    real_exports: Path, tmp_path: Path, variant: str
) -> None:
    src = real_exports / TXT / "PbSe batch 1.txt"
    raw = src.read_bytes().replace(b"\r\n", b"\n")
    if "cr" in variant:
        raw = raw.replace(b"\n", b"\r")
    if "bom" in variant:
        raw = b"\xef\xbb\xbf" + raw
    path = tmp_path / "PbSe.txt"
    path.write_bytes(raw)
    assert sniff(path) == ["jasco-spectramanager-text"]
    m = labbrdf.read(path)
    assert m.data["value"].equals(labbrdf.read(src).data["value"])


# ------------------------------------------------------------- legacy (OLE2) .jws


LEGACY = "jasco-jws-binary/legacy_trans_512.jws"
_INVALID = -np.finfo(np.float32).tiny  # JASCO's invalid-point marker, -FLT_MIN


def legacy_streams(
    y=(50.0, 40.0, 30.0),
    *,
    first: float = 4000.0,
    delta: float = 1000.0,
    last: float | None = None,
    xcode: int = 0x10000100,
    ycode: int = 0,
    npoints: int | None = None,
    channels: int = 1,
) -> dict[str, bytes]:
    n = len(y) if npoints is None else npoints
    last = first + delta * (n - 1) if last is None else last
    info = struct.pack("<6I3d", 3, 1, 0, channels, 1, n, first, last, delta)
    info += struct.pack(f"<{channels + 1}I", xcode, *([ycode] * channels))
    info = info.ljust(96, b"\x00")
    return {"DataInfo": info, "Y-Data": np.asarray(y, "<f4").tobytes(), "Header": b"\x00" * 64}


def test_real_legacy_jws_is_ftir_transmittance_converted_to_nm(real_exports: Path) -> None:
    m = labbrdf.read(real_exports / LEGACY)
    d = m.data
    assert m.meta["format"] == "jasco-jws" and m.quantities == ["transmittance"]
    assert m.meta["x_unit_in_file"] == "1/cm" and m.meta["npoints"] == 7573
    # lambda = 1e7 / nu: the first wavenumber 499.47 1/cm is 20021 nm
    first = m.meta["firstx_in_file"]
    assert d["wavelength_nm"].max() == pytest.approx(1e7 / first, rel=1e-12)
    # percent in the file (up to 27.7 %): fractions in the dataset
    assert 0 < d["value"].max() < 0.3
    assert m.meta["invalid_marker_points"] + len(d) == 7573


def test_synthetic_legacy_jws_wavenumber_and_invalid_marker(tmp_path: Path, make_ole2) -> None:
    p = tmp_path / "ftir.jws"
    p.write_bytes(make_ole2(legacy_streams((50.0, _INVALID, 30.0))))
    assert sniff(p) == ["jasco-jws"]
    m = labbrdf.read(p)
    # 4000 and 6000 1/cm: 2500 and 1666.67 nm; the marked point is dropped and counted
    assert list(m.data["wavelength_nm"]) == pytest.approx([2500.0, 1e7 / 6000.0], rel=1e-15)
    assert list(m.data["value"]) == pytest.approx([0.5, 0.3], rel=1e-7)
    assert m.meta["invalid_marker_points"] == 1 and m.meta["dropped_points"] == 1


def test_synthetic_legacy_jws_in_nm_absorbance(tmp_path: Path, make_ole2) -> None:
    p = tmp_path / "uv.jws"
    streams = legacy_streams((0.5, 0.25), first=400.0, delta=1.0, xcode=0x10000103, ycode=3)
    p.write_bytes(make_ole2(streams))
    m = read_jasco_jws(p)
    assert m.quantities == ["absorbance"] and list(m.data["wavelength_nm"]) == [400.0, 401.0]


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"xcode": 0x10000999}, r"x-axis code 0x10000999 in DataInfo: expected"),
        ({"ycode": 14}, r"channel code 14 in DataInfo has no labbrdf quantity"),
        ({"npoints": 4}, r"'Y-Data' is 12 bytes but 1 channel\(s\) of NPOINTS 4 need 16"),
        ({"npoints": 0}, r"NPOINTS 0: expected > 0"),
        ({"npoints": 10**9}, r"exceeds the limit of 2000000 points"),
        ({"last": 9999.0}, r"disagrees with LASTX 9999"),
        ({"delta": 0.0}, r"DELTAX 0.0: expected finite"),
        ({"channels": 0}, r"DataInfo says 0 channels"),
        ({"first": 100.0, "delta": -1000.0}, r"the X axis reaches -1900 <= 0"),
    ],
)
def test_legacy_jws_errors_name_file_and_field(
    tmp_path: Path, make_ole2, kwargs: dict, match: str
) -> None:
    p = tmp_path / "bad.jws"
    p.write_bytes(make_ole2(legacy_streams(**kwargs)))
    with pytest.raises(AdapterError, match=match) as exc:
        read_jasco_jws(p)
    assert str(p) in str(exc.value)


def test_legacy_jws_without_its_streams_is_refused(tmp_path: Path, make_ole2) -> None:
    p = tmp_path / "other.jws"
    p.write_bytes(make_ole2({"Workbook": b"x" * 10}))
    with pytest.raises(AdapterError, match=r"1.x .jws: no stream 'DataInfo'"):
        labbrdf.read(p)


@pytest.mark.parametrize("keep", [512, 1024, 1500])
def test_truncated_legacy_jws_is_refused(tmp_path: Path, make_ole2, keep: int) -> None:
    p = tmp_path / "cut.jws"
    p.write_bytes(make_ole2(legacy_streams())[:keep])
    with pytest.raises(AdapterError, match=r"cut.jws: .*(corrupt|truncated)"):
        read_jasco_jws(p)


def test_jasco_text_v730_with_cp932_footer(real_exports: Path, value_at, check_spectrum) -> None:
    m = read_jasco_text(real_exports / "jasco-spectramanager-text" / "uvvis_abs.txt")
    check_spectrum(m, "absorbance", 61, 400.0, 700.0)
    assert value_at(m, 700) == -6.38777e-05  # line 19: "700\t-6.38777E-05"
    assert value_at(m, 410) == 0.000211082  # line 77: "410\t0.000211082"
    assert value_at(m, 400) == -0.00019697  # line 79: "400\t-0.00019697"
    assert m.meta["encoding"] == "cp932"
    # footer "[コメント情報]" / "試料名\ttest" and "[測定情報]" / "機種名\tV-730"
    assert set(m.data["sample"]) == {"test"}
    assert m.meta["footer"]["測定情報"]["機種名"] == "V-730"
    assert m.meta["footer_en"]["photometric mode"] == "Abs"
    assert m.meta["footer_en"]["number of points"] == "61"
    assert m.meta["header"]["SPECTROMETER/DATA SYSTEM"] == "JASCO Corp., V-730, Rev. 1.00"


def test_jasco_text_v570_without_footer(real_exports: Path, value_at, check_spectrum) -> None:
    m = read_jasco_text(real_exports / "jasco-spectramanager-text" / "PbSe batch 1.txt")
    check_spectrum(m, "absorbance", 1801, 700.0, 2500.0)
    assert value_at(m, 2500) == 0.10852  # line 19: "2500.0000\t0.10852"
    assert value_at(m, 700) == 1.58144  # last line: "700.0000\t1.58144"
    assert set(m.data["sample"]) == {"PbSe batch 1"}  # TITLE is empty: the file stem
    assert m.meta["footer"] == {} and m.meta["encoding"] == "utf-8"


def test_jws_absorbance_matches_its_text_export(real_exports: Path, check_spectrum) -> None:
    """Same measurement in two files: the binary float32 and the 6-digit text agree."""
    b = read_jasco_jws(real_exports / "jasco-jws-binary" / "uvvis_abs.jws")
    t = read_jasco_text(real_exports / "jasco-spectramanager-text" / "uvvis_abs.txt")
    check_spectrum(b, "absorbance", 61, 400.0, 700.0)
    yb = b.data.sort_values("wavelength_nm")["value"].to_numpy()
    yt = t.data.sort_values("wavelength_nm")["value"].to_numpy()
    # the text prints 6 significant digits: half a unit of the 6th digit, plus float32
    np.testing.assert_allclose(yb, yt, rtol=5e-6 + F32, atol=0)
    assert b.meta["model"] == "V-730" and b.meta["serial"] == "H470561798"
    assert b.meta["time_utc"] == "2026-06-04T07:08:01+00:00"  # text: 26/06/04 16:08 JST


def test_jws_reflectance_uses_firstx_and_deltax_not_stale_lastx(
    real_exports: Path, value_at, check_spectrum
) -> None:
    m = read_jasco_jws(real_exports / "jasco-jws-binary" / "uvvis_refl.jws")
    check_spectrum(m, "reflectance", 11, 650.0, 700.0)
    assert m.meta["lastx_header_nm"] == 400.0 and not m.meta["lastx_consistent"]
    # bytes 0x740..0x743 = 9a 1a c8 42 = 100.05195617675781 (%R) at FIRSTX 700 nm
    assert value_at(m, 700) == pytest.approx(100.05195617675781 / 100, rel=1e-15)


def test_jws_transmittance(real_exports: Path, value_at, check_spectrum) -> None:
    m = read_jasco_jws(real_exports / "jasco-jws-binary" / "uvvis_trans.jws")
    check_spectrum(m, "transmittance", 61, 400.0, 700.0)
    # bytes 0x740..0x743 = 32 10 c8 42 = 100.03163146972656 (%T) at 700 nm
    assert value_at(m, 700) == pytest.approx(100.03163146972656 / 100, rel=1e-15)


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


def test_jasco_text_percent_reflectance_and_title(tmp_path: Path, write) -> None:
    m = read_jasco_text(write(tmp_path, "a.txt", jasco_text()))
    assert list(m.data["value"]) == [0.5, 0.51, 0.52]
    assert set(m.data["quantity"].astype(str)) == {"reflectance"}
    assert set(m.data["sample"]) == {"my title"}


def test_jasco_text_sphere_accessory_gives_hemispherical(tmp_path: Path, write) -> None:
    footer = "\r\n\r\n[コメント情報]\r\n試料名\tOSR-1\r\n[付属品情報]\r\n付属品名\tISV-922\r\n"
    m = read_jasco_text(write(tmp_path, "a.txt", jasco_text(footer=footer)))
    assert set(m.data["quantity"].astype(str)) == {"hemispherical_reflectance"}
    assert set(m.data["sample"]) == {"OSR-1"} and m.meta["encoding"] == "cp932"


def test_jasco_text_comma_separated_transmittance(tmp_path: Path, write) -> None:
    data = jasco_text(yunits="TRANSMITTANCE").replace(b"\t", b",").replace(b"XYDATA", b"XYDATA,")
    m = read_jasco_text(write(tmp_path, "a.csv", data))
    assert set(m.data["quantity"].astype(str)) == {"transmittance"}
    assert list(m.data["value"]) == [0.5, 0.51, 0.52]


def test_jasco_text_footer_right_after_the_data(tmp_path: Path, write) -> None:
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
def test_jasco_text_errors(tmp_path: Path, data: bytes, match: str, write) -> None:
    p = write(tmp_path, "bad.txt", data)
    with pytest.raises(AdapterError, match=match) as exc:
        read_jasco_text(p)
    assert str(p) in str(exc.value)


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


def test_jws_modes_and_invalid_marker(tmp_path: Path, write) -> None:
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
def test_jws_errors(tmp_path: Path, data: bytes, match: str, write) -> None:
    p = write(tmp_path, "bad.jws", data)
    with pytest.raises(AdapterError, match=match) as exc:
        read_jasco_jws(p)
    assert str(p) in str(exc.value)


def test_utf16_jasco_text_is_refused_as_the_wrong_encoding(tmp_path: Path, write) -> None:
    p = write(tmp_path, "utf16.txt", jasco_text().decode("latin-1").encode("utf-16"))
    with pytest.raises(AdapterError, match=r"line 1: binary content \(NUL byte\)"):
        read_jasco_text(p)


def test_jws_string_fields_fall_back_to_latin1(tmp_path: Path, write) -> None:
    data = bytearray(jws())
    data[0x180:0x187] = b"\x81\x20abcd\x00"  # neither UTF-8 nor cp932
    m = read_jasco_jws(write(tmp_path, "a.jws", bytes(data)))
    assert m.meta["title"] == "\x81 abcd"


# ------------------------------------------------------- damaged OLE2 sector chains (legacy)


def _ole_set(raw: bytes, at: int, value: int) -> bytes:
    return raw[:at] + struct.pack("<I", value) + raw[at + 4 :]


def _fat_entry(raw: bytes, sector: int) -> int:
    """Byte offset of FAT entry ``sector`` (the FAT sectors are listed from byte 76)."""
    fat_sector = struct.unpack_from("<I", raw, 76 + 4 * (sector // 128))[0]
    return 512 * (fat_sector + 1) + 4 * (sector % 128)


def test_real_legacy_jws_with_a_looped_chain_is_refused(
    real_exports: Path, tmp_path: Path
) -> None:
    """Y-Data holds sectors 6-65; sector 30 pointing back to 6 read 6,399 of 7,113 rows."""
    raw = (real_exports / LEGACY).read_bytes()
    p = tmp_path / "legacy_trans_512.jws"
    p.write_bytes(_ole_set(raw, _fat_entry(raw, 30), 6))
    with pytest.raises(AdapterError, match=r"stream 'Y-Data' visits sector 6 twice \(a loop\)"):
        labbrdf.read(p)


def _legacy_big(make_ole2) -> tuple[bytes, list[int]]:
    """1200 points: Y-Data (4800 bytes) in the FAT; its chain, from olefile."""
    import olefile

    raw = make_ole2(legacy_streams(np.linspace(10.0, 60.0, 1200)))
    ole = olefile.OleFileIO(raw)
    chain = [ole.direntries[ole._find("Y-Data")].isectStart]
    while ole.fat[chain[-1]] != 0xFFFFFFFE:
        chain.append(ole.fat[chain[-1]])
    return raw, chain


def test_synthetic_legacy_jws_with_a_looped_chain_is_refused(tmp_path: Path, make_ole2) -> None:
    raw, y = _legacy_big(make_ole2)
    p = tmp_path / "loop.jws"
    p.write_bytes(_ole_set(raw, _fat_entry(raw, y[5]), y[2]))
    with pytest.raises(AdapterError, match=rf"loop.jws: .*'Y-Data' visits sector {y[2]} twice"):
        read_jasco_jws(p)


def test_synthetic_legacy_jws_with_a_short_chain_is_refused(tmp_path: Path, make_ole2) -> None:
    raw, y = _legacy_big(make_ole2)
    p = tmp_path / "short.jws"
    p.write_bytes(_ole_set(raw, _fat_entry(raw, y[4]), 0xFFFFFFFE))
    with pytest.raises(AdapterError, match=r"'Y-Data' ends after 5 sector\(s\), .* needs 10"):
        read_jasco_jws(p)


def test_legacy_jws_whose_mini_stream_is_cut_short_is_refused(tmp_path: Path, make_ole2) -> None:
    """The root entry's size bounds the mini sectors: DataInfo's must lie inside it."""
    raw = make_ole2(legacy_streams())
    at = raw.index("Root Entry".encode("utf-16-le")) + 120  # the root entry's size
    p = tmp_path / "mini.jws"
    p.write_bytes(_ole_set(raw, at, 64))  # one mini sector left of three streams' worth
    with pytest.raises(AdapterError, match=r"mini.jws: .*corrupt.*mini"):
        read_jasco_jws(p)
