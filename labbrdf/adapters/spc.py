"""Thermo Galactic SPC binary spectra (``.spc``), new little-endian format (version byte 0x4B).

Layout (Galactic Industries, "SPC file format", 1996; docs/formats.md section 11): a
512-byte main header (all little-endian): ``ftflgs`` byte 0, ``fversn`` byte 1 (0x4B),
``fexp`` signed byte 3 (Y exponent; -128 = float32 Y), ``fnpts`` int32 at 4, ``ffirst``/
``flast`` float64 at 8/16, ``fnsub`` int32 at 24, ``fxtype``/``fytype`` bytes 28/29,
``fdate`` packed int32 at 32, ``fres`` char[9] at 36, ``fsource`` char[9] at 45, ``fcmnt``
char[130] at 88, ``flogoff`` int32 at 248, ``fmethod`` char[48] at 264. Then, if flag
TXVALS (0x80) is set, ``fnpts`` float32 X values; then per subfile a 32-byte sub-header
(``subexp`` signed byte 1, ``subnpts`` int32 at 16: the subfile's own point count, which
the specification uses only with TXYXYS; with a shared X axis it is kept in meta and not
checked, as writers leave 0 or other values there) and ``fnpts`` Y values: float32 when the
exponent is -128, else int32 (int16 with flag TSPREC 0x01) scaled by 2**(exp - 32)
(2**(exp - 16)). X is evenly spaced from ``ffirst`` to ``flast`` unless TXVALS; it must be strictly
monotonic (ascending or descending) and within 1 nm to 1 mm, else the header is corrupt.

Old-format (version byte 0x4D) and big-endian (0x4C) files are recognised, whether the
format is detected or forced, and refused by name with the advice to re-save them in the new
LSB format.

Supported: one or several subfiles sharing one X axis (TMULTI without TXYXYS), X in nm
(``fxtype`` 3) or micrometres (2), Y absorbance (``fytype`` 2), transmission (128) or
reflectance (129), the codes of Galactic's ``spc.h``. The format does not say whether a
transmission or reflectance is a fraction or percent: a Y axis label (``fcatxt``, flag
TALABS 0x20) containing ``%`` means percent, else values above 1.5 (no fraction reaches
that) mean percent, else the values are taken as fractions. Percent is divided by 100, and
``meta["y_scale_in_file"]``/``meta["y_scale_basis"]`` say what the file held and why.
The file size must equal the header plus the data blocks (plus the log block at
``flogoff`` when present), else the file is truncated or misread and AdapterError gives the
byte offset. Each subfile becomes one spectrum, named by the comment (``fcmnt``), else the
file stem, with ``#k`` appended when there are several.

Notes
-----
Own ``struct`` reader rather than a PyPI package: ``spc-spectra`` 0.4.0 (2018) no longer
builds with current pip, and ``spc-io`` 0.2.1 reads HOLMIUM.SPC correctly (901 points,
first Y 1.1663, used as an optional cross-check in the tests) but pulls in pydantic 2,
prints to stdout on errors and raises bare ValueErrors without offsets. The subset of the
format UV-Vis instruments write fits in this module.
"""

from __future__ import annotations

import datetime as _dt
import os
import struct
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..dataset import Measurement
from ._base import AdapterError, Example, Format, check_count, read_bytes
from ._ole2 import is_ole2
from ._spectro import finish, spectrum_frame

__all__ = ["FORMATS", "read_spc"]

INSTRUMENT = "galactic-spc"

_HEADER = 512
#: header size of the old format (version byte 0x4D) [bytes]
_OLD_HEADER = 256
_SUBHEADER = 32
_TSPREC, _TMULTI, _TXYXYS, _TXVALS = 0x01, 0x04, 0x40, 0x80
_XUNITS = {3: ("nm", 1.0), 2: ("micrometers", 1000.0)}
#: Supported ``fytype`` codes and their quantity. The SPC format names the codes (Galactic's
#: spc.h: 2 Absorbance, 128 Transmission, 129 Reflectance) but not whether 128/129 hold
#: fractions or percent: see :func:`_percent_or_fraction`.
_YTYPES = {2: "absorbance", 128: "transmittance", 129: "reflectance"}
#: Names of the other ``fytype`` codes, for the error message (spc.h ``Y...`` constants).
_YTYPE_NAMES = {
    0: "arbitrary intensity",
    1: "interferogram",
    3: "Kubelka-Munk",
    4: "counts",
    5: "volts",
    6: "degrees",
    7: "milliamps",
    8: "millimeters",
    9: "millivolts",
    10: "log(1/R)",
    11: "percent",
    12: "intensity",
    13: "relative intensity",
    14: "energy",
    16: "decibel",
    19: "temperature (F)",
    20: "temperature (C)",
    21: "temperature (K)",
    22: "index of refraction",
    23: "extinction coefficient",
    24: "real",
    25: "imaginary",
    26: "complex",
    130: "arbitrary or single beam with valley peaks",
    131: "emission",
}
_TALABS = 0x20
#: Above this a transmittance or reflectance cannot be a fraction (a fluorescent white
#: reaches about 1.1), so the file holds percent.
_FRACTION_MAX = 1.5
#: the wavelengths an optical spectrum can have [nm] (EUV to far infrared)
_WAVELENGTH_RANGE_NM = (1.0, 1.0e6)


def _sniff(head: bytes) -> bool:
    """True for a Galactic SPC of the new LSB format, or of a kind read_spc refuses by name.

    Old-format and big-endian files are claimed so that detection gives the same precise
    message as a forced format.
    """
    if len(head) < _OLD_HEADER:
        return False
    if head[1] == 0x4D:  # old format: float32 point count at 4, X unit code at 16
        (npts,) = struct.unpack_from("<f", head, 4)
        return 1 <= npts < 10_000_000 and npts == int(npts) and head[16] < 32
    order = {0x4B: "little", 0x4C: "big"}.get(head[1])
    return (
        order is not None
        and len(head) >= _HEADER
        and head[28] in _XUNITS
        and 0 < int.from_bytes(head[4:8], order, signed=True) < 10_000_000  # type: ignore[arg-type]
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


def _percent_or_fraction(y: np.ndarray, ylabel: str | None) -> tuple[float, str, str]:
    """Scale to a fraction, what the file holds and why, for a transmission/reflectance Y.

    A Y axis label (``fcatxt``, flag TALABS) with ``%`` means percent. Otherwise the values
    decide: above :data:`_FRACTION_MAX` they can only be percent; else they are taken as the
    fraction the dataset stores, and the basis says that the file does not say.
    """
    if ylabel and "%" in ylabel:
        return 0.01, "percent", f"the Y axis label {ylabel!r} says percent"
    finite = y[np.isfinite(y)]
    top = float(finite.max()) if finite.size else float("nan")
    if top > _FRACTION_MAX:
        return (
            0.01,
            "percent",
            f"values up to {top:.6g} cannot be a fraction (the SPC y type does not say "
            "fraction or percent)",
        )
    return (
        1.0,
        "fraction",
        f"values up to {top:.6g}, read as a fraction; the SPC y type does not say fraction "
        "or percent" + (f", nor does the Y axis label {ylabel!r}" if ylabel else ""),
    )


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
    h = _header(path, raw)
    flags, npts, nsub = h.flags, h.npts, h.nsub
    x = _x_axis(path, raw, h)
    quantity = _YTYPES[h.ytype]
    ylabel = None
    if flags & _TALABS:  # fcatxt at byte 218: X, Y, Z axis labels separated by NULs
        labels = raw[218:248].split(b"\x00")
        ylabel = labels[1].decode("latin-1").strip() if len(labels) > 1 else ""
    comment = _text(raw, 88, 130)
    base = comment or Path(path).stem
    ys, subnpts_all = _subfiles(raw, h)
    scale, in_file, basis = 1.0, None, None
    if quantity != "absorbance":
        scale, in_file, basis = _percent_or_fraction(np.concatenate([y for y, _ in ys]), ylabel)
    frames, subs, dropped = [], [], 0
    for k, (y, exp) in enumerate(ys):
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
        subs.append(
            {"exponent": exp, "points": int(npts), "subnpts": subnpts_all[k], "dropped": d}
        )
    meta: dict[str, Any] = {
        "format": "galactic-spc",
        "flags": int(flags),
        "version": f"0x{h.version:02X}",
        "experiment_type": int(raw[2]),
        "npoints": int(npts),
        "first_x": float(h.first),
        "last_x": float(h.last),
        "x_unit": _XUNITS[h.xtype][0],
        "y_type": int(h.ytype),
        "y_type_name": quantity,
        "y_axis_label": ylabel,
        "y_scale_in_file": in_file,
        "y_scale_basis": basis,
        "date": _fdate(struct.unpack_from("<I", raw, 32)[0]),
        "resolution": _text(raw, 36, 9),
        "source_instrument": _text(raw, 45, 9),
        "comment": comment,
        "method": _text(raw, 264, 48),
        "subfiles": subs,
        "log_offset": int(h.flogoff),
        "dropped_points": dropped,
    }
    return finish(path, frames, meta)


def _fail(path: str | os.PathLike[str], message: str, offset: int) -> AdapterError:
    """An error at byte ``offset`` of the file."""
    return AdapterError(path, message, offset, unit="byte")


@dataclass(frozen=True)
class _Header:
    """The fields of the 512-byte header that lay out the file."""

    flags: int
    version: int
    fexp: int
    npts: int
    first: float
    last: float
    nsub: int
    xtype: int
    ytype: int
    flogoff: int
    #: bytes per Y value (2 with TSPREC, else 4)
    width: int
    #: bytes of the explicit X array after the header (0 when evenly spaced)
    xbytes: int
    #: where the last subfile ends
    end: int


def _header(path: str | os.PathLike[str], raw: bytes) -> _Header:
    """Check the version, flags, counts, units and size the header states."""
    if is_ole2(raw):
        raise _fail(
            path,
            "this is an OLE2 compound document (magic D0 CF 11 E0 A1 B1 1A E1), not a "
            "Galactic SPC: a Shimadzu UVProbe .spc? Read it with --format "
            "shimadzu-uvprobe-spc on the command line or format='shimadzu-uvprobe-spc' in "
            "Python",
            0,
        )
    if len(raw) >= 2 and raw[1] in (0x4D, 0x4C):  # before the size: old headers are shorter
        kind = "old-format (0x4D)" if raw[1] == 0x4D else "big-endian (0x4C)"
        raise _fail(
            path, f"{kind} SPC files are not supported; re-save as new LSB format (0x4B)", 1
        )
    if len(raw) < _HEADER:
        raise _fail(
            path, f"file is {len(raw)} bytes, shorter than the 512-byte SPC header", len(raw)
        )
    flags, version = raw[0], raw[1]
    if version != 0x4B:
        raise _fail(path, f"version byte 0x{version:02X}: expected 0x4B (new LSB SPC)", 1)
    fexp = struct.unpack_from("<b", raw, 3)[0]
    npts, first, last, nsub = struct.unpack_from("<iddi", raw, 4)
    xtype, ytype = raw[28], raw[29]
    (flogoff,) = struct.unpack_from("<i", raw, 248)
    if flags & _TXYXYS:
        raise _fail(path, "subfiles with their own X arrays (TXYXYS) are not supported", 0)
    if not flags & _TMULTI:
        nsub = 1
    if npts <= 0:
        raise _fail(path, f"fnpts {npts}: expected a positive point count", 4)
    if nsub <= 0:
        raise _fail(path, f"fnsub {nsub}: expected a positive number of subfiles", 24)
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
        raise _fail(path, f"x type {xtype}: only nm (3) and micrometers (2) are supported", 28)
    if ytype not in _YTYPES:
        raise _fail(
            path,
            f"y type {ytype} ({_YTYPE_NAMES.get(ytype, 'unknown code')}): only absorbance (2), "
            "transmission (128) and reflectance (129) are supported",
            29,
        )
    xbytes = 4 * npts if flags & _TXVALS else 0
    end = _HEADER + xbytes + nsub * (_SUBHEADER + width * npts)
    _check_size(path, raw, nsub, npts, end, flogoff)
    return _Header(
        flags, version, fexp, npts, first, last, nsub, xtype, ytype, flogoff, width, xbytes, end
    )


def _check_size(
    path: str | os.PathLike[str], raw: bytes, nsub: int, npts: int, end: int, flogoff: int
) -> None:
    """Refuse a file shorter than its data, or longer without a log block after it."""
    if len(raw) < end:
        raise _fail(
            path,
            f"file is {len(raw)} bytes but {nsub} subfile(s) of {npts} points need {end} "
            "(truncated or fnpts wrong)",
            4,
        )
    if flogoff == 0 and len(raw) != end:
        raise _fail(
            path,
            f"file is {len(raw)} bytes, expected {end} for {nsub} subfile(s) of {npts} points "
            "and no log block",
            len(raw) if len(raw) < end else end,
        )
    if flogoff != 0 and not end <= flogoff < len(raw):
        raise _fail(
            path,
            f"log block offset {flogoff} is outside the file after the data ({end}..{len(raw)})",
            248,
        )


def _x_axis(path: str | os.PathLike[str], raw: bytes, h: _Header) -> np.ndarray:
    """The wavelengths [nm]: explicit or evenly spaced, finite, optical and monotonic."""
    flags, npts, first, last = h.flags, h.npts, h.first, h.last
    xscale = _XUNITS[h.xtype][1]
    if flags & _TXVALS:
        with np.errstate(invalid="ignore"):  # signalling NaNs warn on the cast
            x = np.frombuffer(raw, "<f4", npts, _HEADER).astype(float)
    else:
        if not (np.isfinite(first) and np.isfinite(last)):
            raise _fail(path, f"first/last X {first}, {last}: expected finite numbers", 8)
        with np.errstate(over="ignore", invalid="ignore"):
            x = np.linspace(first, last, npts) if npts > 1 else np.array([first])
    with np.errstate(over="ignore", invalid="ignore"):
        x = x * xscale
    if not np.all(np.isfinite(x) & (x > 0)):
        raise _fail(path, "the X axis has non-finite or non-positive wavelengths", 8)
    lo, hi = _WAVELENGTH_RANGE_NM
    if not (x.min() >= lo and x.max() <= hi):
        raise _fail(
            path,
            f"the X axis spans {x.min():.6g} to {x.max():.6g} nm, outside the {lo:g} to "
            f"{hi:g} nm of an optical spectrum (corrupt ffirst/flast?)",
            _HEADER if flags & _TXVALS else 8,
        )
    step = np.diff(x)
    if npts > 1 and not (np.all(step > 0) or np.all(step < 0)):
        k = int(np.flatnonzero(step * np.sign(x[-1] - x[0]) <= 0)[0])
        raise _fail(
            path,
            "the X axis is not strictly monotonic"
            + (f" (ffirst = flast = {first:g})" if not flags & _TXVALS else f" at point {k + 1}")
            + ": wavelengths must be distinct",
            _HEADER + 4 * (k + 1) if flags & _TXVALS else 8,
        )
    return x


def _subfiles(raw: bytes, h: _Header) -> tuple[list[tuple[np.ndarray, int]], list[int]]:
    """The Y values and exponent of every subfile, and the subnpts each states."""
    npts, nsub, width = h.npts, h.nsub, h.width
    ys: list[tuple[np.ndarray, int]] = []
    subnpts_all: list[int] = []
    offset = _HEADER + h.xbytes
    for _k in range(nsub):
        subexp = struct.unpack_from("<b", raw, offset + 1)[0]
        # subnpts counts the subfile's own X/Y pairs and matters only with TXYXYS (refused
        # above); with one shared X axis the specification leaves it unused, and writers
        # leave 0 or anything there: kept in meta, never checked
        (sub_n,) = struct.unpack_from("<i", raw, offset + 16)
        exp = subexp if nsub > 1 or h.fexp == 0 else h.fexp
        start = offset + _SUBHEADER
        if exp == -128:
            with np.errstate(invalid="ignore"):
                y = np.frombuffer(raw, "<f4", npts, start).astype(float)
        elif width == 4:
            y = np.frombuffer(raw, "<i4", npts, start).astype(float) * 2.0 ** (exp - 32)
        else:
            y = np.frombuffer(raw, "<i2", npts, start).astype(float) * 2.0 ** (exp - 16)
        ys.append((y, int(exp)))
        subnpts_all.append(int(sub_n))
        offset = start + width * npts
    return ys, subnpts_all


FORMATS = (
    Format(
        "galactic-spc",
        "Thermo Galactic SPC binary spectrum (new LSB format)",
        (".spc",),
        _sniff,
        read_spc,
        ("absorbance", "transmittance", "reflectance"),
        examples=(Example("galactic-spc/HOLMIUM.SPC"),),
        states_count=True,
    ),
)
