"""Ocean Optics (Ocean Insight) text exports: OceanView / SpectraSuite, Jaz, Raspberry Pi.

OceanView and SpectraSuite (``oceanoptics-text``, ``.txt``)
    Header lines ``Key: value`` (``Data from <name> Node``, ``Date``, ``User``,
    ``Spectrometer``, ``Integration Time (sec)`` or ``(usec)``, ``Scans to average``,
    ``Boxcar width``, ``XAxis mode``, ``Number of Pixels in Spectrum``; SpectraSuite starts
    with ``SpectraSuite Data File`` and a line of ``+`` signs), then the line
    ``>>>>>Begin Spectral Data<<<<<`` (SpectraSuite: ``>>>>>Begin Processed Spectral
    Data<<<<<``), then one ``wavelength<TAB>value`` row per detector pixel, and in
    SpectraSuite a closing ``>>>>>End Processed Spectral Data<<<<<``. Numbers follow the
    Windows locale: a decimal comma is read as a decimal point (the separator is a TAB).

    The export does not name its processing mode in a header field; OceanView puts it in
    the default file name (``..._Absorbance_10-54-38-373.txt``) and repeats it in ``Data
    from ... Node``. The reader looks for ``Absorbance``, ``Transmission``/``Transmittance``,
    ``Reflection``/``Reflectance`` in the ``Data from`` line, then in the file name.
    Transmission and reflection are percent in both programs (divided by 100).
    ``Scope``/``Scope Minus Dark`` (raw detector counts), ``Irradiance`` and the like have
    no dataset quantity and are refused by name, as is a file whose mode cannot be told.

    Header-less exports (one title line, then ``wavelength<TAB>value`` rows) carry no
    marker, so no sniffer claims them; with the format forced they are read when the title
    or the file name names the mode, else refused with the advice to declare the columns
    (``--columns``).

Jaz (``oceanoptics-jaz``, ``.jaz``)
    ``Jaz Data File``, a line of ``+``, ``Key: value`` lines (``Dark Spectrum Present``,
    ``Reference Spectrum Present``, ``Processed Spectrum Present``, ``Spectrometers``,
    ``Integration Time (usec): 232000 (JAZA3098)``, ..., ``Number of Pixels in Processed
    Spectrum``), ``>>>>>Begin Processed Spectral Data<<<<<``, a column line ``W D R S P``
    (wavelength, dark, reference, sample, processed; TAB-separated) and one row per pixel,
    closed by ``>>>>>End Processed Spectral Data<<<<<``. The header does not name the
    processing; the reader finds it from the columns: every row with ``R - D > 0`` must
    satisfy ``P = 100 (S - D) / (R - D)`` (a percent ratio to the reference: reflectance or
    transmittance, which the file name must then say, as ``oceanoptics-text`` does) or
    ``P = -log10((S - D) / (R - D))`` (absorbance); a row where they disagree is refused at
    its line. Rows with ``R - D <= 0`` (the all-zero first pixels, noise at the UV end) have
    no defined ratio: they are dropped, counted in ``meta["dropped_points"]`` and named in
    ``meta["notes"]``. The dark, reference and sample counts are kept in
    ``meta["counts"]``. ``Jaz Irradiance`` files and files without a ``P`` column (raw
    counts) are refused by name.

Raspberry Pi (``oceanoptics-pi``, ``.pi``, refused)
    ``Saved at time: <ms> milliseconds``, ``Integration time``, ``Scans to average``,
    ``Boxcar smoothing``, then ``Wavelengths<TAB>Intensities``: raw detector intensities
    without dark or reference, which have no dataset quantity. Recognised and refused with
    the exports that work.

Checks: the spectral data marker must be present, a declared pixel count (``Number of
Pixels in Spectrum`` / ``in Processed Spectrum``) must be at most
``MAX_POINTS`` and fit the file's size, both checked before
the data are read, and must equal the number of rows; ``XAxis mode`` (when given) must be
``Wavelengths``, and the wavelengths must be strictly increasing.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..dataset import Measurement
from ._base import (
    MAX_POINTS,
    AdapterError,
    Format,
    check_count,
    check_regular_file,
    decode,
    read_bytes,
    read_head,
    split_lines,
)
from ._spectro import PERCENT, finish, number, spectrum_frame
from ._truncation import check_joined, check_last_row

__all__ = ["FORMATS", "read_jaz", "read_oceanoptics", "refuse_raspberry_pi"]

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
#: the header is read from this many first bytes, before the data are
_HEAD_BYTES = 1 << 16
#: most bytes one data row takes (a row of five long numbers with blanks): the data after
#: the header may not be much longer than the declared pixel count of such rows
_MAX_ROW_BYTES = 256
#: bytes allowed after the rows besides them (end marker, blank lines)
_TAIL_BYTES = 4096
_COLUMNS_HINT = (
    "declare the columns with --columns on the command line or columns= in Python "
    "(format 'columns'), e.g. --columns wavelength_nm,absorbance"
)


def _sniff(head: bytes) -> bool:
    if head.startswith(b"Jaz "):
        return False
    return _BEGIN.search(head.decode("latin-1")) is not None and (
        b"Spectrometer" in head
        or b"SpectraSuite" in head
        or b"OceanView" in head
        or b"Number of Pixels" in head
    )


def _sniff_jaz(head: bytes) -> bool:
    return (
        head.lstrip(b"\xef\xbb\xbf").startswith(b"Jaz ")
        and _BEGIN.search(head.decode("latin-1")) is not None
    )


def _sniff_pi(head: bytes) -> bool:
    text = head.decode("latin-1")
    return re.match(r"(?:[^\n]*sequence[^\n]*\n)?Saved at time: ", text) is not None and (
        re.search(r"^Wavelengths\tIntensities\s*$", text, re.MULTILINE) is not None
    )


def _mode_from(
    path: str | os.PathLike[str], places: list[tuple[str, str]]
) -> tuple[str, float, str] | None:
    """Quantity, scale and where, from the first place that names a mode; None if none."""
    for where, text in places:
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
    return None


def _mode(path: str | os.PathLike[str], data_from: str | None) -> tuple[str, float, str]:
    """Quantity, scale and where the processing mode was found."""
    found = _mode_from(
        path, [("the 'Data from' line", data_from or ""), ("the file name", Path(path).name)]
    )
    if found is None:
        raise AdapterError(
            path,
            "the processing mode (Absorbance, Transmission, Reflection) is named neither in "
            "the 'Data from' line nor in the file name; OceanView writes it in both. Put the "
            "mode in the file name, or " + _COLUMNS_HINT,
        )
    return found


@dataclass(frozen=True)
class _Text:
    """A marked export read after its declared size was checked."""

    lines: list[str]
    encoding: str
    begin: int | None  # 0-based index of the begin marker line, None without one
    declared: int | None  # declared pixel count
    declared_at: int | None  # its 1-based line
    declared_key: str = "Number of Pixels"  # the header key as written
    text: str = ""  # the whole file (is its last line cut short?)


_DECLARED = re.compile(r"(Number of Pixels in (?:Processed )?Spectrum)\s*:\s*(.*)", re.IGNORECASE)


def _declared(path: str | os.PathLike[str], head: list[str]) -> tuple[int | None, int | None, str]:
    """The pixel count the header declares, its line and key, checked against the cap."""
    for n, line in enumerate(head, start=1):
        m = _DECLARED.match(line.strip())
        if m:
            key = m.group(1)
            value = number(m.group(2), path, n, key)
            if value != int(value):
                raise AdapterError(path, f"{key} {m.group(2)!r}: expected a count", n)
            return check_count(path, key, int(value), line=n), n, key
    return None, None, "Number of Pixels"


def _load(path: str | os.PathLike[str]) -> _Text:
    """Check the declared size against the cap and the file size, then read the file.

    A header that declares more pixels than :data:`MAX_POINTS`, or a file far larger or
    smaller than its declared rows can take, is refused from its first bytes alone.
    """
    check_regular_file(path)
    size = os.stat(path).st_size
    try:
        with open(path, "rb") as fh:
            first = fh.read(_HEAD_BYTES)
    except OSError as exc:
        raise AdapterError(path, f"cannot be read ({exc.strerror or exc})") from None
    head = split_lines(first.decode("latin-1"))
    begin = next((i for i, s in enumerate(head) if _BEGIN.fullmatch(s.strip())), None)
    declared, at, key = _declared(path, head[:begin] if begin is not None else head[:50])
    if declared is not None and begin is not None:
        body = size - len("\n".join(head[: begin + 1]).encode("latin-1"))
        if body > declared * _MAX_ROW_BYTES + _TAIL_BYTES:
            raise AdapterError(
                path,
                f"{key} is {declared} but {body} bytes of data follow, more than "
                f"{declared} rows can take: the file holds more than its header declares",
                at,
            )
    elif size > MAX_POINTS * _MAX_ROW_BYTES:
        raise AdapterError(
            path,
            f"{size} bytes with no declared pixel count: more than {MAX_POINTS} rows can take",
        )
    text, encoding = decode(read_bytes(path), path, ("utf-8", "cp1252"))
    lines = split_lines(text)
    check_joined(path, lines)
    begin = next((i for i, s in enumerate(lines) if _BEGIN.fullmatch(s.strip())), None)
    return _Text(lines, encoding, begin, declared, at, key, text)


def read_oceanoptics(path: str | os.PathLike[str]) -> Measurement:
    """Read an OceanView / SpectraSuite tab-delimited export, with header or header-less.

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
        No spectral data marker (and not a header-less export whose title or name gives the
        mode), an unknown or count-like processing mode, a row that is not two numbers, a
        declared pixel count above the cap or disagreeing with the rows, non-increasing
        wavelengths; with the line.
    """
    t = _load(path)
    if t.begin is None:
        return _read_headerless(path, t)
    header, data_from = _header(path, t.lines, t.begin)
    quantity, scale, basis = _mode(path, data_from)
    x, ys, doubts = _pairs(path, t)
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
        "encoding": t.encoding,
        "header": header,
        "quantity_from": basis,
        "percent": scale == PERCENT,
        "dropped_points": dropped,
    }
    if doubts:
        meta["warnings"] = doubts
    return finish(path, [frame], meta)


def _pairs(path: str | os.PathLike[str], t: _Text) -> tuple[np.ndarray, list[float], list[str]]:
    """The checked wavelength and value rows of a marked export, and doubts about them."""
    assert t.begin is not None
    rows, first = _rows(path, t.lines, t.begin + 1, 2, t.declared)
    doubt = check_last_row(path, t.text, t.lines, first, "\t")
    _check_declared(path, t, len(rows))
    x = np.asarray([r[0] for r in rows])
    _increasing(path, x, first)
    return x, [r[1] for r in rows], [doubt] if doubt else []


def _check_declared(path: str | os.PathLike[str], t: _Text, n: int) -> None:
    if t.declared is not None and t.declared != n:
        raise AdapterError(
            path,
            f"{t.declared_key} is {t.declared} but the file has {n} rows (truncated?)",
            t.declared_at,
        )


def _increasing(path: str | os.PathLike[str], x: np.ndarray, first: list[int]) -> None:
    """Wavelengths > 0 and strictly increasing; ``first[i]`` is row i's 1-based line."""
    k = np.flatnonzero(np.diff(x) <= 0)
    if k.size:
        raise AdapterError(
            path,
            f"wavelength {x[k[0] + 1]:g} nm does not increase: the rows must be in pixel order",
            first[int(k[0]) + 1],
        )
    if x.size and x[0] <= 0:
        raise AdapterError(path, f"wavelength {x[0]:g} nm: expected > 0", first[0])


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


def _field(text: str, path: str | os.PathLike[str], line: int, what: str) -> float:
    """One number; a decimal comma (Windows locale) is read as a decimal point."""
    if "." not in text:
        text = text.replace(",", ".", 1)
    return number(text, path, line, what)


_NAMES = ("wavelength", "value")


def _rows(
    path: str | os.PathLike[str],
    lines: list[str],
    start: int,
    ncols: int,
    declared: int | None,
    names: tuple[str, ...] = _NAMES,
) -> tuple[list[list[float]], list[int]]:
    """The TAB-separated rows from ``lines[start]`` to the end marker, and their lines.

    Never more rows than ``declared`` (or :data:`MAX_POINTS`): the first row beyond is
    refused at its line, before it is parsed.
    """
    rows: list[list[float]] = []
    at: list[int] = []
    end = len(lines)
    limit = declared if declared is not None else MAX_POINTS
    for n in range(start, len(lines)):
        s = lines[n].strip()
        if not s:
            continue
        if _END.fullmatch(s):
            end = n
            break
        if len(rows) == limit:
            what = f"the declared {declared}" if declared is not None else f"{MAX_POINTS}"
            raise AdapterError(path, f"more data rows than {what}", n + 1)
        fields = s.split("\t")
        if len(fields) != ncols:
            raise AdapterError(
                path,
                f"expected {ncols} TAB-separated fields ({', '.join(names)}), found {len(fields)}",
                n + 1,
            )
        rows.append([_field(f, path, n + 1, names[j]) for j, f in enumerate(fields)])
        at.append(n + 1)
    for n in range(end + 1, len(lines)):
        if lines[n].strip():
            raise AdapterError(
                path, f"text after the end of the spectral data: {lines[n].strip()[:30]!r}", n + 1
            )
    if not rows:
        raise AdapterError(path, "no data rows after the spectral data marker", start)
    return rows, at


# ------------------------------------------------------------------ header-less OceanView

#: most non-numeric lines before the rows of a header-less export
_MAX_TITLE_LINES = 5
_NUMERIC_ROW = re.compile(r"\s*[-+0-9.,eE]+(?:\t|\s+)[-+0-9.,eE]+\s*")


def _read_headerless(path: str | os.PathLike[str], t: _Text) -> Measurement:
    """A title line (or a few), then ``wavelength<TAB>value`` rows (format forced)."""
    lines = t.lines
    first = next((i for i, s in enumerate(lines) if _NUMERIC_ROW.fullmatch(s)), None)
    title = [s.strip() for s in lines[: first or 0] if s.strip()]
    if first is None or len(title) > _MAX_TITLE_LINES:
        raise AdapterError(
            path,
            "no '>>>>>Begin Spectral Data<<<<<' line and no header-less table (a title line, "
            "then wavelength<TAB>value rows): not an Ocean Optics export",
        )
    found = _mode_from(
        path, [("the title line", " ".join(title)), ("the file name", Path(path).name)]
    )
    if found is None:
        raise AdapterError(
            path,
            "a header-less export (title line, then two columns) whose title and file name "
            "name no processing mode (Absorbance, Transmission, Reflection): "
            + _COLUMNS_HINT
            + " and skip the title line",
            1,
        )
    quantity, scale, basis = found
    rows, at = _headerless_rows(path, lines, first)
    doubt = check_last_row(path, t.text, lines, at, "\t" if "\t" in lines[-1] else None)
    x = np.asarray([r[0] for r in rows])
    _increasing(path, x, at)
    frame, dropped = spectrum_frame(
        path=path,
        sample=Path(path).stem,
        instrument=INSTRUMENT,
        quantity=quantity,
        scale=scale,
        x_nm=x,
        y=[r[1] for r in rows],
    )
    meta: dict[str, Any] = {
        "format": "oceanoptics-text",
        "encoding": t.encoding,
        "header": {"title": " / ".join(title)[:1000]},
        "quantity_from": basis,
        "percent": scale == PERCENT,
        "dropped_points": dropped,
        "layout": "header-less (title line, then two columns)",
    }
    if doubt:
        meta["warnings"] = [doubt]
    return finish(path, [frame], meta)


def _headerless_rows(
    path: str | os.PathLike[str], lines: list[str], first: int
) -> tuple[list[list[float]], list[int]]:
    rows: list[list[float]] = []
    at: list[int] = []
    for n in range(first, len(lines)):
        s = lines[n].strip()
        if not s:
            continue
        if len(rows) == MAX_POINTS:
            raise AdapterError(path, f"more than {MAX_POINTS} data rows", n + 1)
        fields = s.split("\t") if "\t" in s else s.split()
        if len(fields) != 2:
            raise AdapterError(
                path,
                f"expected 2 fields (wavelength, value), found {len(fields)}",
                n + 1,
            )
        rows.append([_field(f, path, n + 1, _NAMES[j]) for j, f in enumerate(fields)])
        at.append(n + 1)
    return rows, at


# ------------------------------------------------------------------------------------ Jaz

_JAZ_COLUMNS = {"W": "wavelength", "D": "dark", "R": "reference", "S": "sample", "P": "processed"}


def read_jaz(path: str | os.PathLike[str]) -> Measurement:
    """Read an Ocean Optics Jaz processed spectrum (``Jaz Data File``, columns W D R S P).

    Parameters
    ----------
    path : str or path-like
        The ``.jaz`` file.

    Returns
    -------
    Measurement
        The processed column as reflectance or transmittance (fraction; which one from the
        file name, the ratio checked on every row) or absorbance, against wavelength [nm].
        ``meta["counts"]`` holds the wavelength [nm], dark, reference and sample [counts]
        of every row of the file; rows with ``R - D <= 0`` are dropped and counted in
        ``meta["dropped_points"]``, with a note in ``meta["notes"]``.

    Raises
    ------
    AdapterError
        An irradiance or raw-counts Jaz file (refused by name), a column line other than
        W D R S P, a row whose P disagrees with its counts, a percent ratio whose file name
        names neither reflectance nor transmittance, a pixel count above the cap or
        disagreeing with the rows; with the line.
    """
    t = _load(path)
    if t.begin is None:
        raise AdapterError(path, "no '>>>>>Begin Processed Spectral Data<<<<<' line")
    title = t.lines[0].strip()
    if not title.startswith("Jaz"):
        raise AdapterError(path, f"first line {title[:40]!r}: expected 'Jaz Data File'", 1)
    if re.search(r"irradiance", title, re.IGNORECASE):
        raise AdapterError(
            path,
            f"a Jaz irradiance file ({title[:40]!r}): spectral irradiance has no labbrdf "
            "quantity; save the spectrum in reflection, transmission or absorbance mode",
            1,
        )
    header, _ = _header(path, t.lines, t.begin)
    names = _jaz_columns(path, t)
    rows, at = _rows(path, t.lines, t.begin + 2, len(names), t.declared, tuple(names))
    doubt = check_last_row(path, t.text, t.lines, at, "\t")
    _check_declared(path, t, len(rows))
    a = np.asarray(rows, dtype=float)
    _increasing(path, a[:, 0], at)
    m = _jaz_measurement(path, t, header, a, at)
    if doubt:
        m.meta["warnings"] = [doubt]
    return m


def _jaz_columns(path: str | os.PathLike[str], t: _Text) -> list[str]:
    assert t.begin is not None
    n = t.begin + 1
    line = t.lines[n].strip() if n < len(t.lines) else ""
    letters = line.split("\t")
    if letters == ["W", "S"] or "P" not in letters and set(letters) <= set(_JAZ_COLUMNS):
        raise AdapterError(
            path,
            f"columns {' '.join(letters)!r} and no processed column P: raw detector counts, "
            "which have no labbrdf quantity; save the Jaz spectrum with a dark and a "
            "reference (reflection, transmission or absorbance mode)",
            n + 1,
        )
    if letters != list(_JAZ_COLUMNS):
        raise AdapterError(
            path,
            f"column line {line[:40]!r}: expected 'W<TAB>D<TAB>R<TAB>S<TAB>P' (wavelength, "
            "dark, reference, sample, processed)",
            n + 1,
        )
    return [_JAZ_COLUMNS[c] for c in letters]


def _jaz_processing(
    path: str | os.PathLike[str], a: np.ndarray, at: list[int]
) -> tuple[str, np.ndarray]:
    """``"percent"`` or ``"absorbance"`` from the columns, and the rows that have a ratio.

    Every row with ``R - D > 0`` (and, for absorbance, ``S - D > 0``) must agree with the
    processing within the rounding of the printed counts; the first that does not is
    refused at its line.
    """
    w, d, r, s, p = a.T
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = (s - d) / (r - d)
        valid = (r - d) > 0
        # rounding of 6-decimal float32 counts, amplified where R - D is small
        tol = 2e-5 * np.abs(p) + 1e-4 * (1 + np.abs(ratio)) / np.abs(r - d) + 1e-5
        percent_ok = np.abs(p - 100 * ratio) <= tol
        absorb = valid & (ratio > 0)
        log_ok = np.abs(p + np.log10(ratio)) <= tol / np.maximum(np.abs(ratio), 1e-300)
    if not valid.any():
        raise AdapterError(path, "no row has reference above dark (R - D > 0): no ratio")
    if np.all(percent_ok[valid]):
        return "percent", valid
    if absorb.any() and np.all(log_ok[absorb]) and np.count_nonzero(absorb) > valid.sum() / 2:
        return "absorbance", absorb
    bad_pct = np.flatnonzero(valid & ~percent_ok)
    bad_abs = np.flatnonzero(absorb & ~log_ok)
    i = int((bad_pct if bad_pct.size <= bad_abs.size else bad_abs)[0])
    raise AdapterError(
        path,
        f"P = {p[i]:g} agrees neither with 100 (S - D) / (R - D) = {100 * ratio[i]:g} nor "
        f"with -log10((S - D) / (R - D)): the columns contradict each other",
        at[i],
    )


def _jaz_measurement(
    path: str | os.PathLike[str],
    t: _Text,
    header: dict[str, str],
    a: np.ndarray,
    at: list[int],
) -> Measurement:
    processing, keep = _jaz_processing(path, a, at)
    if processing == "percent":
        quantity, scale, basis = _jaz_percent_mode(path)
    else:
        quantity, scale = "absorbance", 1.0
        basis = "the processing: P = -log10((S - D) / (R - D)) on every row"
    dropped = int(np.count_nonzero(~keep))
    notes = []
    if dropped:
        lines = [at[i] for i in np.flatnonzero(~keep)]
        shown = ", ".join(map(str, lines[:10])) + (", ..." if len(lines) > 10 else "")
        notes.append(
            f"{dropped} rows dropped where the reference is not above the dark "
            f"(R - D <= 0{', or S - D <= 0 for absorbance' if processing != 'percent' else ''}"
            f"): no defined ratio (lines {shown})"
        )
    frame, nonfinite = spectrum_frame(
        path=path,
        sample=Path(path).stem,
        instrument=INSTRUMENT,
        quantity=quantity,
        scale=scale,
        x_nm=a[keep, 0],
        y=a[keep, 4],
    )
    meta: dict[str, Any] = {
        "format": "oceanoptics-jaz",
        "encoding": t.encoding,
        "header": header,
        "quantity_from": basis,
        "percent": scale == PERCENT,
        "dropped_points": dropped + nonfinite,
        "notes": notes,
        "counts": {
            "unit": "counts",
            **{k: a[:, j].tolist() for j, k in enumerate(("wavelength_nm", "dark", "reference"))},
            "sample": a[:, 3].tolist(),
        },
    }
    return finish(path, [frame], meta)


def _jaz_percent_mode(path: str | os.PathLike[str]) -> tuple[str, float, str]:
    """Reflectance or transmittance for a percent ratio: the header does not say which."""
    found = _mode_from(path, [("the file name", Path(path).name)])
    checked = "; the processing, P = 100 (S - D) / (R - D), checked on every row"
    if found is None:
        raise AdapterError(
            path,
            "P is 100 (S - D) / (R - D), a percent ratio to the reference, but neither the "
            "header nor the file name says whether it is reflectance or transmittance; put "
            "Reflectance or Transmittance in the file name",
        )
    quantity, scale, basis = found
    if quantity == "absorbance":
        raise AdapterError(
            path,
            "the file name says absorbance but P is 100 (S - D) / (R - D), a percent ratio "
            "(reflectance or transmittance): rename the file with the mode it was saved in",
        )
    return quantity, scale, basis + checked


# --------------------------------------------------------------------------- Raspberry Pi


def refuse_raspberry_pi(path: str | os.PathLike[str]) -> Measurement:
    """Refuse an Ocean Optics Raspberry Pi spectrum (``.pi``) with the exports that work.

    Raises
    ------
    AdapterError
        Always: the file's raw intensities have no labbrdf quantity (or it is not this
        layout at all).
    """
    head = read_head(path)
    if not _sniff_pi(head):
        raise AdapterError(
            path,
            "not an Ocean Optics Raspberry Pi spectrum: expected 'Saved at time:' header "
            "lines and a 'Wavelengths<TAB>Intensities' column line",
        )
    raise AdapterError(
        path,
        "an Ocean Optics Raspberry Pi spectrum (.pi, 'Wavelengths<TAB>Intensities'): raw "
        "detector intensities without a dark or a reference, which have no labbrdf quantity; "
        "measure a dark and a reference and save the processed spectrum (OceanView's "
        "Absorbance, Transmission or Reflection text export, format 'oceanoptics-text'), or "
        "compute it yourself and " + _COLUMNS_HINT,
    )


FORMATS = (
    Format(
        "oceanoptics-text",
        "Ocean Optics OceanView / SpectraSuite tab-delimited export (with header, or a "
        "title line and two columns when forced)",
        (".txt",),
        _sniff,
        read_oceanoptics,
        ("absorbance", "transmittance", "reflectance"),
        keywords=(b">>>>>Begin", b"Spectral Data<<<<<"),
    ),
    Format(
        "oceanoptics-jaz",
        "Ocean Optics Jaz processed spectrum (W D R S P columns)",
        (".jaz",),
        _sniff_jaz,
        read_jaz,
        ("absorbance", "transmittance", "reflectance"),
        keywords=(b"Jaz Data File",),
        states_count=True,
    ),
    Format(
        "oceanoptics-pi",
        "Ocean Optics Raspberry Pi raw spectrum (.pi): recognised and refused (raw counts)",
        (".pi",),
        _sniff_pi,
        refuse_raspberry_pi,
        (),
        keywords=(b"Saved at time:", b"Wavelengths\tIntensities"),
    ),
)
