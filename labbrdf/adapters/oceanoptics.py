"""Ocean Optics (Ocean Insight) OceanView and SpectraSuite text exports (``.txt``).

Layout (the tab-delimited "with header" export of both programs)
    Header lines ``Key: value`` (``Data from <name> Node``, ``Date``, ``User``,
    ``Spectrometer``, ``Integration Time (sec)`` or ``(usec)``, ``Scans to average``,
    ``Boxcar width``, ``XAxis mode``, ``Number of Pixels in Spectrum``; SpectraSuite starts
    with ``SpectraSuite Data File`` and a line of ``+`` signs), then the line
    ``>>>>>Begin Spectral Data<<<<<`` (SpectraSuite: ``>>>>>Begin Processed Spectral
    Data<<<<<``), then one ``wavelength<TAB>value`` row per detector pixel, and in
    SpectraSuite a closing ``>>>>>End Processed Spectral Data<<<<<``. Numbers follow the
    Windows locale: a decimal comma is read as a decimal point (the separator is a TAB).

Quantity
    The export does not name its processing mode in a header field; OceanView puts it in the
    default file name (``..._Absorbance_10-54-38-373.txt``) and repeats it in ``Data from
    ... Node``, and SpectraSuite writes ``Processing mode``/file names the same way. The
    reader looks for ``Absorbance``, ``Transmission``/``Transmittance``, ``Reflection``/
    ``Reflectance`` in the ``Data from`` line, then in the file name. Transmission and
    reflection are percent in both programs (divided by 100). ``Scope``/``Scope Minus Dark``
    (raw detector counts), ``Irradiance`` and the like have no dataset quantity and are
    refused by name, as is a file whose mode cannot be told (rename it or export with the
    mode in the name).

Checks: the spectral data marker must be present, ``Number of Pixels in Spectrum`` must
equal the number of rows, ``XAxis mode`` (when given) must be ``Wavelengths``, and the
wavelengths must be strictly increasing. Rows whose wavelength is a detector's dead pixel
are not special: every row is kept.
"""

from __future__ import annotations

import os
import re
from pathlib import Path
from typing import Any

import numpy as np

from ..dataset import Measurement
from ._base import AdapterError, Format, check_count, decode, read_bytes, split_lines
from ._spectro import PERCENT, finish, number, spectrum_frame

__all__ = ["FORMATS", "read_oceanoptics"]

INSTRUMENT = "oceanoptics"

_BEGIN = re.compile(r">>>>>\s*Begin(?: Processed)? Spectral Data\s*<<<<<", re.IGNORECASE)
_END = re.compile(r">>>>>\s*End(?: Processed)? Spectral Data\s*<<<<<", re.IGNORECASE)
#: processing modes found in the ``Data from`` line or the file name -> (quantity, scale)
_MODES: tuple[tuple[re.Pattern[str], str, float], ...] = (
    (re.compile(r"absorbance", re.IGNORECASE), "absorbance", 1.0),
    (re.compile(r"transmi(?:ssion|ttance)", re.IGNORECASE), "transmittance", PERCENT),
    (re.compile(r"reflect(?:ion|ance)", re.IGNORECASE), "reflectance", PERCENT),
)
#: modes without a dataset quantity, refused by name
_REFUSED = re.compile(r"scope|irradiance|counts|fluorescence|raman", re.IGNORECASE)


def _sniff(head: bytes) -> bool:
    return _BEGIN.search(head.decode("latin-1")) is not None and (
        b"Spectrometer" in head
        or b"SpectraSuite" in head
        or b"OceanView" in head
        or b"Number of Pixels" in head
    )


def _mode(path: str | os.PathLike[str], data_from: str | None) -> tuple[str, float, str]:
    """Quantity, scale and where the processing mode was found."""
    stem = Path(path).name
    for where, text in (("the 'Data from' line", data_from or ""), ("the file name", stem)):
        for pattern, quantity, scale in _MODES:
            if pattern.search(text):
                return quantity, scale, where
        bad = _REFUSED.search(text)
        if bad:
            raise AdapterError(
                path,
                f"{where} says the spectrum is {bad.group(0)!r} (detector counts or an "
                "unreferenced signal), which has no labbrdf quantity; save it in Absorbance, "
                "Transmission or Reflection mode",
            )
    raise AdapterError(
        path,
        "the processing mode (Absorbance, Transmission, Reflection) is named neither in the "
        "'Data from' line nor in the file name; OceanView writes it in both. Put the mode in "
        "the file name, or declare the columns with --columns (command line) / columns= "
        "(Python) and --format columns / format='columns'",
    )


def read_oceanoptics(path: str | os.PathLike[str]) -> Measurement:
    """Read an OceanView / SpectraSuite tab-delimited export with header.

    Parameters
    ----------
    path : str or path-like
        The ``.txt`` export.

    Returns
    -------
    Measurement
        One spectrum against wavelength [nm]; ``meta["header"]`` holds the header fields.

    Raises
    ------
    AdapterError
        No spectral data marker, an unknown or count-like processing mode, a row that is not
        two numbers, a pixel count that disagrees with the rows, non-increasing wavelengths;
        with the line.
    """
    raw = read_bytes(path)
    text, encoding = decode(raw, path, ("utf-8", "cp1252"))
    lines = split_lines(text)
    begin = next((i for i, s in enumerate(lines) if _BEGIN.fullmatch(s.strip())), None)
    if begin is None:
        raise AdapterError(
            path, "no '>>>>>Begin Spectral Data<<<<<' line: not an Ocean Optics export"
        )
    header, data_from = _header(path, lines, begin)
    quantity, scale, basis = _mode(path, data_from)
    xs, ys = _rows(path, lines, begin)
    declared = header.get("Number of Pixels in Spectrum")
    if declared is not None:
        at = next(
            i for i, s in enumerate(lines[:begin], start=1) if s.startswith("Number of Pixels")
        )
        count = number(declared, path, at, "Number of Pixels in Spectrum")
        if count != len(xs):
            raise AdapterError(
                path,
                f"Number of Pixels in Spectrum is {declared} but the file has {len(xs)} rows "
                "(truncated?)",
                at,
            )
    x = np.asarray(xs)
    k = np.flatnonzero(np.diff(x) <= 0)
    if k.size:
        raise AdapterError(
            path,
            f"wavelength {x[k[0] + 1]:g} nm does not increase: the rows must be in pixel order",
            begin + 2 + int(k[0]) + 1,
        )
    if x[0] <= 0:
        raise AdapterError(path, f"wavelength {x[0]:g} nm: expected > 0", begin + 2)
    frame, dropped = spectrum_frame(
        path=path,
        sample=Path(path).stem,
        instrument=INSTRUMENT,
        quantity=quantity,
        scale=scale,
        x_nm=x,
        y=ys,
    )
    meta: dict[str, Any] = {
        "format": "oceanoptics-text",
        "encoding": encoding,
        "header": header,
        "quantity_from": basis,
        "percent": scale == PERCENT,
        "dropped_points": dropped,
    }
    return finish(path, [frame], meta)


def _header(
    path: str | os.PathLike[str], lines: list[str], begin: int
) -> tuple[dict[str, str], str | None]:
    """The ``key: value`` lines before the data marker, and the ``Data from`` line."""
    header: dict[str, str] = {}
    data_from = None
    for n, line in enumerate(lines[:begin], start=1):
        s = line.strip()
        if not s or set(s) <= {"+"}:
            continue
        if s.startswith("Data from"):
            data_from = s
            header["Data from"] = s[len("Data from") :].strip()[:1000]
            continue
        key, colon, value = s.partition(":")
        if colon:
            header[key.strip()[:200]] = value.strip()[:1000]
        elif n == 1:
            header["title"] = s[:1000]
    mode = header.get("XAxis mode")
    if mode is not None and mode.strip().lower() != "wavelengths":
        at = next(i for i, s in enumerate(lines[:begin], start=1) if s.startswith("XAxis"))
        raise AdapterError(
            path,
            f"XAxis mode {mode!r}: only Wavelengths is supported (save the spectrum with "
            "the wavelength axis)",
            at,
        )
    return header, data_from


def _rows(
    path: str | os.PathLike[str], lines: list[str], begin: int
) -> tuple[list[float], list[float]]:
    """The wavelength, value rows between the begin and end markers."""
    xs: list[float] = []
    ys: list[float] = []
    end = len(lines)
    for n in range(begin + 1, len(lines)):
        s = lines[n].strip()
        if not s:
            continue
        if _END.fullmatch(s):
            end = n
            break
        fields = s.split("\t")
        if len(fields) != 2:
            raise AdapterError(
                path,
                f"expected 2 TAB-separated fields (wavelength, value), found {len(fields)}",
                n + 1,
            )
        fields = [f.replace(",", ".", 1) if "." not in f else f for f in fields]
        xs.append(number(fields[0], path, n + 1, "wavelength"))
        ys.append(number(fields[1], path, n + 1, "value"))
        check_count(path, "rows", len(xs), line=n + 1)
    for n in range(end + 1, len(lines)):
        if lines[n].strip():
            raise AdapterError(
                path, f"text after the end of the spectral data: {lines[n].strip()[:30]!r}", n + 1
            )
    if not xs:
        raise AdapterError(path, "no data rows after the spectral data marker", begin + 1)
    return xs, ys


FORMATS = (
    Format(
        "oceanoptics-text",
        "Ocean Optics OceanView / SpectraSuite tab-delimited export with header",
        (".txt",),
        _sniff,
        read_oceanoptics,
        ("absorbance", "transmittance", "reflectance"),
        keywords=(b">>>>>Begin", b"Spectral Data<<<<<"),
    ),
)
