"""The end of a text export: a last number cut short, a last row missing cells, two exports joined.

Private checks shared by the text adapters. A file cut short in the middle of its last number
(a copy or download that stopped) still parses: ``0,289`` cut to ``0,`` reads as 0.
:func:`check_last_field` compares the last field of an unterminated last line with the same
column in the rows before it and refuses or warns (see its docstring); the block parser
(``labbrdf.adapters._numblock.parse_block``) applies it to every block it reads, and
:func:`check_last_row` serves the readers that parse their rows themselves.
:func:`check_joined` refuses a file that holds two exports joined end to end.
"""

from __future__ import annotations

import itertools
import os
import re
import warnings
from collections.abc import Sequence
from dataclasses import dataclass

from ..errors import AdapterWarning
from ._base import AdapterError

__all__ = [
    "FIXED_ROWS",
    "TAIL_ROWS",
    "check_joined",
    "check_last_field",
    "check_last_row",
    "tail_lines",
    "unterminated",
    "warn",
]

_EOL = re.compile(r"\r\n|\n|\r")


def warn(path: str | os.PathLike[str], message: str, line: int | None = None) -> str:
    """Issue an :class:`AdapterWarning` naming the file and line; return its text."""
    where = f"{os.fspath(path)}" + (f", line {line}" if line is not None else "")
    text = f"{where}: {message}"
    warnings.warn(AdapterWarning(text), stacklevel=3)
    return text


#: Rows before the last one that give a column its precision (the most recent ones).
TAIL_ROWS = 200
#: Rows that must agree on a column's decimals (or exponent digits) for a shorter last
#: value to be refused rather than warned about: fewer could agree by chance.
FIXED_ROWS = 5

_SHAPE = re.compile(
    r"[+-]?(?P<int>[0-9]*)(?P<mark>[.,]?)(?P<frac>[0-9]*)(?:(?P<e>[eE])[+-]?(?P<exp>[0-9]*))?"
)


@dataclass(frozen=True)
class _Shape:
    """How a number is written: decimals, exponent digits, significant digits."""

    decimals: int
    exponent: int | None
    digits: int
    dangling: bool


def _shape(field: str) -> _Shape | None:
    """The shape of a numeric field (None for text, ``nan``, ``inf`` or an empty field)."""
    m = _SHAPE.fullmatch(field)
    if m is None or not (m["int"] or m["frac"] or m["mark"]):
        return None
    digits = len((m["int"] + m["frac"]).lstrip("0"))
    dangling = (
        (m["mark"] != "" and m["frac"] == "" and m["e"] is None)  # "0," or "300."
        or (m["e"] is not None and m["exp"] == "")  # "4.5E-" or "4.5e"
        or not (m["int"] or m["frac"])  # "," alone
    )
    exp = len(m["exp"]) if m["e"] is not None else None
    return _Shape(len(m["frac"]), exp, digits, dangling)


def _fields(line: str, sep: str | None, tagged: bool) -> list[str]:
    fields = [f.strip() for f in (line.split(sep) if sep is not None else line.split())]
    while fields and not fields[-1]:
        fields.pop()
    if tagged and fields and fields[0][:1].isalpha():
        fields = fields[1:]
    return fields


def _decimals(n: int) -> str:
    return f"{n} decimal" + ("" if n == 1 else "s")


def unterminated(text: str | bytes) -> bool:
    """Whether the last line of ``text`` holds something and has no line end."""
    if not text:
        return False
    tail = text[-1:]
    if tail in ("\n", "\r", b"\n", b"\r"):
        return False
    return not text[-1:].isspace()


def _check_missing_cells(
    path: str | os.PathLike[str],
    last: str,
    previous: list[str],
    line: int,
    sep: str | None,
    tagged: bool,
) -> str | None:
    """Refuse (or warn about) a last line that ends in a separator before cells every
    earlier row fills: ``550,30,31.8,180,0.0694797,`` where each row has its sigma."""
    have = len(_fields(last, sep, tagged))
    ref = [len(_fields(p, sep, tagged)) for p in previous[-TAIL_ROWS:] if p.strip()]
    if not have or not ref or min(ref) <= have:
        return None
    what = (
        f"the last line, which has no line end, stops after {have} field(s) where every "
        f"other row has at least {min(ref)}"
    )
    fix = "if the row is complete, end the line with a line break"
    if len(ref) >= FIXED_ROWS:
        raise AdapterError(path, f"{what}: the file looks truncated ({fix})", line)
    return warn(path, f"{what}: the file may be truncated ({fix})", line)


def check_last_field(
    path: str | os.PathLike[str],
    last: str,
    previous: list[str],
    line: int,
    sep: str | None,
    *,
    tagged: bool = False,
) -> str | None:
    """Refuse or warn when the unterminated last line of a file looks cut mid-number.

    Only the last field of such a line can be cut (every other field is followed by a
    separator); it is compared with the same column in ``previous``, the rows before it
    (the most recent :data:`TAIL_ROWS` are enough). A line that ends in a separator may
    have lost the fields after it: it is refused where at least :data:`FIXED_ROWS` earlier
    rows all have more fields (``...,0.0694797,`` where every row has a sigma after the
    value), warned about where fewer do.

    Refused (the file looks truncated): the field ends in a decimal separator or in an
    exponent without digits (``0,``, ``300.``, ``4.5E-``); or the column has a precision of
    its own, every one of at least :data:`FIXED_ROWS` rows written with the same number of
    decimals (or of exponent digits), and the field has fewer (``0,4`` where the column is
    written ``0,322``; ``4.522`` or ``4.522E-0`` where it is written ``4.522E-02``).
    Warned (the column's own writing varies, so a shorter value may be a real one, e.g.
    ``0.13`` beside ``0.1308`` from a writer that drops trailing zeros): the field has fewer
    significant digits than some other row (a cut always removes significant digits), or
    no exponent where other rows have one; or no other row has the column to compare with.
    Fewer decimals alone is no sign of a cut where the decimals vary: a writer of
    significant digits writes ``0.278168`` beside ``0.0775003``.

    Parameters
    ----------
    path : str or path-like
        The file (for the message).
    last : str
        The last line, without line end (the caller checked it has none: :func:`unterminated`).
    previous : list of str
        The data rows before it, oldest first.
    line : int
        1-based number of the last line.
    sep : str or None
        Field separator; None for runs of blanks.
    tagged : bool
        Whether a row may start with an alphabetic tag (not a column).

    Returns
    -------
    str or None
        The warning issued (an :class:`AdapterWarning`), or None when the field is complete.

    Raises
    ------
    AdapterError
        The field is certainly cut short; the message names the line.
    """
    if last[-1:].isspace() or (sep is not None and last.endswith(sep)):
        # the last field is followed by a separator: complete, but the cells after it may
        # be missing
        return _check_missing_cells(path, last, previous, line, sep, tagged)
    fields = _fields(last, sep, tagged)
    if not fields:
        return None
    j, text = len(fields) - 1, fields[-1]
    f = _shape(text)
    if f is None:
        return None  # not a number: the reader's own parser refuses or keeps it
    cut = f"field {j + 1} {text!r} on the last line, which has no line end,"
    fix = "if the value is complete, end the line with a line break"
    if f.dangling:
        raise AdapterError(
            path, f"{cut} ends without its digits: the file looks truncated ({fix})", line
        )
    ref = [s for p in previous[-TAIL_ROWS:] if len(fs := _fields(p, sep, tagged)) > j
           for s in [_shape(fs[j])] if s is not None]  # fmt: skip
    if not ref:  # nothing to compare with: say so rather than vouch for the value
        return warn(
            path,
            f"{cut} has no other row of its column to compare with: the file may be "
            f"truncated ({fix})",
            line,
        )
    decimals = [r.decimals for r in ref]
    exps = [r.exponent for r in ref if r.exponent is not None]
    fixed = len(ref) >= FIXED_ROWS and min(decimals) == max(decimals)
    if fixed and f.decimals < min(decimals):
        raise AdapterError(
            path,
            f"{cut} has {_decimals(f.decimals)} where every other row of the column has "
            f"at least {_decimals(min(decimals))}: the file looks truncated ({fix})",
            line,
        )
    fixed_exp = len(ref) >= FIXED_ROWS and len(exps) == len(ref) and min(exps) == max(exps)
    if fixed_exp and (f.exponent is None or f.exponent < min(exps)):
        raise AdapterError(
            path,
            f"{cut} lacks the {min(exps)}-digit exponent every other row of the column has: "
            f"the file looks truncated ({fix})",
            line,
        )
    # where the decimals vary, the writer keeps significant digits (%g: 0.0775003 beside
    # 0.278168) or drops trailing zeros (0.13 beside 0.1308): a cut value has fewer
    # significant digits than the most any row has, while a complete one may well have
    # fewer decimals than another row (0.278168 is not short beside 0.0775003)
    short = (
        (f.exponent is None and exps)
        or (f.exponent is not None and exps and f.exponent < min(exps))
        or f.digits < max(r.digits for r in ref)
    )
    if not short:
        return None
    return warn(
        path,
        f"{cut} is written shorter than other values of its column (up to "
        f"{_decimals(max(decimals))}, {max(r.digits for r in ref)} significant digits): "
        f"the file may be truncated ({fix})",
        line,
    )


def check_last_row(
    path: str | os.PathLike[str],
    text: str | bytes,
    lines: list[str],
    rows: Sequence[int],
    sep: str | None,
    *,
    tagged: bool = False,
) -> str | None:
    """:func:`check_last_field` for a reader that parses its rows itself.

    Does nothing unless the file's last line has no line end and is the last data row.

    Parameters
    ----------
    path : str or path-like
        The file (for the message).
    text : str or bytes
        The whole file (only its last characters are looked at).
    lines : list of str
        Its lines, split at CR, LF or CRLF (:func:`labbrdf.adapters._base.split_lines`).
    rows : sequence of int
        1-based line numbers of the data rows, in file order.
    sep : str or None
        Field separator; None for runs of blanks.
    tagged : bool
        Whether a row may start with an alphabetic tag.

    Returns
    -------
    str or None
        The warning issued, if any.

    Raises
    ------
    AdapterError
        The last number (or the cells after the last separator) was certainly cut short.
    """
    if not rows or rows[-1] != len(lines) or not unterminated(text):
        return None
    previous = [lines[k - 1] for k in rows[-TAIL_ROWS - 1 : -1]]
    return check_last_field(path, lines[-1].strip(), previous, rows[-1], sep, tagged=tagged)


def check_joined(path: str | os.PathLike[str], lines: list[str]) -> None:
    """Refuse a single-export file whose first line comes again: two exports joined.

    The first non-blank line of an export (its magic, title or column line) is written
    once; ``cat a.txt a.txt > b.txt`` repeats it where the second export starts, and the
    reader would otherwise read the second copy as more data, a footer or a confusing
    error further on.

    Parameters
    ----------
    path : str or path-like
        The file (for the message).
    lines : list of str
        Its lines (:func:`labbrdf.adapters._base.split_lines`).

    Raises
    ------
    AdapterError
        Naming the line where the second export starts.
    """
    heads = list(itertools.islice((i for i, ln in enumerate(lines) if ln.strip()), 2))
    if not heads:
        return
    first = heads[0]
    head = lines[first]
    at = _index(lines, head, first + 1)
    if at < 0 and len(heads) == 2:  # "a" without a final line end: its last line and the
        # copy's first line are one line, found by the copy's second line after it
        j = _index(lines, lines[heads[1]], heads[1] + 1)
        if j > 0 and head.strip() and lines[j - 1].rstrip().endswith(head.strip()):
            at = j - 1
    if at >= 0:
        raise AdapterError(
            path,
            f"the first line of the export ({head.strip()[:40]!r}, line {first + 1}) comes "
            "again here: the file holds two exports joined (a copy starts at this line); "
            "split it into one file per export",
            at + 1,
        )


def _index(lines: list[str], line: str, start: int) -> int:
    """``lines.index(line, start)`` (C speed), or -1."""
    try:
        return lines.index(line, start)
    except ValueError:
        return -1


def tail_lines(data: bytes, start: int, n: int) -> list[str]:
    """The last ``n`` lines of ``data[start:]`` (any line end), decoded as Latin-1."""
    pos, count = len(data), 0
    while count < n:
        k = max(data.rfind(b"\n", start, pos), data.rfind(b"\r", start, pos))
        if k < start:
            pos = start
            break
        pos, count = k, count + 1
        if k > start and data[k - 1 : k + 1] == b"\r\n":
            pos = k - 1
    chunk = data[pos:].decode("latin-1")
    return [ln for ln in _EOL.split(chunk) if ln.strip()][-n:]
