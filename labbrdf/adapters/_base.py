"""Shared pieces of the instrument adapters: the error type, the format record, text decoding.

Adapters import only :mod:`labbrdf.dataset` and this module.
"""

from __future__ import annotations

import math
import os
import re
import stat
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..dataset import Measurement
from ..errors import LabbrdfError

__all__ = [
    "DECIMAL",
    "MAX_POINTS",
    "NONFINITE",
    "AdapterError",
    "Example",
    "Format",
    "check_count",
    "check_regular_file",
    "decode",
    "parse_number",
    "read_bytes",
    "split_lines",
]

#: A decimal number as instrument files write it: ASCII digits only, optional sign, decimal
#: point and exponent. Python's ``float`` also accepts full-width and other Unicode digits
#: (``'１２'``), underscores (``'1_000'``) and ``inf``/``nan`` spellings; instrument files are
#: ASCII, so every text reader checks a field against this before converting it.
DECIMAL = re.compile(r"[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")
#: The non-finite spellings accepted where a format has them (CompleteEASE ``inf``,
#: Accurion ``NaN``).
NONFINITE = re.compile(r"[+-]?(?:inf(?:inity)?|nan)", re.IGNORECASE)

#: Largest number of points (per spectrum, or in total for a multi-spectrum binary file) a
#: declared count may announce. UV-Vis-NIR spectra have at most a few 10^4 points; the cap
#: keeps a corrupt or crafted count from allocating gigabytes before any other check.
MAX_POINTS = 2_000_000


class AdapterError(LabbrdfError, ValueError):
    """A file cannot be read as the format asked for.

    The message always names the file, and the line (1-based) where that makes sense,
    and says what was expected.

    Parameters
    ----------
    path : str or path-like
        The file.
    message : str
        What was found and what was expected.
    line : int, optional
        1-based line number (or byte offset for binary formats, with ``unit="byte"``).
    """

    def __init__(
        self,
        path: str | os.PathLike[str],
        message: str,
        line: int | None = None,
        *,
        unit: str = "line",
    ) -> None:
        self.path = str(path)
        self.line = line
        self.reason = message
        self.unit = unit
        where = f"{self.path}, {unit} {line}" if line is not None else self.path
        super().__init__(f"{where}: {message}")

    def __reduce__(self) -> tuple[Any, tuple[Any, ...]]:
        """Pickle by the constructor's arguments (an error raised on a dask worker)."""
        return (_rebuild_adapter_error, (type(self), self.path, self.reason, self.line, self.unit))


def _rebuild_adapter_error(
    cls: type[AdapterError], path: str, reason: str, line: int | None, unit: str
) -> AdapterError:
    return cls(path, reason, line, unit=unit)


@dataclass(frozen=True)
class Example:
    """A real export of a format: the file a format's generic tests read and damage.

    The files are not part of the package: the test suite finds them in its collection of
    real exports, one folder per format, and skips where the collection is absent.

    Attributes
    ----------
    path : str
        ``"<folder>/<file name>"`` in the collection of real exports.
    number : tuple of (str, int), optional
        A numeric field exactly as written on a data line of the file, and that line
        (1-based): the field the ASCII-digits test rewrites (full-width digits, ``1_000``,
        a non-finite spelling) to check the reader refuses it at that line.
    rows_per_line : int, optional
        The most dataset rows one text line of the file gives (psi and Delta: 2; a line of
        three angles: 6; a Mueller matrix: 16). A damaged line may cost at most this many
        rows, which bounds what the mutation tests of line-oriented formats accept; they
        damage the examples that state it.
    """

    path: str
    number: tuple[str, int] | None = None
    rows_per_line: int | None = None


@dataclass(frozen=True)
class Format:
    """One supported export format.

    Attributes
    ----------
    name : str
        Registry key, e.g. ``"woollam-wvase"``.
    description : str
        One line for ``labbrdf.adapters.formats()``.
    extensions : tuple of str
        Lower-case file extensions with the dot (``".dat"``); ``".probe.raw.asc"`` style
        multi-part endings are matched against the end of the name.
    sniff : callable
        ``sniff(head: bytes) -> bool``: True when the first bytes of a file look like this
        format. Must be cheap and must never raise.
    read : callable
        ``read(path) -> Measurement``; raises :class:`AdapterError` on anything it cannot read.
    quantities : tuple of str
        The dataset quantities the reader can produce.
    keywords : tuple of bytes
        Byte strings typical of the format's first lines (a magic word, a header keyword).
        A file that no sniffer claims but that contains one of them names this format among
        the closest candidates in the error of :func:`labbrdf.read`. Never used to choose a
        reader.
    examples : tuple of Example
        Real exports of the format, the first one its reference file: the generic tests
        (dispatch, mutation, declared counts under a memory limit, ASCII digits) take
        their cases for the format from here. Never used to read a file.
    states_count : bool
        The files state their point count (or the reader checks the wavelength steps
        against the stated data interval), so a damaged file is either refused or read
        with every point: a mutated file never silently loses or gains a point.
    """

    name: str
    description: str
    extensions: tuple[str, ...]
    sniff: Callable[[bytes], bool]
    read: Callable[[str | os.PathLike[str]], Measurement]
    quantities: tuple[str, ...] = field(default=())
    keywords: tuple[bytes, ...] = field(default=())
    examples: tuple[Example, ...] = field(default=())
    states_count: bool = False


def parse_number(
    text: str,
    path: str | os.PathLike[str],
    line: int | None,
    what: str,
    *,
    nonfinite: bool = False,
) -> float:
    """Parse one number field of a text export, ASCII digits only.

    Parameters
    ----------
    text : str
        The field; surrounding blanks are allowed.
    path, line
        For the error message (``line`` 1-based, or None).
    what : str
        What the field is, e.g. ``"NPOINTS"``.
    nonfinite : bool
        Accept ``inf``/``nan`` spellings (only for formats that write them); otherwise the
        value must be finite, and a number that overflows a float is refused too.

    Raises
    ------
    AdapterError
        Not an ASCII decimal number (full-width digits, ``1_000``, words), or not finite.
    """
    s = text.strip()
    if DECIMAL.fullmatch(s) is None and not (nonfinite and NONFINITE.fullmatch(s)):
        shown = s if len(s) <= 40 else s[:37] + "..."
        raise AdapterError(path, f"{what}: expected a number, found {shown!r}", line)
    v = float(s)
    if not nonfinite and not math.isfinite(v):
        raise AdapterError(path, f"{what}: {s[:40]!r} overflows a float", line)
    return v


def check_count(
    path: str | os.PathLike[str],
    what: str,
    count: int,
    *,
    line: int | None = None,
    unit: str = "line",
    file_size: int | None = None,
    bytes_per_point: int = 0,
) -> int:
    """Check a point count declared in a file before anything is allocated for it.

    Parameters
    ----------
    path : str or path-like
        The file (for the message).
    what : str
        The count's name in the file, e.g. ``"NPOINTS"``.
    count : int
        The declared count.
    line : int, optional
        Where the count is written (line, or byte offset with ``unit="byte"``).
    unit : str
        ``"line"`` or ``"byte"``.
    file_size : int, optional
        Size of the file [bytes]; with ``bytes_per_point`` > 0 the data cannot hold more
        than ``file_size // bytes_per_point`` points.
    bytes_per_point : int
        Least number of bytes one point takes in the file (0: no size check).

    Returns
    -------
    int
        ``count``.

    Raises
    ------
    AdapterError
        The count is negative, above :data:`MAX_POINTS`, or more than the file can hold.
    """
    if count < 0:
        raise AdapterError(path, f"{what} = {count}: expected a count >= 0", line, unit=unit)
    if count > MAX_POINTS:
        raise AdapterError(
            path,
            f"{what} = {count} exceeds the limit of {MAX_POINTS} points (corrupt count?)",
            line,
            unit=unit,
        )
    if file_size is not None and bytes_per_point > 0 and count * bytes_per_point > file_size:
        raise AdapterError(
            path,
            f"{what} = {count} needs at least {count * bytes_per_point} bytes of data, but the "
            f"file has {file_size} (corrupt count or truncated file)",
            line,
            unit=unit,
        )
    return count


def check_regular_file(path: str | os.PathLike[str]) -> None:
    """Refuse anything but an existing regular file, before it is opened.

    A character device (``/dev/zero``) never ends and a FIFO blocks ``open`` until a writer
    comes, so both are refused from their ``stat`` alone (symbolic links are followed).

    Raises
    ------
    AdapterError
        No such file, a directory, or not a regular file (device, FIFO, socket).
    """
    try:
        st = os.stat(path)
    except OSError as exc:
        raise AdapterError(path, f"cannot be read ({exc.strerror or exc})") from None
    if stat.S_ISDIR(st.st_mode):
        raise AdapterError(path, "is a directory, expected a file")
    if not stat.S_ISREG(st.st_mode):
        kind = (
            "a character device"
            if stat.S_ISCHR(st.st_mode)
            else "a FIFO (named pipe)"
            if stat.S_ISFIFO(st.st_mode)
            else "a block device"
            if stat.S_ISBLK(st.st_mode)
            else "a socket"
            if stat.S_ISSOCK(st.st_mode)
            else "not a regular file"
        )
        raise AdapterError(path, f"is {kind}, expected a regular file")


def read_head(path: str | os.PathLike[str], n: int = 4096) -> bytes:
    """The first ``n`` bytes of a regular file; an unreadable or blank file raises AdapterError."""
    check_regular_file(path)
    try:
        with open(path, "rb") as fh:
            head = fh.read(n)
    except OSError as exc:
        raise AdapterError(path, f"cannot be read ({exc.strerror or exc})") from None
    if not head or head.isspace():
        raise AdapterError(path, "the file is empty")
    return head


def read_bytes(path: str | os.PathLike[str]) -> bytes:
    """Read a whole regular file; anything else, or an empty file, raises AdapterError."""
    check_regular_file(path)
    p = Path(path)
    try:
        raw = p.read_bytes()
    except IsADirectoryError:
        raise AdapterError(path, "is a directory, expected a file") from None
    except OSError as exc:
        raise AdapterError(path, f"cannot be read ({exc.strerror or exc})") from None
    if not raw or raw.isspace():  # as `not raw.strip()`, without copying a large file
        raise AdapterError(path, "the file is empty")
    return raw


def decode(
    raw: bytes, path: str | os.PathLike[str], encodings: tuple[str, ...] = ("utf-8", "cp1252")
) -> tuple[str, str]:
    """Decode bytes with the first encoding that works; strip a UTF-8 BOM.

    A NUL byte means binary content and raises :class:`AdapterError`. Latin-1 is not in the
    default list on purpose: it decodes anything, so it would hide a wrong encoding; a
    reader whose format is documented as Latin-1 passes it explicitly.
    """
    if b"\x00" in raw:
        line = raw[: raw.index(b"\x00")].count(b"\n") + 1
        raise AdapterError(path, "binary content (NUL byte) in a text format", line)
    if raw.startswith(b"\xef\xbb\xbf"):
        raw = raw[3:]
    for enc in encodings:
        try:
            return raw.decode(enc), enc
        except UnicodeDecodeError:
            continue
    # report where the last encoding tried (the most permissive) fails
    try:
        raw.decode(encodings[-1])
    except UnicodeDecodeError as exc:
        line = raw[: exc.start].count(b"\n") + 1
        raise AdapterError(
            path, f"byte 0x{raw[exc.start]:02x} is not valid in {', '.join(encodings)}", line
        ) from None
    raise AdapterError(path, "cannot be decoded")  # pragma: no cover


_EOL = re.compile(r"\r\n|\n|\r")


def split_lines(text: str) -> list[str]:
    """Split on CRLF, LF or CR only; a missing final newline is fine.

    Unlike :meth:`str.splitlines` this does not break at form feeds, vertical tabs or
    Unicode line separators, which can occur inside a field of a real export.
    """
    lines = _EOL.split(text)
    if lines and lines[-1] == "":
        lines.pop()
    return lines
