"""OLE2 compound documents (Microsoft structured storage), the container of two vendor formats.

Shimadzu UVProbe ``.spc`` and JASCO Spectra Manager 1.x ``.jws`` files are OLE2 compound
documents: a small file system of named *streams* in *storages*, recognised by the 8-byte
magic ``D0 CF 11 E0 A1 B1 1A E1`` at offset 0. The container is read with ``olefile``; the
vendor modules decode the streams. Every failure becomes an :class:`AdapterError` naming the
file and the stream.
"""

from __future__ import annotations

import os
import struct
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

import olefile

from ._base import AdapterError

__all__ = ["OLE2_MAGIC", "is_ole2", "ole_names", "open_ole2", "read_stream"]

#: First 8 bytes of every OLE2 compound document.
OLE2_MAGIC = b"\xd0\xcf\x11\xe0\xa1\xb1\x1a\xe1"
#: Largest stream read [bytes]: a UV-Vis-NIR or FTIR spectrum of MAX_POINTS float64 values
#: is 16 MB; a stream that claims more is a corrupt directory entry.
MAX_STREAM_BYTES = 64 << 20
#: What olefile raises on a corrupt container: its own OleFileError (an OSError), struct
#: errors on short buffers, lookup errors on bad sector or entry indices, RecursionError on
#: a deep directory tree.
_OLE_ERRORS = (
    OSError,
    ValueError,
    IndexError,
    KeyError,
    TypeError,
    AssertionError,
    OverflowError,
    RecursionError,
    struct.error,
)


def is_ole2(head: bytes) -> bool:
    """True when ``head`` starts with the OLE2 magic."""
    return head[:8] == OLE2_MAGIC


def ole_names(head: bytes, *names: str) -> bool:
    """True when ``head`` is OLE2 and holds every directory entry name of ``names``.

    Directory entries store names in UTF-16LE; in small files they lie in the first few
    kilobytes, which is what the sniffers see. A file whose directory lies further is not
    claimed by content and is dispatched by its extension.
    """
    return is_ole2(head) and all(n.encode("utf-16-le") in head for n in names)


@contextmanager
def open_ole2(path: str | os.PathLike[str], what: str) -> Iterator[Any]:
    """Open an OLE2 compound document; ``what`` names the expected format in errors."""
    try:
        with open(path, "rb") as fh:
            head = fh.read(8)
    except OSError as exc:
        raise AdapterError(path, f"cannot be read ({exc.strerror or exc})") from None
    if not head:
        raise AdapterError(path, "the file is empty")
    if not is_ole2(head):
        raise AdapterError(
            path,
            f"expected a {what} (an OLE2 compound document starting with the bytes "
            f"D0 CF 11 E0 A1 B1 1A E1), found {head!r}",
            0,
            unit="byte",
        )
    try:
        # strict: a defect that olefile would log and work around (a sector index past the
        # end of a truncated file, a bad directory entry) is an error here
        ole = olefile.OleFileIO(os.fspath(path), raise_defects=olefile.DEFECT_INCORRECT)
    except _OLE_ERRORS as exc:
        # olefile raises OSError ("not an OLE2 structured storage file", truncated sectors)
        # and, on a corrupt FAT or directory, assorted lookup errors
        raise AdapterError(
            path, f"{what}: the OLE2 container is corrupt or truncated ({exc})"
        ) from None
    try:
        yield ole
    finally:
        ole.close()


def read_stream(ole: Any, path: str | os.PathLike[str], name: str, what: str) -> bytes:
    """The bytes of stream ``name`` (``/``-separated), or AdapterError naming it."""
    try:
        if not ole.exists(name) or ole.get_type(name) != olefile.STGTY_STREAM:
            raise AdapterError(path, f"{what}: no stream {name!r} in the OLE2 container")
        size = ole.get_size(name)
        if size > MAX_STREAM_BYTES:
            raise AdapterError(
                path,
                f"{what}: stream {name!r} claims {size} bytes, more than the "
                f"{MAX_STREAM_BYTES} a spectrum can take (corrupt directory?)",
            )
        with ole.openstream(name) as fh:
            data: bytes = fh.read()
    except AdapterError:
        raise
    except _OLE_ERRORS as exc:
        raise AdapterError(
            path, f"{what}: stream {name!r} cannot be read ({exc}): corrupt or truncated"
        ) from None
    if len(data) != size:
        raise AdapterError(
            path, f"{what}: stream {name!r} holds {len(data)} of its {size} bytes (truncated)"
        )
    return data
