"""Wasatch Photonics ENLIGHTEN CSV exports (``.csv``).

ENLIGHTEN saves a spectrum in two CSV layouts:

column-ordered (read)
    ``key,value`` header lines, the first ``ENLIGHTEN Version,<version>`` (then
    ``Measurement ID``, ``Serial Number``, ``Model``, ``Label``, ``Technique``, ...,
    ``Integration Time``, ``Timestamp``, ``Note``, ``CCD C0`` .. ``C3``, ``Pixel Count``),
    a blank line, a column header made of ``Pixel``, ``Wavelength``, ``Wavenumber``,
    ``Processed``, ``Raw``, ``Dark``, ``Reference`` (those the user chose to save, in that
    order), then one row per detector pixel. ENLIGHTEN writes ``NA`` for Processed outside
    the region of interest; such points are dropped and counted
    (``meta["dropped_points"]``).
row-ordered (refused)
    the legacy "Dash" layout (first line ``Dash Output v2.1,ENLIGHTEN version: ...``), one
    spectrum per line after a column of metadata; it does not state the technique, so the
    quantity cannot be told: save the spectrum as column-ordered CSV.

Quantity (the ``Processed`` column, by the header's ``Technique``)
    ``Absorbance``: absorbance (AU, as is); ``Transmission``/``Transmittance``:
    transmittance, written in percent (100 (sample - dark) / (reference - dark)) and
    divided by 100; ``Reflectance``/``Reflection``: reflectance, percent, divided by 100.
    ``Scope``, ``Raman``, ``Emission``, ``Fluorescence``, ``Relative Irradiance``,
    ``Absolute Irradiance`` and any other technique are detector counts or properties of
    the light, not of the sample, and are refused by name. ``Raw``, ``Dark`` and
    ``Reference`` (detector counts) are not part of the dataset.

Checks: the ``Wavelength`` column must be present (a spectrum saved against wavenumber
only is refused) and strictly increasing; unless the header says ``Interpolated,True``,
the rows must number ``Pixel Count`` (a truncated file is refused).
"""

from __future__ import annotations

import csv
import os
from pathlib import Path
from typing import Any

import numpy as np

from ..dataset import Measurement
from ._base import AdapterError, Example, Format, check_count, decode, read_bytes, split_lines
from ._spectro import PERCENT, finish, number, spectrum_frame

__all__ = ["FORMATS", "read_enlighten"]

INSTRUMENT = "wasatch-enlighten"

_MAGIC = b"ENLIGHTEN Version,"
_DASH = b"Dash Output v"
#: technique (lower case) -> (quantity, scale)
_TECHNIQUES: dict[str, tuple[str, float]] = {
    "absorbance": ("absorbance", 1.0),
    "transmission": ("transmittance", PERCENT),
    "transmittance": ("transmittance", PERCENT),
    "reflectance": ("reflectance", PERCENT),
    "reflection": ("reflectance", PERCENT),
}
_COLUMNS = ("Pixel", "Wavelength", "Wavenumber", "Processed", "Raw", "Dark", "Reference")
_MISSING = {"NA", "na", ""}


def _sniff(head: bytes) -> bool:
    h = head[3:] if head.startswith(b"\xef\xbb\xbf") else head
    return h.startswith(_MAGIC) or (h.startswith(_DASH) and b"ENLIGHTEN" in h[:200])


def read_enlighten(path: str | os.PathLike[str]) -> Measurement:
    """Read an ENLIGHTEN column-ordered CSV export.

    Parameters
    ----------
    path : str or path-like
        The ``.csv`` export.

    Returns
    -------
    Measurement
        One spectrum against wavelength [nm] (normal incidence: theta_i NaN);
        ``meta["header"]`` holds the header fields, ``meta["technique"]`` the technique.

    Raises
    ------
    AdapterError
        A row-ordered (Dash) file, a technique without a dataset quantity, no Wavelength or
        Processed column, a row that is not numbers, a row count that disagrees with
        ``Pixel Count``, non-increasing wavelengths; with the line.
    """
    raw = read_bytes(path)
    text, encoding = decode(raw, path, ("utf-8", "cp1252"))
    lines = split_lines(text)
    if lines[0].startswith("Dash Output"):
        raise AdapterError(
            path,
            "an ENLIGHTEN row-ordered (Dash) CSV, which does not state the technique (the "
            "quantity of the spectrum): save the spectrum as column-ordered CSV in ENLIGHTEN",
            1,
        )
    if not lines[0].startswith("ENLIGHTEN Version,"):
        raise AdapterError(path, "expected 'ENLIGHTEN Version,...' on the first line", 1)
    header, at, blank = _header(path, lines)
    quantity, scale, technique = _technique(path, header, at)
    columns = _column_header(path, lines, blank)
    x, y, dropped = _rows(path, lines, blank + 1, columns)
    _check_pixels(path, header, at, x.size)
    frame, _ = spectrum_frame(
        path=path,
        sample=header.get("Label") or Path(path).stem,
        instrument=INSTRUMENT,
        quantity=quantity,
        scale=scale,
        x_nm=x,
        y=y,
    )
    meta: dict[str, Any] = {
        "format": INSTRUMENT,
        "encoding": encoding,
        "header": header,
        "technique": technique,
        "percent": scale == PERCENT,
        "columns": columns,
        "dropped_points": dropped,
    }
    return finish(path, [frame], meta)


def _header(
    path: str | os.PathLike[str], lines: list[str]
) -> tuple[dict[str, str], dict[str, int], int]:
    """The ``key,value`` lines up to the first blank line: fields, their lines, the blank."""
    header: dict[str, str] = {}
    at: dict[str, int] = {}
    for n, line in enumerate(lines):
        if not line.strip():
            return header, at, n
        fields = next(csv.reader([line]))
        if len(fields) < 2 or not fields[0].strip():
            raise AdapterError(path, "expected a 'key,value' header line", n + 1)
        key = fields[0].strip()[:200]
        header[key] = ",".join(fields[1:]).strip()[:1000]
        at[key] = n + 1
        if len(header) > 500:
            break
    raise AdapterError(path, "no blank line after the header: no data part", len(lines))


def _technique(
    path: str | os.PathLike[str], header: dict[str, str], at: dict[str, int]
) -> tuple[str, float, str]:
    technique = header.get("Technique")
    if technique is None:
        raise AdapterError(path, "no 'Technique' header line: the quantity cannot be told")
    known = _TECHNIQUES.get(technique.strip().lower())
    if known is None:
        raise AdapterError(
            path,
            f"Technique {technique!r} has no labbrdf quantity (detector counts or a property "
            "of the light, not of the sample); labbrdf reads ENLIGHTEN Absorbance, "
            "Transmission and Reflectance spectra",
            at["Technique"],
        )
    return known[0], known[1], technique.strip()


def _column_header(path: str | os.PathLike[str], lines: list[str], blank: int) -> list[str]:
    n = blank + 1
    if n >= len(lines):
        raise AdapterError(path, "no column header after the blank line", blank + 1)
    columns = [c.strip() for c in lines[n].split(",")]
    unknown = [c for c in columns if c not in _COLUMNS]
    if unknown or len(set(columns)) != len(columns):
        raise AdapterError(
            path, f"column header {lines[n][:80]!r}: expected names from {list(_COLUMNS)}", n + 1
        )
    for need in ("Wavelength", "Processed"):
        if need not in columns:
            raise AdapterError(
                path,
                f"no {need} column (the columns are {columns}); save the spectrum with the "
                "wavelength axis and the processed spectrum",
                n + 1,
            )
    return columns


def _rows(
    path: str | os.PathLike[str], lines: list[str], head: int, columns: list[str]
) -> tuple[np.ndarray, np.ndarray, int]:
    """Wavelength and Processed of the data rows; missing Processed values as NaN."""
    iw, ip = columns.index("Wavelength"), columns.index("Processed")
    xs: list[float] = []
    ys: list[float] = []
    for n in range(head + 1, len(lines)):
        s = lines[n].strip()
        if not s:
            if any(t.strip() for t in lines[n:]):
                raise AdapterError(path, "blank line inside the data", n + 1)
            break
        fields = s.split(",")
        if len(fields) != len(columns):
            raise AdapterError(
                path, f"expected {len(columns)} comma-separated fields, found {len(fields)}", n + 1
            )
        xs.append(number(fields[iw], path, n + 1, "Wavelength"))
        p = fields[ip].strip()
        ys.append(float("nan") if p in _MISSING else number(p, path, n + 1, "Processed"))
        check_count(path, "rows", len(xs), line=n + 1)
    if not xs:
        raise AdapterError(path, "no data rows after the column header", head + 1)
    x = np.asarray(xs)
    k = np.flatnonzero(np.diff(x) <= 0)
    if k.size:
        raise AdapterError(
            path, f"wavelength {x[k[0] + 1]:g} nm does not increase", head + 2 + int(k[0]) + 1
        )
    if x[0] <= 0:
        raise AdapterError(path, f"wavelength {x[0]:g} nm: expected > 0", head + 2)
    y = np.asarray(ys)
    return x, y, int(np.count_nonzero(np.isnan(y)))


def _check_pixels(
    path: str | os.PathLike[str], header: dict[str, str], at: dict[str, int], rows: int
) -> None:
    declared = header.get("Pixel Count")
    if declared is None or header.get("Interpolated", "").strip().lower() == "true":
        return
    count = number(declared, path, at["Pixel Count"], "Pixel Count")
    if count != rows:
        raise AdapterError(
            path,
            f"Pixel Count is {declared} but the file has {rows} data rows (truncated?)",
            at["Pixel Count"],
        )


FORMATS = (
    Format(
        "wasatch-enlighten",
        "Wasatch Photonics ENLIGHTEN column-ordered CSV (Absorbance, Transmission, Reflectance)",
        (".csv",),
        _sniff,
        read_enlighten,
        ("absorbance", "transmittance", "reflectance"),
        keywords=(b"ENLIGHTEN",),
        examples=(Example("wasatch-enlighten/wasatch-enlighten-transmission.csv"),),
        states_count=True,
    ),
)
