"""OLE2 compound documents (Microsoft structured storage), the container of two vendor formats.

Shimadzu UVProbe ``.spc`` and JASCO Spectra Manager 1.x ``.jws`` files are OLE2 compound
documents: a small file system of named *streams* in *storages*, recognised by the 8-byte
magic ``D0 CF 11 E0 A1 B1 1A E1`` at offset 0. The container is read with ``olefile``; the
vendor modules decode the streams. Every failure becomes an :class:`AdapterError` naming the
file and the stream.

``olefile`` (opened with ``raise_defects=DEFECT_INCORRECT``) refuses bad headers, sector
indices past the end of the file, a stream whose chain ends early and a start sector shared
by two streams, but it follows a chain for as many sectors as the stream's size needs
without noticing a loop or a jump into another stream's sectors, and it skips directory
entries that the tree does not reach. So before any stream is read, :func:`open_ole2`
checks the whole container against [MS-CFB]:

* the FAT sectors (listed in the header and the DIFAT sectors) are as many as the header
  says, lie in the file, are distinct and are marked FATSECT (DIFAT sectors DIFSECT) in the
  FAT;
* every chain -- the directory, the mini FAT, the mini stream, each stream -- visits no
  sector twice, stays inside the file (the FAT) or inside the mini stream (the mini FAT),
  ends with ENDOFCHAIN and has exactly the number of sectors its declared size needs;
* no sector (mini sector) belongs to two chains;
* every allocated directory entry is reached from the root, and no entry in the tree is
  marked unused.

A container that fails any of these is refused naming the file and the stream; what is
read is then exactly what the directory entry and its chain say.
"""

from __future__ import annotations

import os
import struct
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

import olefile
from olefile.olefile import OleFileError

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


# ----------------------------------------------------------------------------- chain checks

_END, _FREE, _FATSECT, _DIFSECT = (
    olefile.ENDOFCHAIN,
    olefile.FREESECT,
    olefile.FATSECT,
    olefile.DIFSECT,
)
_SPECIAL = {_END: "ENDOFCHAIN", _FREE: "FREESECT", _FATSECT: "FATSECT", _DIFSECT: "DIFSECT"}
#: [MS-CFB] size of the header's DIFAT array and of a directory entry [bytes]
_HEADER_DIFAT, _DIRENTRY = 109, 128


class _Corrupt(Exception):
    """A structural defect of the container; the message says which chain and sector."""


def _sector(index: int) -> str:
    return _SPECIAL.get(index, str(index))


def _chain(table: Any, start: int, count: int | None, what: str, unit: str) -> list[int]:
    """The sectors of the chain from ``start`` in ``table`` (the FAT or the mini FAT).

    ``count`` is the number of sectors the declared size needs (None: unknown, the
    directory). The walk visits each entry at most once, so it is bounded by the table.
    """
    chain: list[int] = []
    seen: set[int] = set()
    sect = start
    while sect != _END:
        if not 0 <= sect < len(table):
            raise _Corrupt(
                f"the chain of {what} reaches {unit} {_sector(sect)}, not one of the "
                f"{len(table)} {unit}s of the {'mini stream' if unit != 'sector' else 'file'}"
            )
        if sect in seen:
            raise _Corrupt(f"the chain of {what} visits {unit} {sect} twice (a loop)")
        if count is not None and len(chain) == count:
            raise _Corrupt(
                f"the chain of {what} goes on past the {count} {unit}(s) its declared size needs"
            )
        seen.add(sect)
        chain.append(sect)
        sect = int(table[sect])
    if count is not None and len(chain) != count:
        raise _Corrupt(
            f"the chain of {what} ends after {len(chain)} {unit}(s), its declared size "
            f"needs {count}"
        )
    return chain


def _claim(owner: dict[int, str], chain: list[int], what: str, unit: str) -> None:
    """Record that ``chain`` belongs to ``what``; a sector owned twice is a defect."""
    for sect in chain:
        if sect in owner:
            raise _Corrupt(f"{unit} {sect} belongs to both {owner[sect]} and {what}")
        owner[sect] = what


def _fat_sectors(ole: Any) -> tuple[list[int], list[int]]:
    """The FAT sectors the header and the DIFAT sectors list, and the DIFAT sectors."""
    ole.fp.seek(0)
    header = ole.fp.read(512)
    listed = list(struct.unpack_from(f"<{_HEADER_DIFAT}I", header, 76))
    difat: list[int] = []
    per = ole.sectorsize // 4 - 1  # the last entry of a DIFAT sector points to the next one
    sect = ole.first_difat_sector
    for _ in range(ole.num_difat_sectors):
        if sect in difat or not 0 <= sect < len(ole.fat):
            raise _Corrupt(f"the DIFAT chain reaches sector {_sector(sect)} (a loop or outside)")
        difat.append(sect)
        entries = ole.sect2array(ole.getsect(sect))
        listed += list(entries[:per])
        sect = int(entries[per])
    if difat and sect not in (_END, _FREE):
        raise _Corrupt(f"the DIFAT chain goes on past its {len(difat)} sector(s)")
    nfat = ole.num_fat_sectors
    used, unused = listed[:nfat], listed[nfat:]
    if len(used) != nfat or any(s in (_END, _FREE) for s in used):
        raise _Corrupt(f"the header says {nfat} FAT sectors, the DIFAT lists fewer")
    if any(s not in (_END, _FREE) for s in unused):
        raise _Corrupt(f"the DIFAT lists more FAT sectors than the {nfat} the header says")
    return used, difat


def _check_fat(ole: Any, owner: dict[int, str]) -> None:
    """The FAT and DIFAT sectors: in the file, distinct, and marked as such in the FAT."""
    fat_sects, difat = _fat_sectors(ole)
    for sects, mark, what in ((fat_sects, _FATSECT, "the FAT"), (difat, _DIFSECT, "the DIFAT")):
        for sect in sects:
            if not 0 <= sect < len(ole.fat):
                raise _Corrupt(f"{what} lists sector {_sector(sect)}, outside the file")
            if int(ole.fat[sect]) != mark:
                raise _Corrupt(
                    f"{what} sector {sect} is marked {_sector(int(ole.fat[sect]))} in the "
                    f"FAT, not {_SPECIAL[mark]}"
                )
        _claim(owner, sects, what, "sector")


def _entry_paths(ole: Any) -> dict[int, str]:
    """The ``/``-separated path of every directory entry reached from the root, by sid."""
    paths: dict[int, str] = {ole.root.sid: "the root entry (the mini stream)"}
    todo = [(ole.root, "")]
    while todo:
        node, prefix = todo.pop()
        for kid in node.kids:
            paths[kid.sid] = prefix + kid.name
            todo.append((kid, prefix + kid.name + "/"))
    return paths


def _check_tree(ole: Any, paths: dict[int, str]) -> None:
    """Every allocated directory entry is in the tree, and no entry in it is unused."""
    ole.directory_fp.seek(0)
    raw = ole.directory_fp.read()
    for sid in range(len(raw) // _DIRENTRY):
        kind = raw[sid * _DIRENTRY + 66]
        if kind != olefile.STGTY_EMPTY and sid not in paths:
            raise _Corrupt(f"directory entry {sid} is not reached from the root")
        if kind == olefile.STGTY_EMPTY and sid in paths:
            raise _Corrupt(f"directory entry {sid} ({paths[sid]!r}) is in the tree but unused")


def _check_streams(ole: Any, paths: dict[int, str], owner: dict[int, str]) -> None:
    """The chains of the mini stream and of each stream, in the FAT or the mini FAT."""
    big, mini = ole.sectorsize, ole.minisectorsize
    mini_owner: dict[int, str] = {}
    has_mini = False
    for sid in sorted(paths):
        entry = ole.direntries[sid]
        if entry.entry_type not in (olefile.STGTY_ROOT, olefile.STGTY_STREAM) or not entry.size:
            continue  # a storage, or an empty stream: nothing is read
        what = paths[sid] if sid == ole.root.sid else f"stream {paths[sid]!r}"
        if entry.entry_type == olefile.STGTY_STREAM and entry.size < ole.minisectorcutoff:
            has_mini = True
            continue
        count = -(-entry.size // big)
        _claim(owner, _chain(ole.fat, entry.isectStart, count, what, "sector"), what, "sector")
    if not has_mini:
        return
    if not ole.minifat:
        ole.loadminifat()  # the mini FAT, cut to the mini sectors of the mini stream
    for sid in sorted(paths):
        entry = ole.direntries[sid]
        if entry.entry_type != olefile.STGTY_STREAM or not 0 < entry.size < ole.minisectorcutoff:
            continue
        what = f"stream {paths[sid]!r}"
        chain = _chain(ole.minifat, entry.isectStart, -(-entry.size // mini), what, "mini sector")
        _claim(mini_owner, chain, what, "mini sector")


def _check_container(ole: Any) -> None:
    """Check every chain of an open container (see the module docstring).

    Raises
    ------
    _Corrupt
        The defect, naming the chain (stream) and the sector.
    """
    owner: dict[int, str] = {}
    _check_fat(ole, owner)
    ndir = ole.num_dir_sectors if ole.sectorsize == 4096 else None
    directory = _chain(ole.fat, ole.first_dir_sector, ndir, "the directory", "sector")
    _claim(owner, directory, "the directory", "sector")
    nminifat = ole.num_mini_fat_sectors
    if nminifat:  # else no mini FAT is read, whatever its start sector says
        minifat = _chain(ole.fat, ole.first_mini_fat_sector, nminifat, "the mini FAT", "sector")
        _claim(owner, minifat, "the mini FAT", "sector")
    paths = _entry_paths(ole)
    _check_tree(ole, paths)
    _check_streams(ole, paths, owner)


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
        try:
            _check_container(ole)
        except _Corrupt as exc:
            raise AdapterError(path, f"{what}: the OLE2 container is corrupt: {exc}") from None
        except _OLE_ERRORS as exc:
            raise AdapterError(
                path, f"{what}: the OLE2 container is corrupt or truncated ({exc})"
            ) from None
        try:
            yield ole
        except OleFileError as exc:  # listing or looking up entries of the tree
            raise AdapterError(
                path, f"{what}: the OLE2 container is corrupt or truncated ({exc})"
            ) from None
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
