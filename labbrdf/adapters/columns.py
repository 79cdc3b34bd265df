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
is refused with its line number: this reader is for files that have none.
"""

from __future__ import annotations

import os
import re
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ..dataset import Measurement
from ._base import AdapterError, Format, check_count, decode, read_bytes, split_lines
from ._spectro import PERCENT, finish, number, spectrum_frame

__all__ = ["ABSCISSAE", "FORMATS", "ORDINATES", "parse_columns", "read_columns"]

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
_HINT = (
    "declare them with --columns on the command line or columns= in Python, e.g. "
    "--columns wavelength_nm,absorbance"
)


def parse_columns(
    spec: str | Sequence[str], path: str | os.PathLike[str] = "<columns>"
) -> list[str]:
    """Check a column declaration and return it as a list of names.

    Raises
    ------
    AdapterError
        An unknown name, no or several abscissae, no ordinate, or a repeated ordinate.
    """
    names = [s.strip().lower() for s in (spec.split(",") if isinstance(spec, str) else spec)]
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


def _separator(line: str, ncols: int) -> str | None:
    if "\t" in line:
        return "\t"
    if ";" in line:
        return ";"
    if "," in line and len(line.split(",")) == ncols:
        return ","
    return None  # blanks


def read_columns(
    path: str | os.PathLike[str], columns: str | Sequence[str] | None = None
) -> Measurement:
    """Read a headerless table of numbers whose columns are declared.

    Parameters
    ----------
    path : str or path-like
        The file.
    columns : str or sequence of str
        Column names in file order (see the module docstring), e.g.
        ``"wavelength_nm,absorbance"``.

    Returns
    -------
    Measurement
        One spectrum per ordinate column against wavelength [nm]; ``sample`` is the file
        stem.

    Raises
    ------
    AdapterError
        No or a wrong declaration, a line with another number of fields or a non-number,
        a non-positive abscissa, repeated wavelengths; with the line.
    """
    if columns is None:
        raise AdapterError(path, f"the columns of a generic column file are not declared; {_HINT}")
    names = parse_columns(columns, path)
    raw = read_bytes(path)
    text, encoding = decode(raw, path, ("utf-8", "cp1252"))
    ncols = len(names)
    sep: str | None = None
    rows: list[list[float]] = []
    lines_of: list[int] = []
    for n, line in enumerate(split_lines(text), start=1):
        s = line.strip()
        if not s or s.startswith("#"):
            continue
        if sep is None and not rows:
            sep = _separator(s, ncols)
        fields = s.split(sep) if sep is not None else s.split()
        if sep is not None:
            fields = [f.strip() for f in fields]
        if len(fields) != ncols:
            shown = "TAB" if sep == "\t" else repr(sep) if sep else "blanks"
            raise AdapterError(
                path,
                f"expected {ncols} fields ({','.join(names)}) separated by {shown}, found "
                f"{len(fields)} in {s[:40]!r}",
                n,
            )
        if sep != ",":
            fields = [f.replace(",", ".", 1) if "." not in f else f for f in fields]
        if not rows and not re.match(r"[+\-.0-9]", fields[0]):
            raise AdapterError(
                path,
                f"expected numbers, found the text {s[:40]!r} (a header?): the columns reader "
                "takes files without a header; remove the line or comment it with '#'",
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
    if not rows:
        raise AdapterError(path, "no data rows (only blank or '#' lines)")
    table = np.asarray(rows, dtype=float)
    xi = next(i for i, nm in enumerate(names) if nm in ABSCISSAE)
    xname = names[xi]
    xv = table[:, xi]
    bad = np.flatnonzero(xv <= 0)
    if bad.size:
        raise AdapterError(
            path, f"{xname} {xv[bad[0]]:g}: expected a positive value", lines_of[bad[0]]
        )
    x = ABSCISSAE[xname](xv)
    if x.size > 1:
        step = np.diff(x)
        sign = 1.0 if step[0] > 0 else -1.0
        k = np.flatnonzero(step * sign <= 0)
        if k.size:
            raise AdapterError(
                path,
                f"{xname} {xv[k[0] + 1]:g} repeats or breaks the order of the column: the "
                "abscissa must be strictly increasing or decreasing",
                lines_of[k[0] + 1],
            )
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
