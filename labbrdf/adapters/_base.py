"""Shared pieces of the instrument adapters: the error type, the format record, text decoding.

Adapters import only :mod:`labbrdf.dataset` and this module.
"""

from __future__ import annotations

import os
import re
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

from ..dataset import Measurement
from ..errors import LabbrdfError

__all__ = ["AdapterError", "Format", "decode", "read_bytes", "split_lines"]


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
        where = f"{self.path}, {unit} {line}" if line is not None else self.path
        super().__init__(f"{where}: {message}")


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
    """

    name: str
    description: str
    extensions: tuple[str, ...]
    sniff: Callable[[bytes], bool]
    read: Callable[[str | os.PathLike[str]], Measurement]
    quantities: tuple[str, ...] = field(default=())


def read_bytes(path: str | os.PathLike[str]) -> bytes:
    """Read a whole file; an unreadable or empty file raises :class:`AdapterError`."""
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
