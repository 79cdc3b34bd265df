"""Avantes AvaSoft text exports (``avantes-avasoft``).

AvaSoft writes two text layouts; both are read by content, whatever the extension
(``.txt``, ``.csv``, and the converted-graph endings ``.ttt`` transmittance, ``.trt``
reflectance, ``.tat`` absorbance, ``.tit`` irradiance).

ASCII export ("Export > ASCII", one spectrometer)
    An optional title line (often empty), then ``Integration time [ms]: 84.900``,
    ``Averaging Nr. [scans]: 10``, ``Smoothing Nr. [pixels]: 1``, ``Data measured with
    spectrometer [name]: 1501154U1`` (AvaSoft 6: ``Integration time: 175 ms``, ``Average: 20
    scans``, ``Nr of pixels used for smoothing: 0``, ``... serial number: ...``), a column line
    ``Wave ;Sample ;Dark ;Reference;Reflectance`` (AvaSoft 6: ``Wave ;Dark ;Ref ;Sample
    ;Transmittance``), a unit line ``[nm] ;[counts] ;[counts] ;[counts] ;[%]``, an optional
    blank line and one row per pixel. Fields are separated by ``;`` (numbers then follow the
    Windows locale, decimal comma or point) or ``,`` (decimal point); blanks pad the fields.
    The fifth column is the processed spectrum and its name is the measurement mode.

Excel-style CSV export (``Filename-->,F1.IRR``)
    ``key-->,value`` lines (``Filename``, ``Mode/Unit``, ``Int.time[ms]``, ``NrOfAverages``,
    ``Smoothing``), then ``Wavelength[nm],<label>[,<label>...]`` and rows of a wavelength
    and one value per spectrometer channel. ``Mode/Unit`` names the mode and its unit,
    e.g. ``Irradiance[µWatt/cm²/nm]`` (a real file has ``?`` for the non-ASCII signs).

Quantity
    From the mode the file states (processed column name, or ``Mode/Unit``), never from the
    file name: ``Reflectance``/``Reflection`` and ``Transmittance``/``Transmission`` in
    percent (unit ``[%]``; divided by 100; a fraction with no ``%`` is refused, as the unit
    is then unknown), ``Absorbance``. ``Scope`` (raw counts, also ``Scope Corrected for
    Dark``), ``Absolute``/``Relative Irradiance``, ``Photon Counts``, ``Radiance`` and the
    like have no dataset quantity and are refused by name, with the export that works. An
    ASCII export without a processed column (``Wave;Sample;Dark;Reference;``) is scope data.

Rows and counts
    Where the sample, dark and reference counts are given, a row with ``Reference - Dark <=
    0`` has no defined ratio: it is dropped, counted in ``meta["dropped_points"]`` and named
    in ``meta["notes"]``; the counts of every row are kept in ``meta["counts"]``. Every row
    must hold as many numbers as there are columns; wavelengths must increase. There is no
    declared pixel count: at most ``MAX_POINTS`` rows are read,
    and a larger file is refused from its size before it is read.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..dataset import Measurement
from ._base import MAX_POINTS, AdapterError, Format, check_regular_file, decode, split_lines
from ._base import read_bytes as _read_bytes
from ._spectro import PERCENT, finish, number, spectrum_frame
from ._truncation import check_joined, check_last_row

__all__ = ["FORMATS", "read_avasoft"]

INSTRUMENT = "avantes-avasoft"

#: most bytes one row takes (six padded fields): a larger file is refused unread
_MAX_ROW_BYTES = 256
_ARROW = re.compile(r"^\s*[A-Za-z./\[\]]+-->\s*[,;]", re.MULTILINE)
_MEASURED_WITH = re.compile(r"^Data measured with spectrometer", re.MULTILINE | re.IGNORECASE)
_WAVE_LINE = re.compile(r"^\s*Wave\s*[;,]", re.MULTILINE)
#: mode word -> (quantity, needs a percent unit)
_MODES: tuple[tuple[re.Pattern[str], str], ...] = (
    (re.compile(r"^\s*reflect(?:ance|ion)\b", re.IGNORECASE), "reflectance"),
    (re.compile(r"^\s*transmi(?:ttance|ssion)\b", re.IGNORECASE), "transmittance"),
    (re.compile(r"^\s*absorbance\b", re.IGNORECASE), "absorbance"),
)
_WORKS = (
    "save the measurement in AvaSoft's Reflection, Transmission or Absorbance mode (with a "
    "dark and a reference) and export it as ASCII"
)


def _sniff(head: bytes) -> bool:
    text = head.decode("latin-1")
    if text.lstrip().startswith("Filename-->") and "Mode/Unit-->" in text:
        return True
    return _MEASURED_WITH.search(text) is not None and _WAVE_LINE.search(text) is not None


@dataclass
class _Layout:
    """What the header says: column names, units, mode, separator, first data line."""

    names: list[str]
    units: list[str]
    mode: str  # the measurement mode as written (processed column name, Mode/Unit)
    unit: str  # the processed values' unit as written ("" when none)
    sep: str
    first: int  # 0-based index of the first data line
    mode_line: int  # 1-based line that states the mode
    header: dict[str, str]


def read_avasoft(path: str | os.PathLike[str]) -> Measurement:
    """Read an Avantes AvaSoft text export (ASCII export or Excel-style CSV).

    Parameters
    ----------
    path : str or path-like
        The export.

    Returns
    -------
    Measurement
        The processed spectrum (reflectance or transmittance as a fraction, absorbance)
        against wavelength [nm]; ``meta["header"]`` holds the header fields and
        ``meta["counts"]`` the sample, dark and reference counts where the file has them.

    Raises
    ------
    AdapterError
        A mode without a labbrdf quantity (scope, irradiance, ...) or an unknown one, named;
        a row that is not numbers, non-increasing wavelengths, more than
        ``MAX_POINTS`` rows; with the line.
    """
    check_regular_file(path)
    size = os.stat(path).st_size
    if size > MAX_POINTS * _MAX_ROW_BYTES:
        raise AdapterError(path, f"{size} bytes: more than {MAX_POINTS} rows can take")
    text, encoding = decode(_read_bytes(path), path, ("utf-8", "cp1252"))
    lines = split_lines(text)
    check_joined(path, lines)
    arrow = bool(lines) and lines[0].lstrip().startswith("Filename-->")
    lay = _arrow_layout(path, lines) if arrow else _ascii_layout(path, lines)
    quantity, scale = _quantity(path, lay)
    a, at = _rows(path, lines, lay)
    doubt = check_last_row(path, text, lines, at, lay.sep)
    x = a[:, 0]
    k = np.flatnonzero(np.diff(x) <= 0)
    if k.size:
        raise AdapterError(
            path, f"wavelength {x[k[0] + 1]:g} nm does not increase", at[int(k[0]) + 1]
        )
    m = _measurement(path, lay, quantity, scale, a, at, encoding)
    if doubt:
        m.meta["warnings"] = [doubt]
    return m


def _arrow_layout(path: str | os.PathLike[str], lines: list[str]) -> _Layout:
    header: dict[str, str] = {}
    sep = ","
    for n, line in enumerate(lines):
        key, arrow, value = line.partition("-->")
        if arrow:
            sep = value[:1] if value[:1] in ",;" else sep
            header[key.strip()[:200]] = value[1:].strip().strip(sep).strip()[:1000]
            continue
        if not line.strip().lower().startswith("wavelength"):
            raise AdapterError(
                path, f"expected 'key-->' header lines, then 'Wavelength[nm]{sep}...'", n + 1
            )
        names = [f.strip() for f in line.split(sep)]
        while len(names) > 1 and not names[-1]:
            names.pop()
        if len(names) < 2:
            raise AdapterError(path, "no spectrum column after 'Wavelength[nm]'", n + 1)
        mode_unit = header.get("Mode/Unit")
        if mode_unit is None:
            raise AdapterError(path, "no 'Mode/Unit-->' line: the measurement mode is unknown")
        mode, _, unit = mode_unit.partition("[")
        at = next(i for i, s in enumerate(lines, start=1) if s.startswith("Mode/Unit"))
        return _Layout(names, [], mode.strip(), unit.rstrip("]"), sep, n + 1, at, header)
    raise AdapterError(path, "no 'Wavelength[nm]' column line after the header")


def _ascii_layout(path: str | os.PathLike[str], lines: list[str]) -> _Layout:
    wave = next((i for i, s in enumerate(lines[:50]) if _WAVE_LINE.match(s)), None)
    if wave is None:
        raise AdapterError(path, "no 'Wave ;Sample ;Dark ;Reference;...' column line")
    header: dict[str, str] = {}
    for n, line in enumerate(lines[:wave], start=1):
        key, colon, value = line.partition(":")
        if colon:
            header[key.strip()[:200]] = value.strip()[:1000]
        elif line.strip() and n == 1:
            header["title"] = line.strip()[:1000]
    sep = ";" if ";" in lines[wave] else ","
    names = [f.strip() for f in lines[wave].split(sep)]
    units_at = wave + 1
    units = lines[units_at].split(sep) if units_at < len(lines) else []
    if not units or not units[0].strip().startswith("["):
        raise AdapterError(path, "expected the unit line '[nm] ;[counts] ;...'", units_at + 1)
    units = [u.strip().strip("[]").strip() for u in units]
    mode = names[4] if len(names) > 4 else ""
    unit = units[4] if len(units) > 4 else ""
    return _Layout(names, units, mode, unit, sep, units_at + 1, wave + 1, header)


def _quantity(path: str | os.PathLike[str], lay: _Layout) -> tuple[str, float]:
    """The dataset quantity and scale of the mode the file states, or a refusal by name."""
    for pattern, quantity in _MODES:
        if not pattern.match(lay.mode):
            continue
        if quantity == "absorbance":
            return quantity, 1.0
        if "%" not in lay.unit:
            raise AdapterError(
                path,
                f"mode {lay.mode!r} with unit {lay.unit!r}: expected percent ('[%]')",
                lay.mode_line,
            )
        return quantity, PERCENT
    if not lay.mode:
        what = "with no processed column (scope mode: raw detector counts)"
    elif re.search(r"irradiance|radiance|photon|lux|colou?r", lay.mode, re.IGNORECASE):
        what = f"in mode {lay.mode!r} (a radiometric quantity)"
    elif re.search(r"scope|count|raw", lay.mode, re.IGNORECASE):
        what = f"in mode {lay.mode!r} (raw detector counts)"
    else:
        what = f"in mode {lay.mode!r} (not one labbrdf knows)"
    raise AdapterError(
        path,
        f"an Avantes AvaSoft export {what}, which has no labbrdf quantity; {_WORKS}",
        lay.mode_line,
    )


def _rows(
    path: str | os.PathLike[str], lines: list[str], lay: _Layout
) -> tuple[np.ndarray, list[int]]:
    """Every data row as numbers (``ncols`` each), and their 1-based lines."""
    ncols = len(lay.names)
    rows: list[list[float]] = []
    at: list[int] = []
    for n in range(lay.first, len(lines)):
        s = lines[n].strip()
        if not s:
            continue
        if len(rows) == MAX_POINTS:
            raise AdapterError(path, f"more than {MAX_POINTS} data rows", n + 1)
        fields = s.split(lay.sep)
        if fields and not fields[-1].strip() and len(fields) == ncols + 1:
            fields.pop()  # a trailing separator
        if len(fields) != ncols:
            raise AdapterError(
                path, f"expected {ncols} {lay.sep!r}-separated numbers, found {len(fields)}", n + 1
            )
        row = []
        for name, f in zip(lay.names, fields, strict=True):
            f = f.strip()
            if lay.sep == ";" and "." not in f:
                f = f.replace(",", ".", 1)
            row.append(number(f, path, n + 1, name or "value"))
        rows.append(row)
        at.append(n + 1)
    if not rows:
        raise AdapterError(path, "no data rows after the header", lay.first)
    return np.asarray(rows, dtype=float), at


_COUNT_NAMES = {"sample": "sample", "dark": "dark", "reference": "reference", "ref": "reference"}


def _counts(lay: _Layout, a: np.ndarray) -> dict[str, np.ndarray]:
    out = {}
    for j, name in enumerate(lay.names):
        key = _COUNT_NAMES.get(name.lower())
        if key is not None:
            out[key] = a[:, j]
    return out


def _measurement(
    path: str | os.PathLike[str],
    lay: _Layout,
    quantity: str,
    scale: float,
    a: np.ndarray,
    at: list[int],
    encoding: str,
) -> Measurement:
    counts = _counts(lay, a)
    keep = np.ones(len(a), dtype=bool)
    notes = []
    if {"dark", "reference"} <= set(counts):
        keep = counts["reference"] - counts["dark"] > 0
        if not keep.all():
            lines = [at[i] for i in np.flatnonzero(~keep)]
            shown = ", ".join(map(str, lines[:10])) + (", ..." if len(lines) > 10 else "")
            notes.append(
                f"{len(lines)} rows dropped where the reference is not above the dark "
                f"(Reference - Dark <= 0): no defined ratio (lines {shown})"
            )
    value_cols = [4] if lay.units else list(range(1, len(lay.names)))
    frames = []
    dropped = int(np.count_nonzero(~keep)) * len(value_cols)
    for j in value_cols:
        sample = Path(path).stem if len(value_cols) == 1 else lay.names[j]
        frame, nonfinite = spectrum_frame(
            path=path,
            sample=sample,
            instrument=INSTRUMENT,
            quantity=quantity,
            scale=scale,
            x_nm=a[keep, 0],
            y=a[keep, j],
        )
        frames.append(frame)
        dropped += nonfinite
    meta: dict[str, Any] = {
        "format": "avantes-avasoft",
        "encoding": encoding,
        "header": lay.header,
        "columns": lay.names,
        "quantity_from": f"the measurement mode the file states ({lay.mode!r}, line "
        f"{lay.mode_line})",
        "percent": scale == PERCENT,
        "dropped_points": dropped,
        "notes": notes,
    }
    if counts:
        meta["counts"] = {
            "unit": "counts",
            "wavelength_nm": a[:, 0].tolist(),
            **{k: v.tolist() for k, v in counts.items()},
        }
    return finish(path, frames, meta)


FORMATS = (
    Format(
        "avantes-avasoft",
        "Avantes AvaSoft ASCII or Excel-style CSV export (reflection, transmission, "
        "absorbance; scope and irradiance refused by name)",
        (".ttt", ".trt", ".tat", ".tit"),
        _sniff,
        read_avasoft,
        ("reflectance", "transmittance", "absorbance"),
        keywords=(b"Data measured with spectrometer", b"Mode/Unit-->", b"Int.time[ms]-->"),
    ),
)
