"""JASCO Spectra Manager exports: the text export (``.txt``) and the binary ``.jws``/``.jrs``.

Text export (``jasco-spectramanager-text``)
    JCAMP-like ``KEY<TAB>VALUE`` header lines (``TITLE``, ``ORIGIN JASCO``, ``DATE yy/mm/dd``,
    ``SPECTROMETER/DATA SYSTEM``, ``DELTAX``, ``XUNITS NANOMETERS``, ``YUNITS``, ``FIRSTX``,
    ``LASTX``, ``NPOINTS``, ``FIRSTY``, ``MAXY``, ``MINY``), an ``XYDATA`` line, then ``x<TAB>y``
    rows; the same layout with commas is accepted. Newer versions append, after blank lines,
    a footer of ``[section]`` blocks with Japanese keys in Shift-JIS (cp932): sample name
    (``試料名``), operator, creation time, photometric mode, bandwidth, accessory. The file is
    decoded as UTF-8, else cp932; the footer is kept in ``meta["footer"]`` (original keys) and
    the keys we know are also given in English in ``meta["footer_en"]``. ``NPOINTS`` must
    match the data rows and every X must lie on ``FIRSTX + i * DELTAX``.

Binary ``.jws``/``.jrs`` (``jasco-jws``), Spectra Manager 2 (magic bytes ``"L~S "``)
    Little-endian fixed offsets (docs/formats.md section 7, confirmed on three V-730 files):
    NPOINTS int32 at 0x84; FIRSTX, LASTX, DELTAX float64 at 0x88/0x90/0x98; x-unit code
    (byte) at 0xA0 (3 = nm); y-mode code (byte) at 0xA4 (0 = %T, 2 = %R, 3 = Abs, 8-10 =
    single-beam intensity); data-block length int64 at 0xC8; model, serial, title, comment,
    operator strings at 0x140, 0x160, 0x180, 0x1C0, 0x240; Unix time at 0x2C0; accessory at
    0x484; float32 ordinates from 0x740 to the end of the file. The file size must be exactly
    0x740 + 4 * NPOINTS and the block length 4 * NPOINTS, otherwise the file is truncated or
    not understood and AdapterError gives the byte offset. Legacy Spectra Manager 1.x files
    (OLE2 compound documents, magic ``D0 CF 11 E0``) are read as below.

Legacy ``.jws`` (Spectra Manager 1.x, the same format name ``jasco-jws``)
    An OLE2 compound document (``labbrdf.adapters._ole2``). Stream ``DataInfo`` (96 bytes,
    little-endian, the layout used by the public jwsProcessor/pyjws readers): six uint32
    (the fourth is the number of channels, the sixth NPOINTS), FIRSTX, LASTX, DELTAX as
    float64 at 24/32/40, then one uint32 data-type code per axis from byte 48: the X code
    then one code per channel. X codes: ``0x10000103`` wavelength [nm], ``0x10000100``
    wavenumber [1/cm] (FTIR; converted by lambda [nm] = 1e7 / nu). Channel codes: 0 = %T,
    2 = %R, 3 = absorbance (as the version-2 y-mode byte). Stream ``Y-Data``: NPOINTS
    float32 per channel (channel after channel); only the first channel is read, and its
    code must be one of these. The stream size must be a multiple of 4 * NPOINTS that holds
    the channels, FIRSTX + (NPOINTS - 1) * DELTAX must equal LASTX (to 1e-6 relative), and
    the invalid-point marker -FLT_MIN is dropped as below. The sample is the file stem.

Quantities: ``ABSORBANCE``/Abs -> ``absorbance``; ``%T``/``TRANSMITTANCE`` (JASCO writes
percent) -> ``transmittance``; ``%R``/``REFLECTANCE`` -> ``reflectance``, or
``hemispherical_reflectance`` when the accessory is an integrating sphere (JASCO ISV-/ISN-
models, or a name containing "sphere"/"積分球"). theta_i is NaN (normal incidence or sphere).

Notes
-----
* ``LASTX`` is stale in ``uvvis_refl.jws`` (11 points from 700 nm by -5 nm, LASTX 400): the
  binary reader derives X from FIRSTX + i * DELTAX and records ``lastx_consistent`` in meta.
* Missing points: the binary invalid-point marker (-FLT_MIN, printed -1.18e-38 by JASCO) and
  NaN/inf ordinates are dropped and counted in ``meta["dropped_points"]``. The text export
  has no missing-value convention: a non-numeric cell is an error.
"""

from __future__ import annotations

import datetime as _dt
import os
import re
import struct
from pathlib import Path
from typing import Any

import numpy as np

from ..dataset import Measurement
from ._base import AdapterError, Example, Format, check_count, decode, read_bytes, split_lines
from ._ole2 import ole_names, open_ole2, read_stream
from ._spectro import PERCENT, finish, number, spectrum_frame
from ._truncation import check_joined, check_last_row

__all__ = ["FORMATS", "read_jasco_jws", "read_jasco_text"]

TEXT_INSTRUMENT = "jasco-spectramanager"
JWS_INSTRUMENT = "jasco-spectramanager"

#: YUNITS of the text export -> (quantity, scale); JASCO writes %T and %R as percent
_TEXT_YUNITS: dict[str, tuple[str, float]] = {
    "ABSORBANCE": ("absorbance", 1.0),
    "ABS": ("absorbance", 1.0),
    "TRANSMITTANCE": ("transmittance", PERCENT),
    "%T": ("transmittance", PERCENT),
    "REFLECTANCE": ("reflectance", PERCENT),
    "%R": ("reflectance", PERCENT),
}

#: y-mode code (byte 0xA4 of .jws) -> (quantity, scale)
_JWS_YMODES: dict[int, tuple[str, float]] = {
    0: ("transmittance", PERCENT),
    2: ("reflectance", PERCENT),
    3: ("absorbance", 1.0),
}
_JWS_SINGLE_BEAM = {8, 9, 10}

#: footer keys (cp932) we translate
_FOOTER_EN = {
    "コメント情報": "comment info",
    "データ情報": "data info",
    "測定情報": "measurement info",
    "付属品情報": "accessory info",
    "試料名": "sample name",
    "オペレーター": "operator",
    "所属": "affiliation",
    "コメント": "comment",
    "作成日時": "creation time",
    "スタート": "start",
    "エンド": "end",
    "データ間隔": "data interval",
    "データ数": "number of points",
    "機種名": "model",
    "シリアル番号": "serial number",
    "測光モード": "photometric mode",
    "UV/Vis バンド幅": "UV/Vis bandwidth",
    "レスポンス": "response",
    "走査速度": "scan speed",
    "光源": "light source",
    "光源切換": "light source change-over",
    "付属品名": "accessory",
}

_SECTION = re.compile(r"\[(.+)\]")
_SPHERE = re.compile(r"^\s*IS[VN]-|sphere|積分球", re.IGNORECASE)

_OLE_MAGIC = b"\xd0\xcf\x11\xe0\xa1\xb1\x1a\xe1"
_JWS_MAGIC = b"L~S "
_JWS_DATA_OFFSET = 0x740


def _is_sphere(accessory: str) -> bool:
    return bool(accessory and _SPHERE.search(accessory))


def _reflectance_quantity(quantity: str, accessory: str) -> str:
    if quantity == "reflectance" and _is_sphere(accessory):
        return "hemispherical_reflectance"
    return quantity


# ----------------------------------------------------------------------------- text


def _sniff_text(head: bytes) -> bool:
    """Sniff a JASCO text export by its ``TITLE``, ``NPOINTS`` and ``XYDATA`` lines.

    ``TITLE`` comes first (after a UTF-8 BOM, if any); line ends CRLF, LF or CR alike.
    """
    head = head.removeprefix(b"\xef\xbb\xbf")
    return (
        head.startswith(b"TITLE")
        and re.search(rb"[\r\n]XYDATA[ \t,]*[\r\n]", head) is not None
        and re.search(rb"[\r\n]NPOINTS[\t,]", head) is not None
    )


def read_jasco_text(path: str | os.PathLike[str]) -> Measurement:
    """Read a JASCO Spectra Manager text export (``.txt``, TAB or comma separated).

    Parameters
    ----------
    path : str or path-like
        The export file.

    Returns
    -------
    Measurement
        One spectrum: absorbance, transmittance or (hemispherical) reflectance [1] against
        wavelength [nm]; ``meta`` holds the header, the decoded footer and the encoding.

    Raises
    ------
    AdapterError
        Not a JASCO text export, a non-nm X axis, an unknown YUNITS, a bad data row, a row
        count that disagrees with NPOINTS or an X off the FIRSTX/DELTAX grid.
    """
    raw = read_bytes(path)
    try:
        text, encoding = decode(raw, path, ("utf-8",))
    except AdapterError as exc:
        if "NUL" in exc.reason:
            raise
        # report where cp932 fails, not where UTF-8 did (a valid cp932 footer is not UTF-8)
        text, encoding = decode(raw, path, ("cp932",))
    lines = split_lines(text)
    check_joined(path, lines)
    header, sep, xy_line = _text_header(path, lines)
    xunits = header.get("XUNITS", "")
    if xunits.upper() not in ("NANOMETERS", "NM"):
        raise AdapterError(path, f"XUNITS {xunits!r}: only wavelength in NANOMETERS is supported")
    yunits = header.get("YUNITS", "")
    if yunits.upper() not in _TEXT_YUNITS:
        raise AdapterError(path, f"YUNITS {yunits!r} is not one of {sorted(_TEXT_YUNITS)}")
    quantity, scale = _TEXT_YUNITS[yunits.upper()]
    npoints: float | None = None
    if "NPOINTS" in header:
        npoints = number(header["NPOINTS"], path, None, "NPOINTS")
        if npoints != int(npoints):
            raise AdapterError(path, f"NPOINTS {header['NPOINTS']!r}: expected an integer")
        # a data row "x<TAB>y<LF>" takes at least 4 bytes
        check_count(path, "NPOINTS", int(npoints), file_size=len(raw), bytes_per_point=4)
    xs, ys, end_of_data = _text_xy(path, lines, xy_line, sep)
    doubt = check_last_row(path, text, lines, range(xy_line + 1, end_of_data + 1), sep)
    footer, footer_en = _read_footer(path, lines, end_of_data, sep)
    if npoints is not None:
        if npoints != len(xs):
            raise AdapterError(
                path,
                f"NPOINTS says {header['NPOINTS']} but the data has {len(xs)} rows "
                f"(file truncated or edited?)",
                end_of_data,
            )
    _check_text_grid(path, header, xs, xy_line)
    accessory = footer_en.get("accessory", "")
    quantity = _reflectance_quantity(quantity, accessory)
    sample = footer_en.get("sample name") or header.get("TITLE") or Path(path).stem
    frame, dropped = spectrum_frame(
        path=path,
        sample=sample,
        instrument=TEXT_INSTRUMENT,
        quantity=quantity,
        scale=scale,
        x_nm=xs,
        y=ys,
    )
    meta: dict[str, Any] = {
        "format": "jasco-spectramanager-text",
        "encoding": encoding,
        "header": header,
        "footer": footer,
        "footer_en": footer_en,
        "yunits": yunits,
        "npoints": len(xs),
        "dropped_points": dropped,
    }
    if doubt:
        meta["warnings"] = [doubt]
    return finish(path, [frame], meta)


def _text_header(
    path: str | os.PathLike[str], lines: list[str]
) -> tuple[dict[str, str], str, int]:
    """The ``KEY<sep>VALUE`` header up to ``XYDATA``.

    Returns the header, the separator and the index of the first data row.
    """
    if not lines or not lines[0].startswith("TITLE"):
        raise AdapterError(path, "expected a JASCO text export starting with 'TITLE'", 1)
    sep = "\t" if "\t" in lines[0] else ","
    header: dict[str, str] = {}
    i = 0
    while i < len(lines) and lines[i].strip().rstrip(sep).strip() != "XYDATA":
        line = lines[i]
        if line.strip():
            if sep not in line:
                raise AdapterError(
                    path, f"expected 'KEY{sep!r}VALUE' header line, found {line[:40]!r}", i + 1
                )
            key, _, value = line.partition(sep)
            header[key.strip()] = value.strip()
        i += 1
    if i == len(lines):
        raise AdapterError(path, "no 'XYDATA' line: not a JASCO text export or truncated")
    return header, sep, i + 1


def _text_xy(
    path: str | os.PathLike[str], lines: list[str], xy_line: int, sep: str
) -> tuple[list[float], list[float], int]:
    """The ``x<sep>y`` rows from ``xy_line`` to a blank line or a section title.

    Returns the X and Y values and the index of the line that ends them.
    """
    xs: list[float] = []
    ys: list[float] = []
    i = xy_line
    while i < len(lines) and lines[i].strip() and not _SECTION.fullmatch(lines[i].strip()):
        cells = lines[i].split(sep)
        if len(cells) != 2:
            raise AdapterError(
                path, f"expected 2 cells 'x{sep!r}y' in the data, found {len(cells)}", i + 1
            )
        xs.append(number(cells[0], path, i + 1, "X"))
        ys.append(number(cells[1], path, i + 1, "Y"))
        i += 1
    if not xs:
        raise AdapterError(path, "no data rows after XYDATA", xy_line)
    return xs, ys, i


def _check_text_grid(
    path: str | os.PathLike[str], header: dict[str, str], xs: list[float], xy_line: int
) -> None:
    """Refuse an X off the FIRSTX + i*DELTAX grid the header states (a lost or doubled row)."""
    if "FIRSTX" in header and "DELTAX" in header:
        first = number(header["FIRSTX"], path, None, "FIRSTX")
        delta = number(header["DELTAX"], path, None, "DELTAX")
        with np.errstate(over="ignore", invalid="ignore"):
            grid = first + delta * np.arange(len(xs))
            off = ~(np.abs(np.asarray(xs) - grid) <= 0.01 * abs(delta) + 1e-9)
        if off.any():
            k = int(np.flatnonzero(off)[0])
            raise AdapterError(
                path,
                f"X {xs[k]} is not on the FIRSTX + i*DELTAX grid (expected {grid[k]:.6g}): "
                "a data row is missing or duplicated",
                xy_line + 1 + k,
            )


def _read_footer(
    path: str | os.PathLike[str], lines: list[str], start: int, sep: str
) -> tuple[dict[str, dict[str, str]], dict[str, str]]:
    """The ``[section]`` blocks after the data: {section: {key: value}} and English keys."""
    footer: dict[str, dict[str, str]] = {}
    english: dict[str, str] = {}
    section: str | None = None
    for j in range(start, len(lines)):
        line = lines[j].strip()
        if not line:
            continue
        m = _SECTION.fullmatch(line)
        if m:
            section = m.group(1)
            footer.setdefault(section, {})
            continue
        if section is None:
            raise AdapterError(
                path,
                f"unexpected line after the data block: {line[:40]!r} "
                "(expected a blank line or a '[section]' footer)",
                j + 1,
            )
        key, _, value = lines[j].partition(sep)
        key, value = key.strip(), value.strip()
        footer[section][key] = value
        if key in _FOOTER_EN:
            english.setdefault(_FOOTER_EN[key], value)
    return footer, english


# ----------------------------------------------------------------------------- binary


def _sniff_jws(head: bytes) -> bool:
    return head[:4] == _JWS_MAGIC or ole_names(head, "DataInfo", "Y-Data")


def _cstr(raw: bytes, offset: int, width: int) -> str:
    field = raw[offset : offset + width].split(b"\x00", 1)[0]
    for enc in ("utf-8", "cp932"):
        try:
            return field.decode(enc).strip()
        except UnicodeDecodeError:
            continue
    return field.decode("latin-1").strip()


def read_jasco_jws(path: str | os.PathLike[str]) -> Measurement:
    """Read a JASCO Spectra Manager 2 binary ``.jws`` (or firmware ``.jrs``) file.

    Parameters
    ----------
    path : str or path-like
        The binary file.

    Returns
    -------
    Measurement
        One spectrum against wavelength [nm] from FIRSTX + i * DELTAX.

    Raises
    ------
    AdapterError
        Legacy OLE2 ``.jws``, a wrong magic, a size inconsistent with NPOINTS, a non-nm X
        axis, single-beam or unknown y-mode; the message gives the byte offset.
    """
    raw = read_bytes(path)

    def fail(message: str, offset: int) -> AdapterError:
        return AdapterError(path, message, offset, unit="byte")

    if raw[:8] == _OLE_MAGIC:
        return _read_legacy(path)
    if raw[:4] != _JWS_MAGIC:
        raise fail(f"expected the JASCO magic 'L~S ', found {raw[:4]!r}", 0)
    if len(raw) < _JWS_DATA_OFFSET:
        raise fail(
            f"file is {len(raw)} bytes, shorter than the {_JWS_DATA_OFFSET}-byte header "
            "(truncated)",
            len(raw),
        )
    (npoints,) = struct.unpack_from("<i", raw, 0x84)
    firstx, lastx, deltax = struct.unpack_from("<3d", raw, 0x88)
    xcode, ymode = raw[0xA0], raw[0xA4]
    (block,) = struct.unpack_from("<q", raw, 0xC8)
    if npoints <= 0:
        raise fail(f"NPOINTS {npoints}: expected a positive count", 0x84)
    check_count(path, "NPOINTS", npoints, line=0x84, unit="byte")
    if block != 4 * npoints:
        raise fail(
            f"data-block length {block} bytes disagrees with NPOINTS {npoints} (expected "
            f"{4 * npoints})",
            0xC8,
        )
    expected = _JWS_DATA_OFFSET + 4 * npoints
    if len(raw) != expected:
        raise fail(
            f"file is {len(raw)} bytes but NPOINTS {npoints} needs {expected} "
            f"(header 0x{_JWS_DATA_OFFSET:X} + 4 * NPOINTS): truncated or NPOINTS wrong",
            0x84,
        )
    if not (np.isfinite(firstx) and firstx > 0):
        raise fail(f"FIRSTX {firstx}: expected a positive wavelength [nm]", 0x88)
    if not (np.isfinite(deltax) and deltax != 0):
        raise fail(f"DELTAX {deltax}: expected a finite non-zero step", 0x98)
    if xcode != 3:
        raise fail(f"x-unit code {xcode}: only 3 (nm) is supported", 0xA0)
    if ymode in _JWS_SINGLE_BEAM:
        raise fail(
            f"y-mode {ymode} is a single-beam intensity, which has no labbrdf quantity; "
            "export %T, %R or Abs",
            0xA4,
        )
    if ymode not in _JWS_YMODES:
        raise fail(f"unknown y-mode code {ymode}; known are {sorted(_JWS_YMODES)}", 0xA4)
    quantity, scale = _JWS_YMODES[ymode]
    with np.errstate(over="ignore", invalid="ignore"):
        x = firstx + deltax * np.arange(npoints)
    if not np.all(np.isfinite(x)) or x.min() <= 0:
        raise fail(f"FIRSTX {firstx} + i * DELTAX {deltax} reaches {x.min():.6g} nm <= 0", 0x98)
    with np.errstate(invalid="ignore"):  # a signalling NaN in float32 warns on the cast
        y = np.frombuffer(raw, dtype="<f4", count=npoints, offset=_JWS_DATA_OFFSET).astype(float)
    invalid = (y <= -1.17e-38) & (y >= -1.19e-38)
    y[invalid] = np.nan

    strings = {
        "format_id": _cstr(raw, 0x08, 16),
        "version": _cstr(raw, 0x20, 16),
        "model": _cstr(raw, 0x140, 32),
        "serial": _cstr(raw, 0x160, 32),
        "title": _cstr(raw, 0x180, 64),
        "comment": _cstr(raw, 0x1C0, 64),
        "operator": _cstr(raw, 0x240, 64),
        "accessory": _cstr(raw, 0x484, 32),
    }
    (stamp,) = struct.unpack_from("<I", raw, 0x2C0)
    when = (
        _dt.datetime.fromtimestamp(stamp, _dt.UTC).isoformat()
        if 0 < stamp < 4_102_444_800
        else None
    )
    quantity = _reflectance_quantity(quantity, strings["accessory"])
    frame, dropped = spectrum_frame(
        path=path,
        sample=strings["title"] or Path(path).stem,
        instrument=JWS_INSTRUMENT,
        quantity=quantity,
        scale=scale,
        x_nm=x,
        y=y,
    )
    meta: dict[str, Any] = {
        "format": "jasco-jws",
        **strings,
        "npoints": int(npoints),
        "firstx_nm": float(firstx),
        "deltax_nm": float(deltax),
        "lastx_header_nm": float(lastx) if np.isfinite(lastx) else None,
        "lastx_nm": float(x[-1]),
        "lastx_consistent": bool(np.isclose(lastx, x[-1])),
        "ymode_code": int(ymode),
        "time_utc": when,
        "dropped_points": dropped,
        "invalid_marker_points": int(np.count_nonzero(invalid)),
    }
    return finish(path, [frame], meta)


#: legacy DataInfo X codes -> (name, function to wavelength [nm])
_LEGACY_X: dict[int, tuple[str, Any]] = {
    0x10000103: ("nm", lambda v: v),
    0x10000100: ("1/cm", lambda v: 1.0e7 / v),
}
_LEGACY_WHAT = "JASCO Spectra Manager 1.x .jws"


def _read_legacy(path: str | os.PathLike[str]) -> Measurement:
    """Read a legacy (Spectra Manager 1.x, OLE2) ``.jws``; see the module docstring."""
    with open_ole2(path, _LEGACY_WHAT) as ole:
        info = read_stream(ole, path, "DataInfo", _LEGACY_WHAT)
        if len(info) < 56:
            raise AdapterError(
                path, f"{_LEGACY_WHAT}: stream 'DataInfo' is {len(info)} bytes, expected >= 56"
            )
        head = struct.unpack_from("<6I3d", info, 0)
        channels, npoints = head[3], head[5]
        firstx, lastx, deltax = head[6:9]
        if not 1 <= channels <= 16:
            raise AdapterError(
                path, f"{_LEGACY_WHAT}: DataInfo says {channels} channels, expected 1 to 16"
            )
        if len(info) < 48 + 4 * (channels + 1):
            raise AdapterError(
                path, f"{_LEGACY_WHAT}: stream 'DataInfo' ends before the channel codes"
            )
        codes = struct.unpack_from(f"<{channels + 1}I", info, 48)
        if npoints <= 0:
            raise AdapterError(path, f"{_LEGACY_WHAT}: NPOINTS {npoints}: expected > 0")
        check_count(path, "NPOINTS (DataInfo)", npoints)
        ydata = read_stream(ole, path, "Y-Data", _LEGACY_WHAT)
    if len(ydata) < 4 * npoints * channels:
        raise AdapterError(
            path,
            f"{_LEGACY_WHAT}: stream 'Y-Data' is {len(ydata)} bytes but {channels} channel(s) "
            f"of NPOINTS {npoints} need {4 * npoints * channels} (truncated or NPOINTS wrong)",
        )
    xcode, ycode = codes[0], codes[1]
    if xcode not in _LEGACY_X:
        raise AdapterError(
            path,
            f"{_LEGACY_WHAT}: x-axis code 0x{xcode:08X} in DataInfo: expected 0x10000103 "
            "(wavelength, nm) or 0x10000100 (wavenumber, 1/cm)",
        )
    if ycode not in _JWS_YMODES:
        raise AdapterError(
            path,
            f"{_LEGACY_WHAT}: channel code {ycode} in DataInfo has no labbrdf quantity; "
            f"expected one of {sorted(_JWS_YMODES)} (%T, %R, absorbance)",
        )
    if not (np.isfinite(firstx) and np.isfinite(deltax) and deltax != 0 and firstx > 0):
        raise AdapterError(
            path, f"{_LEGACY_WHAT}: FIRSTX {firstx}, DELTAX {deltax}: expected finite, > 0, != 0"
        )
    with np.errstate(over="ignore", invalid="ignore"):
        x_file = firstx + deltax * np.arange(npoints)
    if not abs(x_file[-1] - lastx) <= 1e-6 * max(abs(lastx), 1.0):
        raise AdapterError(
            path,
            f"{_LEGACY_WHAT}: FIRSTX {firstx:g} + (NPOINTS - 1) * DELTAX = {x_file[-1]:g} "
            f"disagrees with LASTX {lastx:g} (corrupt DataInfo)",
        )
    if x_file.min() <= 0:
        raise AdapterError(path, f"{_LEGACY_WHAT}: the X axis reaches {x_file.min():g} <= 0")
    xunit, to_nm = _LEGACY_X[xcode]
    x = to_nm(x_file)
    with np.errstate(invalid="ignore"):
        y = np.frombuffer(ydata, "<f4", npoints, 0).astype(float)
    invalid = (y <= -1.17e-38) & (y >= -1.19e-38)
    y[invalid] = np.nan
    quantity, scale = _JWS_YMODES[ycode]
    frame, dropped = spectrum_frame(
        path=path,
        sample=Path(path).stem,
        instrument=JWS_INSTRUMENT,
        quantity=quantity,
        scale=scale,
        x_nm=x,
        y=y,
    )
    meta: dict[str, Any] = {
        "format": "jasco-jws",
        "layout": "Spectra Manager 1.x (OLE2)",
        "npoints": int(npoints),
        "channels": int(channels),
        "x_unit_in_file": xunit,
        "firstx_in_file": float(firstx),
        "lastx_in_file": float(lastx),
        "deltax_in_file": float(deltax),
        "x_code": f"0x{xcode:08X}",
        "ymode_code": int(ycode),
        "dropped_points": dropped,
        "invalid_marker_points": int(np.count_nonzero(invalid)),
    }
    return finish(path, [frame], meta)


FORMATS = (
    Format(
        "jasco-spectramanager-text",
        "JASCO Spectra Manager text export (TAB/comma, cp932 footer)",
        (".txt",),
        _sniff_text,
        read_jasco_text,
        ("absorbance", "transmittance", "reflectance", "hemispherical_reflectance"),
        keywords=(b"JASCO", b"\nXYDATA"),
        examples=(
            Example("jasco-spectramanager-text/uvvis_abs.txt", number=("-6.38777E-05", 19)),
        ),
        states_count=True,
    ),
    Format(
        "jasco-jws",
        "JASCO Spectra Manager binary .jws/.jrs (version 2, and 1.x OLE2)",
        (".jws", ".jrs"),
        _sniff_jws,
        read_jasco_jws,
        ("absorbance", "transmittance", "reflectance", "hemispherical_reflectance"),
        examples=(Example("jasco-jws-binary/uvvis_abs.jws"),),
        states_count=True,
    ),
)
