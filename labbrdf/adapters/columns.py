"""Generic numeric columns with declared meaning (headerless ``.txt``/``.csv``/``.dat``).

Many spectra reach a lab as bare columns of numbers, without a header that says what they
are (a spectrophotometer's table saved by hand, a colleague's CSV). Such a file cannot be
recognised, so it is read only when its columns are declared::

    labbrdf ingest MoS2.txt --format columns --columns wavelength_nm,absorbance
    labbrdf.read("MoS2.txt", columns="wavelength_nm,absorbance")

Column names (in file order, comma-separated or a sequence):

* exactly one abscissa: ``wavelength_nm``, ``wavelength_um`` (micrometres),
  ``wavenumber_cm-1`` (converted by lambda [nm] = 1e7 / nu [1/cm]) or ``energy_ev``
  (lambda [nm] = hc / E = 1239.841984 / E [eV], CODATA 2018);
* one or more ordinates: ``absorbance``, ``transmittance``, ``reflectance``,
  ``hemispherical_reflectance`` (fractions), or the same with ``_percent`` appended
  (``transmittance_percent``: divided by 100);
* ``skip`` for a column to ignore.

Every non-blank line that does not start with ``#`` must hold exactly as many numbers as
columns were declared. The separator is taken from the first data line: TAB, ``;``, ``,``
(when splitting on commas gives the declared number of fields), else blanks. With TAB,
``;`` or blank separators a decimal comma is read as a decimal point. A header line (text)
is refused with its line number, unless leading lines are skipped:

* ``skip_lines=N`` in the declaration (``--skip-lines N`` on the command line) skips the
  first N lines whatever they hold: a title line (header-less OceanView exports), the
  quoted header of a LI-COR LI-1800 ``.PRN``, the text header of an ASD ``.txt``/``.tsv``;
* ``skip_lines=auto`` (``--skip-lines auto``) skips every line before the first one that
  holds as many numbers as columns were declared.

The skipped lines are kept in ``meta["preamble"]`` and counted in ``meta["skipped_lines"]``,
with a note in ``meta["notes"]``. A table whose abscissa returns to its first value is the
same table twice (files joined) and is refused at the line where the copy starts. A last
line without line end whose last number is written shorter than its column is refused or
warned about (``check_last_field``).
"""

from __future__ import annotations

import os
import re
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ..dataset import Measurement
from ._base import DECIMAL, AdapterError, Format, check_count, decode, read_bytes, split_lines
from ._spectro import PERCENT, finish, number, spectrum_frame
from ._truncation import TAIL_ROWS, check_last_field, unterminated

__all__ = [
    "ABSCISSAE",
    "FORMATS",
    "ORDINATES",
    "SKIP_LINES",
    "parse_columns",
    "parse_skip_lines",
    "read_columns",
]

INSTRUMENT = "generic-columns"

#: h c [eV nm] (CODATA 2018, exact)
_HC_EV_NM = 1239.8419843320026

#: abscissa name -> function from the file's value to wavelength [nm]
ABSCISSAE: dict[str, Any] = {
    "wavelength_nm": lambda v: v,
    "wavelength_um": lambda v: v * 1000.0,
    "wavenumber_cm-1": lambda v: 1.0e7 / v,
    "energy_ev": lambda v: _HC_EV_NM / v,
}
#: ordinate name -> (quantity, scale)
ORDINATES: dict[str, tuple[str, float]] = {
    "absorbance": ("absorbance", 1.0),
    **{q: (q, 1.0) for q in ("transmittance", "reflectance", "hemispherical_reflectance")},
    **{
        f"{q}_percent": (q, PERCENT)
        for q in ("transmittance", "reflectance", "hemispherical_reflectance")
    },
}
_SKIP = "skip"
#: the setting of a declaration that skips leading lines
SKIP_LINES = "skip_lines"
_HINT = (
    "declare them with --columns on the command line or columns= in Python, e.g. "
    "--columns wavelength_nm,absorbance"
)


def _split_spec(spec: str | Sequence[str]) -> tuple[list[str], list[str]]:
    """(column names, ``key=value`` settings) of a declaration, stripped and lower-cased."""
    items = [s.strip().lower() for s in (spec.split(",") if isinstance(spec, str) else spec)]
    return [s for s in items if "=" not in s], [s for s in items if "=" in s]


def parse_columns(
    spec: str | Sequence[str], path: str | os.PathLike[str] = "<columns>"
) -> list[str]:
    """Check a column declaration and return it as a list of names.

    A ``skip_lines=N`` or ``skip_lines=auto`` entry is a setting, not a column
    (:func:`parse_skip_lines`), and is left out of the list.

    Raises
    ------
    AdapterError
        An unknown name, no or several abscissae, no ordinate, or a repeated ordinate.
    """
    names, _ = _split_spec(spec)
    parse_skip_lines(spec, path)
    known = [*ABSCISSAE, *ORDINATES, _SKIP]
    for name in names:
        if name not in known:
            raise AdapterError(
                path, f"--columns / columns=: unknown column {name!r}; expected one of {known}"
            )
    xs = [n for n in names if n in ABSCISSAE]
    ys = [n for n in names if n in ORDINATES]
    if len(xs) != 1:
        raise AdapterError(
            path,
            f"--columns / columns=: expected exactly one abscissa ({list(ABSCISSAE)}), "
            f"found {xs or 'none'}",
        )
    if not ys:
        raise AdapterError(
            path, f"--columns / columns=: expected at least one ordinate ({list(ORDINATES)})"
        )
    if len(set(ys)) != len(ys):
        raise AdapterError(path, f"--columns / columns=: an ordinate is repeated in {ys}")
    return names


def parse_skip_lines(
    spec: str | Sequence[str], path: str | os.PathLike[str] = "<columns>"
) -> int | str:
    """The leading lines a declaration skips: ``0``, a count, or ``"auto"``.

    ``skip_lines=N`` skips the first N lines whatever they hold (a title, a header);
    ``skip_lines=auto`` skips every line before the first one that holds as many numbers
    as columns were declared.

    Raises
    ------
    AdapterError
        An unknown setting, a repeated one, or a value that is not a count or ``auto``.
    """
    _, settings = _split_spec(spec)
    skip: int | str = 0
    for i, item in enumerate(settings):
        key, value = (t.strip() for t in item.split("=", 1))
        if key != SKIP_LINES or i:
            what = f"unknown setting {key!r}" if key != SKIP_LINES else "a repeated setting"
            raise AdapterError(
                path, f"--columns / columns=: {what} in {item!r}; expected {SKIP_LINES}=N|auto"
            )
        if value == "auto":
            skip = "auto"
        elif value.isdigit() and len(value) <= 9:
            skip = int(value)
        else:
            raise AdapterError(
                path,
                f"--columns / columns=: {SKIP_LINES}={value!r}: expected a number of lines "
                "(0 or more) or 'auto'",
            )
    return skip


def _separator(line: str, ncols: int) -> str | None:
    if "\t" in line:
        return "\t"
    if ";" in line:
        return ";"
    if "," in line and len(line.split(",")) == ncols:
        return ","
    return None  # blanks


def _split(line: str, sep: str | None) -> list[str]:
    """The fields of a stripped line; a decimal comma becomes a point unless ``,`` separates."""
    fields = line.split(sep) if sep is not None else line.split()
    if sep is not None:
        fields = [f.strip() for f in fields]
    if sep != ",":
        fields = [f.replace(",", ".", 1) if "." not in f else f for f in fields]
    return fields


def _is_row(line: str, ncols: int) -> bool:
    """Whether a line holds exactly ``ncols`` numbers (the first data row of ``auto``)."""
    s = line.strip()
    if not s or s.startswith("#"):
        return False
    fields = _split(s, _separator(s, ncols))
    return len(fields) == ncols and all(DECIMAL.fullmatch(f) for f in fields)


def _preamble(path: str | os.PathLike[str], lines: list[str], skip: int | str, ncols: int) -> int:
    """Number of leading lines to skip (``skip_lines``), checked against the file."""
    if skip == "auto":
        k = next((i for i, ln in enumerate(lines) if _is_row(ln, ncols)), None)
        if k is None:
            raise AdapterError(
                path,
                f"{SKIP_LINES}=auto: no line holds {ncols} numbers (the declared columns), so "
                "there is no data row to start from",
            )
        return k
    assert isinstance(skip, int)
    if skip >= len(lines):
        raise AdapterError(
            path, f"{SKIP_LINES}={skip} skips every line: the file has only {len(lines)}"
        )
    return skip


def _header_error(path: str | os.PathLike[str], s: str, n: int) -> AdapterError:
    return AdapterError(
        path,
        f"expected numbers, found the text {s[:40]!r} (a header?): the columns reader takes "
        "files without a header; remove the line or comment it with '#', or skip the "
        f"leading lines with --skip-lines N or --skip-lines auto ({SKIP_LINES}=N or "
        f"{SKIP_LINES}=auto in columns=)",
        n,
    )


def _rows(
    path: str | os.PathLike[str], lines: list[str], start: int, names: list[str], cut: bool
) -> tuple[str | None, list[list[float]], list[int], list[str]]:
    """(separator, rows, their 1-based line numbers, warnings) of the data lines."""
    ncols = len(names)
    sep: str | None = None
    rows: list[list[float]] = []
    lines_of: list[int] = []
    notes: list[str] = []
    for n, line in enumerate(lines[start:], start=start + 1):
        s = line.strip()
        if not s or s.startswith("#"):
            continue
        if sep is None and not rows:
            sep = _separator(s, ncols)
        fields = _split(s, sep)
        if not rows and not re.match(r"[+\-.0-9]", fields[0]):
            raise _header_error(path, s, n)
        if cut and n == len(lines):  # the last line has no line end: cut mid-number?
            previous = [lines[i - 1] for i in lines_of[-TAIL_ROWS:]]
            note = check_last_field(path, line, previous, n, sep)
            notes.extend([note] if note else [])
        if len(fields) != ncols:
            shown = "TAB" if sep == "\t" else repr(sep) if sep else "blanks"
            raise AdapterError(
                path,
                f"expected {ncols} fields ({','.join(names)}) separated by {shown}, found "
                f"{len(fields)} in {s[:40]!r}",
                n,
            )
        rows.append(
            [
                number(f, path, n, name) if name != _SKIP else 0.0
                for f, name in zip(fields, names, strict=True)
            ]
        )
        lines_of.append(n)
        check_count(path, "rows", len(rows), line=n)
    return sep, rows, lines_of, notes


def _check_abscissa(
    path: str | os.PathLike[str], xname: str, xv: np.ndarray, lines_of: list[int]
) -> None:
    """Positive and strictly monotonic; a return to the first value is a repeated table."""
    bad = np.flatnonzero(xv <= 0)
    if bad.size:
        raise AdapterError(
            path, f"{xname} {xv[bad[0]]:g}: expected a positive value", lines_of[bad[0]]
        )
    if xv.size < 2:
        return
    step = np.diff(xv)
    sign = 1.0 if step[0] > 0 else -1.0
    k = np.flatnonzero(step * sign <= 0)
    if not k.size:
        return
    i = int(k[0]) + 1
    if xv[i] == xv[0] and i > 1:
        raise AdapterError(
            path,
            f"{xname} {xv[i]:g} starts the column again (first row: line {lines_of[0]}): the "
            "table is in the file twice from here (files joined?); keep one copy",
            lines_of[i],
        )
    raise AdapterError(
        path,
        f"{xname} {xv[i]:g} repeats or breaks the order of the column: the abscissa must be "
        "strictly increasing or decreasing",
        lines_of[i],
    )


def read_columns(
    path: str | os.PathLike[str],
    columns: str | Sequence[str] | None = None,
    *,
    skip_lines: int | str | None = None,
) -> Measurement:
    """Read a headerless table of numbers whose columns are declared.

    Parameters
    ----------
    path : str or path-like
        The file.
    columns : str or sequence of str
        Column names in file order (see the module docstring), e.g.
        ``"wavelength_nm,absorbance"``; may hold a ``skip_lines=N|auto`` entry.
    skip_lines : int or "auto", optional
        Leading lines to skip (a title or header); overrides a ``skip_lines`` entry of
        ``columns``. ``"auto"`` skips every line before the first that holds as many
        numbers as columns were declared.

    Returns
    -------
    Measurement
        One spectrum per ordinate column against wavelength [nm]; ``sample`` is the file
        stem. ``meta["skipped_lines"]`` counts the skipped leading lines and
        ``meta["preamble"]`` holds them (the first 50, 200 characters each);
        ``meta["warnings"]`` holds doubts (a last number that may be cut short).

    Raises
    ------
    AdapterError
        No or a wrong declaration, a line with another number of fields or a non-number,
        a non-positive abscissa, repeated wavelengths (or the whole table twice), a last
        number cut short; with the line.
    """
    if columns is None:
        raise AdapterError(path, f"the columns of a generic column file are not declared; {_HINT}")
    names = parse_columns(columns, path)
    skip = parse_skip_lines(columns, path) if skip_lines is None else skip_lines
    if skip != "auto" and not (isinstance(skip, int) and skip >= 0):
        raise AdapterError(path, f"skip_lines={skip!r}: expected a count of lines or 'auto'")
    raw = read_bytes(path)
    text, encoding = decode(raw, path, ("utf-8", "cp1252"))
    lines = split_lines(text)
    start = _preamble(path, lines, skip, len(names))
    sep, rows, lines_of, notes = _rows(path, lines, start, names, unterminated(text))
    if not rows:
        raise AdapterError(path, "no data rows (only blank or '#' lines)")
    table = np.asarray(rows, dtype=float)
    xi = next(i for i, nm in enumerate(names) if nm in ABSCISSAE)
    _check_abscissa(path, names[xi], table[:, xi], lines_of)
    x = ABSCISSAE[names[xi]](table[:, xi])
    frames, dropped = [], 0
    stem = Path(path).stem
    for i, name in enumerate(names):
        if name not in ORDINATES:
            continue
        quantity, scale = ORDINATES[name]
        frame, d = spectrum_frame(
            path=path,
            sample=stem,
            instrument=INSTRUMENT,
            quantity=quantity,
            scale=scale,
            x_nm=x,
            y=table[:, i],
        )
        frames.append(frame)
        dropped += d
    separator = {"\t": "TAB", ";": ";", ",": ",", None: "blanks"}[sep]
    meta: dict[str, Any] = {
        "format": "columns",
        "encoding": encoding,
        "columns": names,
        "separator": separator,
        "rows": len(rows),
        "dropped_points": dropped,
    }
    if start:
        meta["skipped_lines"] = start
        meta["preamble"] = [ln[:200] for ln in lines[: min(start, 50)]]
        meta["notes"] = [
            f"{'line 1' if start == 1 else f'lines 1-{start}'} skipped as a preamble "
            f"({SKIP_LINES}={skip}); data from line {lines_of[0]}"
        ]
    if notes:
        meta["warnings"] = notes
    return finish(path, frames, meta)


def _never(head: bytes) -> bool:
    """Bare numbers say nothing of what they are: never claimed by content."""
    return False


def _undeclared(path: str | os.PathLike[str]) -> Measurement:
    return read_columns(path, None)


FORMATS = (
    Format(
        "columns",
        "generic headerless numeric columns, declared with --columns / columns=",
        (),
        _never,
        _undeclared,
        ("absorbance", "transmittance", "reflectance", "hemispherical_reflectance"),
    ),
)
