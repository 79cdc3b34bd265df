"""Galactic SPC: the holmium file against ``spc_io``, integer, float and 16-bit Y, explicit X
and multifile variants, reflectance and transmittance Y types, degenerate X axes refused.

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
from labbrdf.adapters import AdapterError
from labbrdf.adapters.spc import read_spc

# float32 holds 24 bits: relative round-off of one stored value
F32 = 2.0**-24


def _holmium(real_exports: Path) -> bytearray:
    return bytearray((real_exports / "galactic-spc/HOLMIUM.SPC").read_bytes())


@pytest.mark.parametrize(
    ("first", "last", "match"),
    [
        (500.0, 500.0, r"byte 8: the X axis is not strictly monotonic \(ffirst = flast = 500\)"),
        (1e-300, 1e-300, r"byte 8: the X axis spans 1e-300 to 1e-300 nm, outside"),
        (1e300, 1e300, r"byte 8: the X axis spans 1e\+300 to 1e\+300 nm, outside"),
        (250.0, 2e6, r"byte 8: the X axis spans 250 to 2e\+06 nm, outside"),
    ],
)
def test_degenerate_or_non_physical_x_range_is_refused(
    real_exports: Path, tmp_path: Path, first: float, last: float, match: str
) -> None:
    raw = _holmium(real_exports)
    struct.pack_into("<dd", raw, 8, first, last)  # ffirst, flast at byte 8 and 16
    bad = tmp_path / "x.spc"
    bad.write_bytes(bytes(raw))
    with pytest.raises(AdapterError, match=match):
        read_spc(bad)


def test_descending_x_range_is_read(real_exports: Path, tmp_path: Path) -> None:
    raw = _holmium(real_exports)
    struct.pack_into("<dd", raw, 8, 700.0, 250.0)
    path = tmp_path / "down.spc"
    path.write_bytes(bytes(raw))
    d = read_spc(path).data
    assert d["wavelength_nm"].iloc[0] == 700.0 and d["wavelength_nm"].iloc[-1] == 250.0


# ------------------------------------------------------------ reflectance and transmittance


def _float_spc(y: list[float], *, ytype: int, labels: bytes = b"") -> bytes:
    """A one-subfile SPC with float32 Y over 400-500 nm; ``labels`` go to fcatxt (TALABS)."""
    h = bytearray(512)
    h[0], h[1] = (0x20 if labels else 0), 0x4B
    struct.pack_into("<b", h, 3, -128)
    struct.pack_into("<iddi", h, 4, len(y), 400.0, 500.0, 1)
    h[28], h[29] = 3, ytype
    h[218 : 218 + len(labels)] = labels
    sub = bytearray(32)
    struct.pack_into("<b", sub, 1, -128)
    return bytes(h) + bytes(sub) + struct.pack(f"<{len(y)}f", *y)


def test_reflectance_y_type_of_a_real_file_is_read_as_percent_when_above_1(
    real_exports: Path, tmp_path: Path
) -> None:
    raw = _holmium(real_exports)
    raw[29] = 129  # fytype: reflectance
    p = tmp_path / "r.spc"
    p.write_bytes(bytes(raw))
    m = read_spc(p)
    d = m.data
    assert set(d["quantity"]) == {"reflectance"} and len(d) == 901
    # first Y 1.1663 (the same as the JCAMP file of this spectrum), up to 3.3747: percent
    assert d["value"].iloc[0] == pytest.approx(0.011663, rel=1e-4)
    assert d["value"].max() == pytest.approx(0.033747, rel=1e-4)
    assert m.meta["y_type_name"] == "reflectance"
    assert m.meta["y_scale_in_file"] == "percent"
    assert "3.3747" in m.meta["y_scale_basis"]


def test_transmittance_y_type_with_values_up_to_1_is_read_as_fraction(tmp_path: Path) -> None:
    p = tmp_path / "t.spc"
    p.write_bytes(_float_spc([0.25, 0.5, 0.75], ytype=128))
    m = read_spc(p)
    assert set(m.data["quantity"]) == {"transmittance"}
    assert list(m.data["value"]) == [0.25, 0.5, 0.75]
    assert m.meta["y_scale_in_file"] == "fraction"
    assert "does not say" in m.meta["y_scale_basis"]


def test_percent_axis_label_wins_over_the_value_range(tmp_path: Path) -> None:
    p = tmp_path / "rl.spc"
    p.write_bytes(_float_spc([0.5, 0.75, 1.0], ytype=129, labels=b"Wavelength\x00%R\x00\x00"))
    m = read_spc(p)
    assert list(m.data["value"]) == [0.005, 0.0075, 0.01]
    assert m.meta["y_scale_in_file"] == "percent"
    assert "'%R'" in m.meta["y_scale_basis"]


def test_other_y_types_are_still_refused_at_their_byte(tmp_path: Path) -> None:
    p = tmp_path / "c.spc"
    p.write_bytes(_float_spc([1.0, 2.0], ytype=4))  # counts
    with pytest.raises(AdapterError, match=r"byte 29: y type 4 \(counts\): only absorbance"):
        read_spc(p)


def test_spc_holmium(real_exports: Path, value_at, check_spectrum) -> None:
    m = read_spc(real_exports / "galactic-spc" / "HOLMIUM.SPC")
    check_spectrum(m, "absorbance", 901, 250.0, 700.0)
    # first Y at byte 0x220: a8 a4 4a 00 = 4891816, exponent 10: 4891816 * 2**(10 - 32)
    assert value_at(m, 250.0) == 4891816 * 2.0**-22
    # last Y at byte 0x1030: d4 09 04 00 = 264660
    assert value_at(m, 700.0) == 264660 * 2.0**-22
    assert set(m.data["sample"]) == {"Holmium Oxide Glass, the UV standard"}
    assert m.meta["date"] == "1992-03-04T14:31:00" and m.meta["resolution"] == ".5"


def test_spc_against_spc_io(real_exports: Path) -> None:
    spc_io = pytest.importorskip("spc_io")
    import io

    raw = (real_exports / "galactic-spc" / "HOLMIUM.SPC").read_bytes()
    sub = spc_io.SPC.from_bytes_io(io.BytesIO(raw))[0]
    ours = read_spc(real_exports / "galactic-spc" / "HOLMIUM.SPC").data
    np.testing.assert_allclose(ours["wavelength_nm"], sub.xarray, rtol=1e-15)
    np.testing.assert_allclose(ours["value"], sub.yarray, rtol=F32)


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


def test_spc_integer_float_16bit_explicit_x_and_multifile(tmp_path: Path, write) -> None:
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
def test_spc_errors(tmp_path: Path, data: bytes, match: str, write) -> None:
    p = write(tmp_path, "bad.spc", data)
    with pytest.raises(AdapterError, match=match) as exc:
        read_spc(p)
    assert str(p) in str(exc.value)


def test_spc_subheader_point_count_is_not_checked_with_a_shared_x_axis(
    tmp_path: Path, write
) -> None:
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


def test_spc_without_a_valid_date_and_with_non_finite_x_range(tmp_path: Path, write) -> None:
    data = bytearray(spc())
    struct.pack_into("<I", data, 32, 0)
    assert read_spc(write(tmp_path, "a.spc", bytes(data))).meta["date"] is None
    struct.pack_into("<d", data, 16, float("inf"))
    with pytest.raises(AdapterError, match=r"byte 8: first/last X 400.0, inf: expected finite"):
        read_spc(write(tmp_path, "b.spc", bytes(data)))


def _old_format_spc(npts: int = 3) -> bytes:
    """An old-format SPC (version 0x4D): float32 point count and X range, 256-byte header."""
    head = struct.pack("<BBhfff", 0, 0x4D, 0, float(npts), 400.0, 402.0) + bytes([3, 2])
    head = head.ljust(256, b"\x00")
    return head + struct.pack(f"<{npts}i", *range(npts))


def _big_endian_spc() -> bytes:
    raw = bytearray(spc(version=0x4C))
    raw[4:8] = struct.pack(">i", 3)
    return bytes(raw)


@pytest.mark.parametrize(
    ("make", "match"),
    [
        (_old_format_spc, r"byte 1: old-format \(0x4D\) SPC files are not supported; re-save"),
        (_big_endian_spc, r"byte 1: big-endian \(0x4C\) SPC files are not supported"),
    ],
)
def test_old_and_big_endian_spc_get_the_precise_message_when_detected(
    tmp_path: Path, write, make, match: str
) -> None:
    """Auto-detection says what --format galactic-spc says, not 'no adapter recognises'."""
    p = write(tmp_path, "old.spc", make())
    for fmt in (None, "galactic-spc"):
        with pytest.raises(AdapterError, match=match) as exc:
            labbrdf.read(p, format=fmt)
        assert str(p) in str(exc.value)
