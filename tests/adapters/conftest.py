"""Fixtures of the adapter tests: reading and error checks shared by the vendors' files, and
a minimal OLE2 compound-document writer.

The checks (``load``, ``pick``, ``approx``, ``value_at``, ``check_spectrum``, ``write``,
``raises``) are fixtures that return
plain functions, so that each vendor's file uses the same ones.

Shimadzu UVProbe ``.spc`` and legacy JASCO ``.jws`` files are OLE2 compound documents. The
tests build their own from named streams (``olefile`` reads but does not create them), so
they run without ../shared. The writer follows [MS-CFB] version 3: 512-byte sectors, a FAT
(its sectors past the 109 the header lists in DIFAT sectors),
streams under 4096 bytes in the mini stream (64-byte mini sectors, a mini FAT), directory
entries of 128 bytes whose siblings are chained through the right-sibling pointer (a valid
if unbalanced tree: readers do not check the red-black colours).
"""

from __future__ import annotations

import struct
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import labbrdf
from labbrdf.adapters import AdapterError

#: relative tolerance of a value read from a text export against the digits quoted from it
REL = 1e-12

MAGIC = b"\xd0\xcf\x11\xe0\xa1\xb1\x1a\xe1"
_FREE, _END, _FATSECT, _DIFSECT = 0xFFFFFFFF, 0xFFFFFFFE, 0xFFFFFFFD, 0xFFFFFFFC
_NOSTREAM = 0xFFFFFFFF
_SECTOR, _MINI, _CUTOFF = 512, 64, 4096


def _pad(data: bytes, size: int) -> bytes:
    return data + b"\x00" * (-len(data) % size)


def write_ole2(streams: dict[str, bytes]) -> bytes:
    """An OLE2 compound document holding ``streams`` ({"storage/sub/name": bytes})."""
    # directory tree: entry 0 is the root; storages are created along the paths
    entries: list[dict] = [{"name": "Root Entry", "type": 5, "kids": [], "data": b""}]
    index: dict[tuple[str, ...], int] = {(): 0}
    for path, data in streams.items():
        parts = tuple(path.split("/"))
        for depth in range(1, len(parts) + 1):
            key = parts[:depth]
            if key in index:
                continue
            is_stream = depth == len(parts)
            entries.append(
                {"name": key[-1], "type": 2 if is_stream else 1, "kids": [], "data": data}
            )
            index[key] = len(entries) - 1
            entries[index[key[:-1]]]["kids"].append(index[key])
    # the mini stream (small streams) and the big streams
    mini = b""
    for e in entries:
        if e["type"] == 2 and len(e["data"]) < _CUTOFF and e["data"]:
            e["start"] = len(mini) // _MINI
            mini += _pad(e["data"], _MINI)
    nmini = len(mini) // _MINI
    minifat = []
    for e in entries:
        if e["type"] == 2 and 0 < len(e["data"]) < _CUTOFF:
            n = -(-len(e["data"]) // _MINI)
            minifat += [e["start"] + i + 1 for i in range(n - 1)] + [_END]
    assert len(minifat) == nmini
    ndir = -(-len(entries) * 128 // _SECTOR)
    nminifat = -(-len(minifat) * 4 // _SECTOR)
    nministream = -(-len(mini) // _SECTOR)
    big = [e for e in entries if e["type"] == 2 and len(e["data"]) >= _CUTOFF]
    nbig = sum(-(-len(e["data"]) // _SECTOR) for e in big)
    nfat, ndifat = 1, 0  # past 109 FAT sectors (a file over 7 MB) DIFAT sectors list the rest
    while nfat * 128 < nfat + ndifat + ndir + nminifat + nministream + nbig:
        nfat += 1
        ndifat = max(0, -(-(nfat - 109) // 127))
    fat: list[int] = [_FATSECT] * nfat + [_DIFSECT] * ndifat
    nxt = nfat + ndifat

    def chain(n: int) -> int:
        nonlocal nxt
        if n == 0:
            return _END
        start = nxt
        fat.extend([start + i + 1 for i in range(n - 1)] + [_END])
        nxt += n
        return start

    dir_start = chain(ndir)
    minifat_start = chain(nminifat)
    ministream_start = chain(nministream)
    for e in big:
        e["start"] = chain(-(-len(e["data"]) // _SECTOR))
    fat += [_FREE] * (nfat * 128 - len(fat))
    # directory entries
    raw_dir = b""
    for i, e in enumerate(entries):
        kids = e["kids"]
        right = _NOSTREAM
        for e2 in entries:  # the next kid of the same parent is this entry's right sibling
            if i in e2["kids"]:
                k = e2["kids"].index(i)
                right = e2["kids"][k + 1] if k + 1 < len(e2["kids"]) else _NOSTREAM
        name = e["name"].encode("utf-16-le") + b"\x00\x00"
        if e["type"] == 5:
            start, size = (ministream_start if mini else _END), len(mini)
        elif e["type"] == 2:
            start, size = (e.get("start", _END) if e["data"] else _END), len(e["data"])
        else:
            start, size = 0, 0
        raw_dir += (
            name.ljust(64, b"\x00")
            + struct.pack(
                "<HBB3I", len(name), e["type"], 1, _NOSTREAM, right, kids[0] if kids else _NOSTREAM
            )
            + b"\x00" * 36
            + struct.pack("<IQ", start, size)
        )
    raw_dir = _pad(raw_dir, _SECTOR)
    header = (
        MAGIC
        + b"\x00" * 16
        + struct.pack("<HHHHH", 0x3E, 3, 0xFFFE, 9, 6)
        + b"\x00" * 6
        + struct.pack(
            "<IIIIIIIII",
            0,
            nfat,
            dir_start,
            0,
            _CUTOFF,
            minifat_start if minifat else _END,
            nminifat,
            nfat if ndifat else _END,
            ndifat,
        )
        + struct.pack("<109I", *(list(range(min(nfat, 109))) + [_FREE] * (109 - nfat)))
    )
    assert len(header) == _SECTOR
    body = struct.pack(f"<{len(fat)}I", *fat)
    for k in range(ndifat):
        listed = list(range(109 + 127 * k, min(nfat, 109 + 127 * (k + 1))))
        after = nfat + k + 1 if k + 1 < ndifat else _END
        body += struct.pack("<128I", *(listed + [_FREE] * (127 - len(listed)) + [after]))
    body += raw_dir
    body += _pad(struct.pack(f"<{len(minifat)}I", *minifat), _SECTOR) if minifat else b""
    body += _pad(mini, _SECTOR)
    for e in big:
        body += _pad(e["data"], _SECTOR)
    return header + body


@pytest.fixture(scope="session")
def make_ole2() -> Callable[[dict[str, bytes]], bytes]:
    """The writer: ``make_ole2({"DataInfo": b"...", "Y-Data": b"..."}) -> bytes``."""
    return write_ole2


# ----------------------------------------------------------------------------- reading checks

_READ: dict[Path, labbrdf.Measurement] = {}


def _load(real_exports: Path, rel: str) -> labbrdf.Measurement:
    """``labbrdf.read`` of a real export, once per session (tests only look at the result)."""
    path = real_exports / rel
    if path not in _READ:
        _READ[path] = labbrdf.read(path)
    return _READ[path]


def _pick(m: labbrdf.Measurement, quantity: str, wl: float, aoi: float | None = None, **kw):
    """The single row of ``quantity`` at wavelength ``wl`` (and AOI, channel, time...)."""
    d = m.data
    sel = (d["quantity"] == quantity) & np.isclose(d["wavelength_nm"], wl, rtol=1e-9, atol=0)
    if aoi is not None:
        sel &= np.isclose(d["theta_i_deg"], aoi, rtol=1e-9, atol=0)
    for k, v in kw.items():
        col = d[k]
        sel &= np.isclose(col, v, rtol=1e-9, atol=0) if isinstance(v, float) else col == v
    rows = d[sel]
    assert len(rows) == 1, f"{len(rows)} rows match {quantity} {wl} {aoi} {kw}"
    return rows.iloc[0]


def _value_at(m: labbrdf.Measurement, wavelength: float, sample: str | None = None) -> float:
    """The value of the single row at ``wavelength`` [nm] (of ``sample``)."""
    d = m.data
    sel = np.isclose(d["wavelength_nm"], wavelength, rtol=0, atol=1e-9)
    if sample is not None:
        sel &= d["sample"] == sample
    assert sel.sum() == 1, f"{sel.sum()} rows at {wavelength} nm"
    return float(d.loc[sel, "value"].iloc[0])


def _check_spectrum(m: labbrdf.Measurement, quantity: str, n: int, lo: float, hi: float) -> None:
    """A spectrophotometer spectrum: ``n`` rows of ``quantity`` from ``lo`` to ``hi`` [nm],
    fractions (unit "1"), no angle of incidence and no uncertainty."""
    d = m.data
    assert len(d) == n
    assert set(d["quantity"].astype(str)) == {quantity}
    assert d["wavelength_nm"].min() == pytest.approx(lo, abs=1e-9)
    assert d["wavelength_nm"].max() == pytest.approx(hi, abs=1e-9)
    assert (d["unit"] == "1").all()
    assert d["theta_i_deg"].isna().all() and d["sigma"].isna().all()


def _approx(x: float) -> object:
    return pytest.approx(x, rel=REL, abs=1e-15)


def _write(tmp_path: Path, name: str, data: bytes) -> Path:
    p = tmp_path / name
    p.write_bytes(data)
    return p


def _raises(path: Path, match: str, line: int | None = None, reader=labbrdf.read, **kw: Any):
    """The AdapterError of reading ``path``: matches ``match``, names the file (and line)."""
    with pytest.raises(AdapterError, match=match) as ei:
        reader(path, **kw)
    assert str(path) in str(ei.value)
    if line is not None:
        assert ei.value.line == line, str(ei.value)
    return ei.value


@pytest.fixture(scope="session")
def load() -> Callable[[Path, str], labbrdf.Measurement]:
    """``load(real_exports, "vendor-folder/file")``: the measurement read from a real export."""
    return _load


@pytest.fixture(scope="session")
def pick() -> Callable[..., Any]:
    """``pick(m, quantity, wl, aoi=None, **column=value)``: the one row that matches."""
    return _pick


@pytest.fixture(scope="session")
def approx() -> Callable[[float], object]:
    """``approx(x)``: ``pytest.approx`` at :data:`REL` (digits quoted from a text export)."""
    return _approx


@pytest.fixture(scope="session")
def value_at() -> Callable[..., float]:
    """``value_at(m, wavelength, sample=None)``: the value of the one row there."""
    return _value_at


@pytest.fixture(scope="session")
def check_spectrum() -> Callable[[labbrdf.Measurement, str, int, float, float], None]:
    """``check_spectrum(m, quantity, n, lo, hi)``: asserts a spectrum's shape and units."""
    return _check_spectrum


@pytest.fixture(scope="session")
def write() -> Callable[[Path, str, bytes], Path]:
    """``write(tmp_path, name, data)``: a file of those bytes."""
    return _write


@pytest.fixture(scope="session")
def raises() -> Callable[..., AdapterError]:
    """``raises(path, match, line=None, reader=labbrdf.read, **kw)``: the reader's error."""
    return _raises
