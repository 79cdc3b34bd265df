"""Numeric blocks of text exports: a vectorised parser with line-numbered errors.

Private helpers shared by the text adapters (Woollam, Accurion, Film Sense, SENTECH,
Shimadzu UVProbe text, declared columns). The block parser reads a block of delimited numbers with
:func:`pandas.read_csv` (C engine) and falls back to a strict line-by-line parser only when
the fast path meets something it cannot read; the slow parser is the authority: it either
returns the same table or raises :class:`AdapterError` naming the file, the line and what
was expected. A reader therefore never returns a half-read file, and a good file is parsed
at pandas speed.

A file cut short in the middle of its last number (a copy or download that stopped) still
parses: ``0,289`` cut to ``0,`` reads as 0. :func:`check_last_field` compares the last
field of an unterminated last line with the same column in the rows before it and refuses
or warns (see its docstring); :func:`parse_block` applies it to every block it reads.
"""

from __future__ import annotations

import csv
import io
import itertools
import os
import re
import warnings
from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
import pandas as pd

from ..dataset import DatasetError, Measurement
from ..errors import AdapterWarning
from ._base import DECIMAL, NONFINITE, AdapterError

__all__ = [
    "AdapterWarning",
    "Block",
    "NUMBER",
    "build_frame",
    "check_last_field",
    "check_last_row",
    "check_joined",
    "unterminated",
    "labels",
    "body_bytes",
    "group_angles",
    "head_lines",
    "measurement",
    "parse_block",
    "split_head",
    "within",
]

#: What a number may look like in an export: ASCII digits (:data:`._base.DECIMAL`), or
#: ``inf``/``Infinity``/``nan`` in any case (CompleteEASE writes ``inf``, Accurion ``NaN``).
NUMBER = re.compile(f"(?:{DECIMAL.pattern})|(?:{NONFINITE.pattern})", re.IGNORECASE)
_TAG = re.compile(r"[A-Za-z][A-Za-z0-9_]*")


@dataclass(frozen=True)
class Block:
    """A parsed numeric block.

    Attributes
    ----------
    values : numpy.ndarray
        ``(n, ncols)`` float64; empty or missing trailing fields are NaN.
    lines : numpy.ndarray
        ``(n,)`` 1-based line number of each row in the file.
    tags : numpy.ndarray or None
        ``(n,)`` object array with the alphabetic tag of each row (``""`` for an untagged
        row), or None when the block was parsed without tags.
    blank_lines : int
        Number of empty (or whitespace-only) lines skipped.
    nfields : numpy.ndarray or None
        ``(n,)`` number of fields as written (separator count + 1, tag included), for
        TAB-separated blocks; None for whitespace-separated ones.
    tag_codes : tuple or None
        ``(codes, names)`` with ``tags == names[codes]`` when the parser knows them without
        hashing every tag (an untagged block: all codes 0, names ``[""]``); else None.
    warnings : tuple of str
        Doubts about the block (a last number that may be cut short), also issued as
        :class:`AdapterWarning`.
    """

    values: np.ndarray
    lines: np.ndarray
    tags: np.ndarray | None
    blank_lines: int
    nfields: np.ndarray | None = None
    tag_codes: tuple[np.ndarray, list[str]] | None = None
    warnings: tuple[str, ...] = ()


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


def head_lines(text: str, n: int) -> tuple[list[str], int]:
    """The first ``n`` lines of ``text`` (CRLF, LF or CR ends) and the offset after them."""
    head: list[str] = []
    pos = 0
    while len(head) < n and pos < len(text):
        m = _EOL.search(text, pos)
        if m is None:
            head.append(text[pos:])
            return head, len(text)
        head.append(text[pos : m.start()])
        pos = m.end()
    return head, pos


def split_head(text: str, n: int) -> tuple[list[str], str]:
    """Split off the first ``n`` lines of ``text``; return them and the rest (the body).

    Line ends may be CRLF, LF or CR; a missing final newline is fine.
    """
    head, pos = head_lines(text, n)
    return head, text[pos:]


def body_bytes(raw: bytes, text: str, offset: int, encoding: str) -> bytes:
    """The bytes of ``text[offset:]`` cut from ``raw`` (``text`` decoded from ``raw``)."""
    bom = 3 if raw.startswith(b"\xef\xbb\xbf") else 0
    return raw[bom + len(text[:offset].encode(encoding)) :]


def _slow(
    path: str | os.PathLike[str],
    body: str,
    first_line: int,
    ncols: int,
    sep: str | None,
    tagged: bool,
) -> Block:
    """Strict line-by-line parser; the authority on what a valid block is."""
    lines = body.splitlines()
    vals = np.full((len(lines), ncols), np.nan)
    tags = np.full(len(lines), "", dtype=object)
    keep = np.ones(len(lines), dtype=bool)
    nfields = np.zeros(len(lines), dtype=np.int64)
    for i, line in enumerate(lines):
        lineno = first_line + i
        fields = line.split(sep) if sep is not None else line.split()
        nfields[i] = len(fields)
        while fields and not fields[-1].strip():
            fields.pop()
        if not fields:
            keep[i] = False
            continue
        if tagged:
            first = fields[0].strip()
            if first[:1].isalpha():
                if not _TAG.fullmatch(first):
                    raise AdapterError(path, f"bad row tag {first!r}", lineno)
                tags[i] = first
                fields = fields[1:]
        if len(fields) > ncols:
            raise AdapterError(
                path, f"expected at most {ncols} numeric fields, found {len(fields)}", lineno
            )
        for j, f in enumerate(fields):
            f = f.strip()
            if not f:
                continue
            if not NUMBER.fullmatch(f):
                shown = f if len(f) <= 40 else f[:37] + "..."
                raise AdapterError(
                    path,
                    f"field {j + 1 + (tags[i] != '')}: expected a number, found {shown!r}",
                    lineno,
                )
            vals[i, j] = float(f)
    linenos = first_line + np.flatnonzero(keep)
    return Block(
        vals[keep],
        linenos,
        tags[keep] if tagged else None,
        int((~keep).sum()),
        nfields[keep] if sep is not None else None,
    )


_READ_KW: dict[str, Any] = {
    "header": None,
    "index_col": False,
    "keep_default_na": False,
    "na_values": ["", "NaN", "nan"],
    "skip_blank_lines": False,
    "quoting": csv.QUOTE_NONE,
    "engine": "c",
}


def _line_starts(arr: np.ndarray) -> np.ndarray:
    starts = np.concatenate(([0], np.flatnonzero(arr == 10) + 1))
    return starts[starts < arr.size]


def _line_starts_alpha(arr: np.ndarray, starts: np.ndarray) -> bool:
    if arr.size == 0:
        return False
    c = arr[starts] | 0x20
    return bool(((c >= ord("a")) & (c <= ord("z"))).any())


def _fields_per_line(arr: np.ndarray, starts: np.ndarray, sep: str) -> np.ndarray:
    """Separator count + 1 for every line (vectorised)."""
    seps = np.flatnonzero(arr == ord(sep))
    ends = np.concatenate((starts[1:], [arr.size]))
    return np.searchsorted(seps, ends) - np.searchsorted(seps, starts) + 1


def _fast(
    body: str | None,
    data: bytes,
    first_line: int,
    ncols: int,
    sep: str | None,
    tagged: bool,
    count_fields: bool,
    start: int = 0,
) -> Block | None:
    """pandas C-engine parse of ``data[start:]``; None when anything looks off.

    The caller then goes slow. Lone CR line ends, form feeds and the like make pandas and
    the line count disagree; the row-count cross-check below sends such blocks to the slow
    parser. A tagged block is first read as numbers only (the common untagged file): a
    line that starts with a letter either fails that parse or gives a non-finite first
    field (``inf``, ``nan``), and only then are the line starts inspected for tags.
    """
    if _NONSPACE.search(data, start) is None:
        return Block(np.empty((0, ncols)), np.empty(0, dtype=np.int64), None, 0)
    starts: np.ndarray | None = None

    def line_starts() -> np.ndarray:
        nonlocal starts
        if starts is None:
            starts = _line_starts(np.frombuffer(data, dtype=np.uint8, offset=start))
        return starts

    def has_tags() -> bool:
        return tagged and _line_starts_alpha(
            np.frombuffer(data, dtype=np.uint8, offset=start), line_starts()
        )

    # read only as many columns as the first line has (fewer empty columns to fill); a
    # longer line further on makes pandas fail, and the block is read again at full width
    width = _first_line_fields(data, start, sep, ncols)
    df = None
    if sep is not None and not _first_line_has_empty_field(data, start, sep):
        # no missing-value detection: faster; any empty or NaN field makes it fail
        df = _read_csv(data, start, width, sep, False, na_filter=False)
    # a failed numbers-only parse may be due to tags: then go straight to the tagged parse
    with_tags = df is None and has_tags()
    if not with_tags:
        if df is None:
            df = _read_csv(data, start, width, sep, False)
        if df is None and width < ncols:
            df = _read_csv(data, start, ncols, sep, False)
        if df is not None and tagged and not np.isfinite(df[0].to_numpy(np.float64)).all():
            with_tags = has_tags()  # "inf"/"nan" in the first field: a tag, or a number?
    if with_tags:
        df = _read_csv(data, start, ncols, sep, True)
    if df is None:
        return None
    if with_tags:
        col0 = df[0].to_numpy(dtype=object)
        rest = df.iloc[:, 1:].to_numpy(dtype=np.float64)
        s0 = pd.Series(col0, dtype=object)
        present = s0.notna().to_numpy()
        is_tag = present & s0.str.match(r"[A-Za-z]", na=False).to_numpy(dtype=bool)
        if is_tag.any() and not s0[is_tag].str.fullmatch(_TAG.pattern).all():
            return None
        num0 = pd.to_numeric(s0.where(~is_tag), errors="coerce").to_numpy(dtype=np.float64)
        bad0 = present & ~is_tag & np.isnan(num0)
        if bad0.any():  # could be a literal NaN or garbage: let the slow path decide
            return None
        vals = np.where(is_tag[:, None], rest, np.column_stack([num0, rest[:, :-1]]))
        over = ~is_tag & ~np.isnan(rest[:, -1])
        if over.any():
            return None
        tags = np.where(is_tag, col0, "").astype(object)
    else:
        vals = _columns(df, ncols)
        tags = None
    n = len(vals)
    # pandas skips a whitespace-separated block's leading-space lines differently; cross-check
    # the number of rows against the number of lines so that line numbers stay exact.
    if sep is None:
        nlines = len(_body(body, data, start).splitlines())
    else:  # = line_starts().size: lines end with LF, a last line may lack it
        nlines = _count_lf(data, start) + (not data.endswith(b"\n", start))
    if n != nlines:
        return None
    # a blank line is NaN in every field, so in the first one: test that column first
    blank = np.isnan(vals[:, 0]) if n else np.zeros(0, dtype=bool)
    if blank.any():
        blank &= np.isnan(vals).all(axis=1)
        if tags is not None:
            blank &= tags == ""
    nfields = None
    if count_fields and sep is not None:
        nfields = _fields_per_line(np.frombuffer(data, np.uint8, offset=start), line_starts(), sep)
    if not blank.any():  # the usual case: no copies
        return Block(vals, first_line + np.arange(n), tags, 0, nfields)
    keep = ~blank
    linenos = first_line + np.flatnonzero(keep)
    return Block(
        vals[keep],
        linenos,
        None if tags is None else tags[keep],
        int(blank.sum()),
        None if nfields is None else nfields[keep],
    )


_NONSPACE = re.compile(rb"\S")


def _first_line(data: bytes, start: int) -> bytes:
    """The first line of ``data[start:]``, without its line end."""
    end = data.find(b"\n", start)
    return (data[start:] if end < 0 else data[start:end]).rstrip(b"\r")


def _first_line_fields(data: bytes, start: int, sep: str | None, ncols: int) -> int:
    """Fields on the first line of ``data[start:]`` (``sep``-separated), within [1, ncols]."""
    if sep is None:
        return ncols
    return max(1, min(ncols, _first_line(data, start).count(sep.encode()) + 1))


def _first_line_has_empty_field(data: bytes, start: int, sep: str) -> bool:
    """Whether the first line has an empty field (then missing values are to be expected)."""
    line, s = _first_line(data, start), sep.encode()
    return not line.strip() or s + s in line or line.startswith(s) or line.endswith(s)


def _columns(df: pd.DataFrame, ncols: int) -> np.ndarray:
    """The float columns of ``df`` as an ``(n, ncols)`` array, NaN beyond ``df``'s columns.

    Column-major (each column one contiguous copy, no interleaving): rows are read as
    ``values[i]`` and columns as ``values[:, j]`` alike.
    """
    out = np.empty((ncols, len(df)))
    for j in range(df.shape[1]):
        out[j] = df.iloc[:, j].to_numpy(dtype=np.float64)
    out[df.shape[1] :] = np.nan
    return out.T


def _count_lf(data: bytes, start: int, chunk: int = 1 << 20) -> int:
    """Number of LF bytes in ``data[start:]``; numpy on cache-sized chunks (4x bytes.count)."""
    arr = np.frombuffer(data, dtype=np.uint8, offset=start)
    return sum(int(np.count_nonzero(arr[i : i + chunk] == 10)) for i in range(0, arr.size, chunk))


def _body(body: str | None, data: bytes, start: int) -> str:
    """The block as text: ``body`` when given, else ``data[start:]`` (ASCII) decoded."""
    return body if body is not None else data[start:].decode("ascii")


def _read_csv(
    data: bytes,
    start: int,
    ncols: int,
    sep: str | None,
    with_tags: bool,
    *,
    na_filter: bool = True,
) -> pd.DataFrame | None:
    """``pandas.read_csv`` of ``data[start:]`` without copying it; None on any complaint.

    With ``na_filter=False`` pandas skips its missing-value detection (about 15 % faster);
    an empty field or a ``NaN`` then fails the float conversion, so the result, when there
    is one, is the same as with detection.
    """
    width = ncols + 1 if with_tags else ncols
    kw = dict(_READ_KW)
    if not na_filter:
        kw["na_filter"] = False
    kw["sep"] = sep if sep is not None else r"\s+"
    if with_tags:
        kw["dtype"] = {0: object, **{k: np.float64 for k in range(1, width)}}
        # a first field "nan" is a tag to the strict parser: keep it as text
        kw["na_values"] = {0: [""], **{k: _READ_KW["na_values"] for k in range(1, width)}}
    else:
        kw["dtype"] = np.float64
    buf = io.BytesIO(data)  # shares the bytes object's buffer
    buf.seek(start)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            return pd.read_csv(buf, names=list(range(width)), **kw)
    except (ValueError, TypeError, pd.errors.ParserError, pd.errors.ParserWarning):
        return None


def parse_block(
    path: str | os.PathLike[str],
    body: str | None,
    first_line: int,
    ncols: int,
    *,
    sep: str | None = "\t",
    tagged: bool = False,
    count_fields: bool = False,
    data: bytes | None = None,
    data_start: int = 0,
) -> Block:
    """Parse a block of delimited numbers.

    Parameters
    ----------
    path : str or path-like
        The file (for error messages).
    body : str or None
        The block's text, starting at a line start. None when ``data`` is given and is
        pure ASCII: the text is then decoded from it only if needed (slow path).
    first_line : int
        1-based line number of the block's first line in the file.
    ncols : int
        Maximum number of numeric fields per row (after the tag, if any); shorter rows are
        padded with NaN, trailing empty fields (trailing TABs or spaces) are ignored.
    sep : str or None
        Field separator; None splits on runs of whitespace.
    tagged : bool
        Whether a row may start with an alphabetic tag (Woollam ``pR``, ``dpolE``, ...).
    count_fields : bool
        Fill :attr:`Block.nfields` (TAB-separated blocks only).
    data : bytes, optional
        The block encoded in an ASCII-compatible encoding, from ``data_start`` on, when the
        caller has it (saves re-encoding and copying a large block).
    data_start : int
        Offset of the block in ``data`` [bytes].

    Returns
    -------
    Block
        Values, line numbers and tags; blank lines are skipped and counted.

    Raises
    ------
    AdapterError
        A row with too many fields or a field that is not a number, naming its line; a
        last line without line end whose last number is cut short (:func:`check_last_field`).
    """
    if data is None:
        if body is None:
            raise TypeError("parse_block needs body or data")
        data = body.encode("utf-8")
        data_start = 0
    block = _fast(body, data, first_line, ncols, sep, tagged, count_fields, data_start)
    if block is None:
        block = _slow(path, _body(body, data, data_start), first_line, ncols, sep, tagged)
    if tagged and block.tags is None:
        n = len(block.lines)
        tags = np.broadcast_to(np.array([""], dtype=object), (n,))  # read-only, no memory
        block = Block(
            block.values,
            block.lines,
            tags,
            block.blank_lines,
            block.nfields,
            (np.zeros(n, dtype=np.intp), [""]),
        )
    if len(block.lines) and len(data) > data_start and unterminated(data):
        tail = tail_lines(data, data_start, TAIL_ROWS + 1)
        note = check_last_field(
            path, tail[-1], tail[:-1], int(block.lines[-1]), sep, tagged=tagged
        )
        if note is not None:
            block = replace(block, warnings=(note,))
    return block


def group_angles(angles: Any, tol: float = 0.05) -> list[dict[str, float | int]]:
    """Group nearly equal angles for a summary (goniometer readings such as 64.999634).

    Parameters
    ----------
    angles : array_like
        Angles [deg]; NaN ignored.
    tol : float
        Largest gap inside one group [deg].

    Returns
    -------
    list of dict
        One ``{"nominal", "min", "max", "rows"}`` per group, ascending; ``nominal`` is the
        group mean rounded to 3 decimals. The data themselves are never rounded.
    """
    a = np.asarray(angles, dtype=float).ravel()
    a = np.sort(a[np.isfinite(a)])
    if a.size == 0:
        return []
    cuts = np.flatnonzero(np.diff(a) > tol) + 1
    out = []
    for g in np.split(a, cuts):
        out.append(
            {
                "nominal": round(float(g.mean()), 3),
                "min": float(g[0]),
                "max": float(g[-1]),
                "rows": int(g.size),
            }
        )
    return out


def build_frame(
    *,
    sample: str,
    instrument: str,
    source: str,
    quantity: Any,
    value: Any,
    unit: Any,
    wavelength_nm: Any,
    sigma: Any = np.nan,
    theta_i_deg: Any = np.nan,
    theta_r_deg: Any = np.nan,
    phi_r_deg: Any = np.nan,
    **optional: Any,
) -> pd.DataFrame:
    """Build a schema table from arrays and scalars without per-row Python work.

    Like :func:`labbrdf.dataset.make_frame`, but string columns are built as categoricals
    (a constant string, an object array, or a :class:`pandas.Categorical` made with
    :func:`labels`), which keeps files of millions of rows fast; :func:`measurement`
    validates the result (and :func:`labbrdf.dataset.validate` turns them into plain
    strings).
    """
    value = np.asarray(value, dtype=float).ravel()
    n = value.size

    def num(v: Any) -> np.ndarray:
        if np.ndim(v) == 0:
            return np.full(n, v, dtype=float)
        arr = np.asarray(v, dtype=float).ravel()
        if arr.size != n:  # pragma: no cover - programming error
            raise ValueError(f"column has {arr.size} values, expected {n}")
        return arr

    def text(v: Any) -> pd.Categorical:
        if isinstance(v, str):
            return pd.Categorical.from_codes(np.zeros(n, dtype=np.int8), categories=[v])
        if isinstance(v, pd.Categorical):
            out = v
        else:
            out = pd.Categorical(np.asarray(v, dtype=object).ravel())
        if len(out) != n:  # pragma: no cover - programming error
            raise ValueError(f"column has {len(out)} values, expected {n}")
        return out

    cols: dict[str, Any] = {
        "sample": text(sample),
        "instrument": text(instrument),
        "source": text(source),
        "quantity": text(quantity),
        "value": value,
        "sigma": num(sigma),
        "unit": text(unit),
        "wavelength_nm": num(wavelength_nm),
        "theta_i_deg": num(theta_i_deg),
        "theta_r_deg": num(theta_r_deg),
        "phi_r_deg": num(phi_r_deg),
    }
    for k, v in optional.items():
        cols[k] = text(v) if k == "channel" else num(v)
    return pd.DataFrame(cols, copy=False)


#: Mueller elements whose sign differs between the vendors' convention (Woollam, SENTECH:
#: ``M12 = M21 = -cos 2psi`` for an isotropic sample, i.e. ``S1 = Ip - Is``) and
#: :mod:`labbrdf.optics` (``S1 = Is - Ip``, ``M12 = M21 = +cos 2psi``, ``M33 = sin 2psi cos
#: Delta``, ``M34 = sin 2psi sin Delta``): ``M_optics = D M_vendor D`` with ``D = diag(1, -1,
#: 1, 1)`` flips every element with exactly one index 2.
MUELLER_S1_FLIP = frozenset(
    {"mueller_12", "mueller_21", "mueller_23", "mueller_24", "mueller_32", "mueller_42"}
)


def mueller_convention(vendor: str) -> dict[str, str]:
    """The ``meta["mueller_convention"]`` record of a reader that converted Mueller data."""
    return {
        "vendor": f"{vendor}: S1 = Ip - Is, M12 = M21 = -cos 2psi for an isotropic sample",
        "converted": "labbrdf.optics: S1 = Is - Ip, M12 = M21 = +cos 2psi, M33 = sin 2psi "
        "cos Delta, M34 = sin 2psi sin Delta; M = D M_vendor D, D = diag(1, -1, 1, 1) "
        "(M12, M21, M23, M24, M32, M42 change sign)",
    }


def labels(names: list[str], counts: list[int] | np.ndarray) -> pd.Categorical:
    """``names[k]`` repeated ``counts[k]`` times, as a categorical (no per-row strings)."""
    uniq = list(dict.fromkeys(names))
    codes = np.array([uniq.index(x) for x in names], dtype=np.int16)
    return pd.Categorical.from_codes(np.repeat(codes, counts), categories=uniq)


def measurement(
    path: str | os.PathLike[str], frame: pd.DataFrame, meta: dict[str, Any]
) -> Measurement:
    """Validate into a :class:`Measurement`; a schema problem becomes an :class:`AdapterError`."""
    if len(frame) == 0:
        raise AdapterError(path, "no data rows found")
    try:
        return Measurement(frame, meta)
    except DatasetError as exc:
        raise AdapterError(path, f"data do not fit the labbrdf schema: {exc}") from None


def first_bad(mask: np.ndarray) -> int | None:
    """Index of the first True in ``mask`` or None."""
    idx = np.flatnonzero(mask)
    return int(idx[0]) if idx.size else None


def check_rows(path: str | os.PathLike[str], block: Block, mask: np.ndarray, message: str) -> None:
    """Raise ``AdapterError(path, message, line)`` for the first row where ``mask`` is True."""
    i = first_bad(mask)
    if i is not None:
        raise AdapterError(path, message, int(block.lines[i]))


def delta_range(delta: np.ndarray) -> list[float] | None:
    """[min, max] of the Delta values as written in the file (JSON-safe), None if empty."""
    d = np.asarray(delta, dtype=float)
    if within(d):
        return [float(d.min()), float(d.max())]
    d = d[np.isfinite(d)]
    if d.size == 0:
        return None
    return [float(d.min()), float(d.max())]


def within(
    a: np.ndarray, lo: float = -np.inf, hi: float = np.inf, *, hi_open: bool = False
) -> bool:
    """True when every value of ``a`` is finite and within [lo, hi] ([lo, hi) with ``hi_open``).

    Two reductions (NaN propagates into min and max) instead of several full-length masks:
    the fast path of a range check; when it says no, the caller builds the exact row mask
    to name the first offending line. True for an empty array.
    """
    if a.size == 0:
        return True
    mn, mx = float(np.min(a)), float(np.max(a))
    if not (np.isfinite(mn) and np.isfinite(mx)):
        return False
    return mn >= lo and (mx < hi if hi_open else mx <= hi)
