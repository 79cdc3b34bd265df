"""Numeric blocks of text exports: vectorised parsers with line-numbered errors.

Private helpers shared by the text adapters. Two parsers, one per kind of block:

* :func:`parse_block` (Woollam, Accurion, Film Sense, SENTECH, Shimadzu UVProbe text,
  declared columns): a block of delimited numbers, rows of up to ``ncols`` fields, optional
  row tags, empty fields read as NaN, ``inf``/``nan`` spellings accepted (:data:`NUMBER`). It
  reads with :func:`pandas.read_csv` (C engine) and falls back to a strict line-by-line
  parser only when the fast path meets something it cannot read; the slow parser is the
  authority: it either returns the same table or raises :class:`AdapterError` naming the
  file, the line and what was expected. A reader therefore never returns a half-read file,
  and a good file is parsed at pandas speed. Every block it reads goes through
  :func:`labbrdf.adapters._truncation.check_last_field` (a last number cut short).
* :func:`parse_rows` (the ``.bsdf`` tables: Zemax, SPEOS, PAB Mountain): rows the reader has
  already picked out of the file, each with exactly ``ncols`` blank-separated numbers, every
  one finite ASCII decimal (no tags, no empty fields, no ``inf``/``nan``), for formats whose
  grids the header states.

A field holding one number is read by :func:`finite_number`.
"""

from __future__ import annotations

import csv
import io
import math
import os
import re
import warnings
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from ._base import DECIMAL, NONFINITE, AdapterError
from ._truncation import TAIL_ROWS, check_last_field, tail_lines, unterminated

__all__ = [
    "Block",
    "NUMBER",
    "body_bytes",
    "finite_number",
    "head_lines",
    "parse_block",
    "parse_rows",
    "split_head",
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


#: A character no row of finite ASCII decimals (blank-separated) holds.
_NOT_NUMERIC = re.compile(r"[^0-9eE+\-. \t\n]")


def finite_number(path: str | os.PathLike[str], text: str, line: int, what: str) -> float:
    """One finite ASCII decimal number (no blanks around it), else AdapterError.

    Parameters
    ----------
    path : str or path-like
        The file (for the message).
    text : str
        The field.
    line : int
        Its 1-based line.
    what : str
        What the field is (the message starts with it).
    """
    if not DECIMAL.fullmatch(text):
        raise AdapterError(path, f"{what}: expected an ASCII decimal number, found {text!r}", line)
    v = float(text)
    if not math.isfinite(v):
        raise AdapterError(path, f"{what}: {text!r} is not a finite number", line)
    return v


def parse_rows(
    path: str | os.PathLike[str], rows: list[str], lines: list[int], ncols: int
) -> NDArray[np.float64]:
    """Parse rows of exactly ``ncols`` finite numbers each, vectorised and strict.

    Unlike :func:`parse_block`, a row holds no tag and no empty field, ``inf`` and ``nan``
    are refused, and a row with fewer fields than ``ncols`` is an error (not NaN-padded).

    Parameters
    ----------
    path : str or path-like
        The file (for error messages).
    rows : list of str
        The rows' text, blank-separated numbers (the reader picked them out of the file).
    lines : list of int
        The 1-based line of each row.
    ncols : int
        Numbers per row.

    Returns
    -------
    numpy.ndarray
        ``(len(rows), ncols)`` float64.

    Raises
    ------
    AdapterError
        A character that belongs in no number, a row with another number of values, or a
        field that is not a finite number (:func:`finite_number`), naming its line.
    """
    text = "\n".join(rows)
    bad = _NOT_NUMERIC.search(text)
    if bad is not None:
        i = text.count("\n", 0, bad.start())
        raise AdapterError(
            path, f"expected numbers, found the character {bad.group()!r}", lines[i]
        )
    counts = np.fromiter((len(r.split()) for r in rows), dtype=np.int64, count=len(rows))
    wrong = np.flatnonzero(counts != ncols)
    if wrong.size:
        i = int(wrong[0])
        raise AdapterError(
            path, f"expected {ncols} values in the row, found {counts[i]}", lines[i]
        )
    toks = text.split()
    try:
        vals = np.array(toks, dtype=np.float64)
    except ValueError:
        vals = None
    if vals is None or not np.isfinite(vals).all():
        for row, ln in zip(rows, lines, strict=True):
            for t in row.split():
                finite_number(path, t, ln, "value")
        raise AdapterError(path, "unreadable numbers in the data section")  # pragma: no cover
    return vals.reshape(len(rows), ncols)
