"""Thermo Galactic SPC binary spectra (``.spc``), new little-endian format (version byte 0x4B).

Layout (Galactic Industries, "SPC file format", 1996; docs/formats.md section 11): a
512-byte main header (all little-endian): ``ftflgs`` byte 0, ``fversn`` byte 1 (0x4B),
``fexp`` signed byte 3 (Y exponent; -128 = float32 Y), ``fnpts`` int32 at 4, ``ffirst``/
``flast`` float64 at 8/16, ``fnsub`` int32 at 24, ``fxtype``/``fytype`` bytes 28/29,
``fdate`` packed int32 at 32, ``fres`` char[9] at 36, ``fsource`` char[9] at 45, ``fcmnt``
char[130] at 88, ``flogoff`` int32 at 248, ``fmethod`` char[48] at 264. Then, if flag
TXVALS (0x80) is set, ``fnpts`` float32 X values; then per subfile a 32-byte sub-header
(``subexp`` signed byte 1, ``subnpts`` int32 at 16) and ``fnpts`` Y values: float32 when the
exponent is -128, else int32 (int16 with flag TSPREC 0x01) scaled by 2**(exp - 32)
(2**(exp - 16)). X is evenly spaced from ``ffirst`` to ``flast`` unless TXVALS; it must be strictly
monotonic (ascending or descending) and within 1 nm to 1 mm, else the header is corrupt.

Supported: one or several subfiles sharing one X axis (TMULTI without TXYXYS), X in nm
(``fxtype`` 3) or micrometres (2), Y absorbance (``fytype`` 2). The file size must equal
the header plus the data blocks (plus the log block at ``flogoff`` when present), else the
file is truncated or misread and AdapterError gives the byte offset. Each subfile becomes
one spectrum, named by the comment (``fcmnt``), else the file stem, with ``#k`` appended
when there are several.

Notes
-----
Own ``struct`` reader rather than a PyPI package: ``spc-spectra`` 0.4.0 (2018) no longer
builds with current pip, and ``spc-io`` 0.2.1 reads HOLMIUM.SPC correctly (901 points,
first Y 1.1663, used as an optional cross-check in the tests) but pulls in pydantic 2,
prints to stdout on errors and raises bare ValueErrors without offsets. The subset of the
format UV-Vis instruments write fits in this module.
Y types 128 (transmission) and 129 (reflectance) are refused: the format does not say
whether they are fractions or percent and no real file was available to decide.
"""

from __future__ import annotations

import datetime as _dt
import os
import struct
from pathlib import Path
from typing import Any

import numpy as np

from ..dataset import Measurement
from ._base import AdapterError, Format, check_count, read_bytes
from ._spectro import finish, spectrum_frame

__all__ = ["FORMATS", "read_spc"]

INSTRUMENT = "galactic-spc"

_HEADER = 512
_SUBHEADER = 32
_TSPREC, _TMULTI, _TXYXYS, _TXVALS = 0x01, 0x04, 0x40, 0x80
_XUNITS = {3: ("nm", 1.0), 2: ("micrometers", 1000.0)}
_YTYPES = {2: ("absorbance", 1.0)}
#: the wavelengths an optical spectrum can have [nm] (EUV to far infrared)
_WAVELENGTH_RANGE_NM = (1.0, 1.0e6)


def _sniff(head: bytes) -> bool:
    return (
        len(head) >= _HEADER
        and head[1] == 0x4B
        and head[28] in _XUNITS
        and 0 < int.from_bytes(head[4:8], "little", signed=True) < 10_000_000
    )


def _text(raw: bytes, offset: int, width: int) -> str:
    return raw[offset : offset + width].split(b"\x00", 1)[0].decode("latin-1").strip()


def _fdate(value: int) -> str | None:
    """Packed date: year bits 20-31, month 16-19, day 11-15, hour 6-10, minute 0-5."""
    try:
        return _dt.datetime(
            value >> 20 & 0xFFF,
            value >> 16 & 0xF,
            value >> 11 & 0x1F,
            value >> 6 & 0x1F,
            value & 0x3F,
        ).isoformat()
    except ValueError:
        return None


def read_spc(path: str | os.PathLike[str]) -> Measurement:
    """Read a Galactic SPC file (new LSB format, evenly spaced or explicit X).

    Parameters
    ----------
    path : str or path-like
        The ``.spc`` file.

    Returns
    -------
    Measurement
        One spectrum per subfile against wavelength [nm]; ``meta`` has the header fields.

    Raises
    ------
    AdapterError
        Old or big-endian versions, unsupported flags or units, or a file size that does not
        match the header; the message gives the byte offset.
    """
    raw = read_bytes(path)

    def fail(message: str, offset: int) -> AdapterError:
        return AdapterError(path, message, offset, unit="byte")

    if len(raw) < _HEADER:
        raise fail(f"file is {len(raw)} bytes, shorter than the 512-byte SPC header", len(raw))
    flags, version = raw[0], raw[1]
    if version in (0x4D, 0x4C):
        kind = "old-format (0x4D)" if version == 0x4D else "big-endian (0x4C)"
        raise fail(f"{kind} SPC files are not supported; re-save as new LSB format (0x4B)", 1)
    if version != 0x4B:
        raise fail(f"version byte 0x{version:02X}: expected 0x4B (new LSB SPC)", 1)
    fexp = struct.unpack_from("<b", raw, 3)[0]
    npts, first, last, nsub = struct.unpack_from("<iddi", raw, 4)
    xtype, ytype = raw[28], raw[29]
    (flogoff,) = struct.unpack_from("<i", raw, 248)
    if flags & _TXYXYS:
        raise fail("subfiles with their own X arrays (TXYXYS) are not supported", 0)
    if not flags & _TMULTI:
        nsub = 1
    if npts <= 0:
        raise fail(f"fnpts {npts}: expected a positive point count", 4)
    if nsub <= 0:
        raise fail(f"fnsub {nsub}: expected a positive number of subfiles", 24)
    width = 2 if flags & _TSPREC else 4
    # before anything is allocated: the total against the cap and what the file can hold
    check_count(
        path, "fnpts", npts, line=4, unit="byte", file_size=len(raw), bytes_per_point=width
    )
    check_count(
        path,
        "fnpts * fnsub",
        npts * nsub,
        line=24,
        unit="byte",
        file_size=len(raw),
        bytes_per_point=width,
    )
    if xtype not in _XUNITS:
        raise fail(f"x type {xtype}: only nm (3) and micrometers (2) are supported", 28)
    if ytype not in _YTYPES:
        raise fail(
            f"y type {ytype}: only absorbance (2) is supported (128/129 transmission and "
            "reflectance do not say fraction or percent)",
            29,
        )
    xbytes = 4 * npts if flags & _TXVALS else 0
    end = _HEADER + xbytes + nsub * (_SUBHEADER + width * npts)
    if len(raw) < end:
        raise fail(
            f"file is {len(raw)} bytes but {nsub} subfile(s) of {npts} points need {end} "
            "(truncated or fnpts wrong)",
            4,
        )
    if flogoff == 0 and len(raw) != end:
        raise fail(
            f"file is {len(raw)} bytes, expected {end} for {nsub} subfile(s) of {npts} points "
            "and no log block",
            len(raw) if len(raw) < end else end,
        )
    if flogoff != 0 and not end <= flogoff < len(raw):
        raise fail(
            f"log block offset {flogoff} is outside the file after the data ({end}..{len(raw)})",
            248,
        )
    xname, xscale = _XUNITS[xtype]
    if flags & _TXVALS:
        with np.errstate(invalid="ignore"):  # signalling NaNs warn on the cast
            x = np.frombuffer(raw, "<f4", npts, _HEADER).astype(float)
    else:
        if not (np.isfinite(first) and np.isfinite(last)):
            raise fail(f"first/last X {first}, {last}: expected finite numbers", 8)
        with np.errstate(over="ignore", invalid="ignore"):
            x = np.linspace(first, last, npts) if npts > 1 else np.array([first])
    with np.errstate(over="ignore", invalid="ignore"):
        x = x * xscale
    if not np.all(np.isfinite(x) & (x > 0)):
        raise fail("the X axis has non-finite or non-positive wavelengths", 8)
    lo, hi = _WAVELENGTH_RANGE_NM
    if not (x.min() >= lo and x.max() <= hi):
        raise fail(
            f"the X axis spans {x.min():.6g} to {x.max():.6g} nm, outside the {lo:g} to "
            f"{hi:g} nm of an optical spectrum (corrupt ffirst/flast?)",
            _HEADER if flags & _TXVALS else 8,
        )
    step = np.diff(x)
    if npts > 1 and not (np.all(step > 0) or np.all(step < 0)):
        k = int(np.flatnonzero(step * np.sign(x[-1] - x[0]) <= 0)[0])
        raise fail(
            "the X axis is not strictly monotonic"
            + (f" (ffirst = flast = {first:g})" if not flags & _TXVALS else f" at point {k + 1}")
            + ": wavelengths must be distinct",
            _HEADER + 4 * (k + 1) if flags & _TXVALS else 8,
        )

    quantity, scale = _YTYPES[ytype]
    comment = _text(raw, 88, 130)
    base = comment or Path(path).stem
    frames, subs, dropped = [], [], 0
    offset = _HEADER + xbytes
    for k in range(nsub):
        subexp = struct.unpack_from("<b", raw, offset + 1)[0]
        (subnpts,) = struct.unpack_from("<i", raw, offset + 16)
        if subnpts not in (0, npts):
            raise fail(f"subfile {k}: subnpts {subnpts} disagrees with fnpts {npts}", offset + 16)
        exp = subexp if nsub > 1 or fexp == 0 else fexp
        start = offset + _SUBHEADER
        if exp == -128:
            with np.errstate(invalid="ignore"):
                y = np.frombuffer(raw, "<f4", npts, start).astype(float)
        elif width == 4:
            y = np.frombuffer(raw, "<i4", npts, start).astype(float) * 2.0 ** (exp - 32)
        else:
            y = np.frombuffer(raw, "<i2", npts, start).astype(float) * 2.0 ** (exp - 16)
        frame, d = spectrum_frame(
            path=path,
            sample=base if nsub == 1 else f"{base} #{k}",
            instrument=INSTRUMENT,
            quantity=quantity,
            scale=scale,
            x_nm=x,
            y=y,
        )
        frames.append(frame)
        dropped += d
        subs.append({"exponent": int(exp), "points": int(npts), "dropped": d})
        offset = start + width * npts
    meta: dict[str, Any] = {
        "format": "galactic-spc",
        "flags": int(flags),
        "version": f"0x{version:02X}",
        "experiment_type": int(raw[2]),
        "npoints": int(npts),
        "first_x": float(first),
        "last_x": float(last),
        "x_unit": xname,
        "y_type": int(ytype),
        "date": _fdate(struct.unpack_from("<I", raw, 32)[0]),
        "resolution": _text(raw, 36, 9),
        "source_instrument": _text(raw, 45, 9),
        "comment": comment,
        "method": _text(raw, 264, 48),
        "subfiles": subs,
        "log_offset": int(flogoff),
        "dropped_points": dropped,
    }
    return finish(path, frames, meta)


FORMATS = (
    Format(
        "galactic-spc",
        "Thermo Galactic SPC binary spectrum (new LSB format)",
        (".spc",),
        _sniff,
        read_spc,
        ("absorbance",),
    ),
)
