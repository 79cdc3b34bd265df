"""The registry of optical formats and the dispatch of one file to its reader.

Every vendor module defines ``FORMATS``; :data:`READERS` holds them by name in the order of
``_VENDOR_MODULES`` (the order of :func:`formats` and of the candidates named in errors).
:func:`read` chooses a reader as the package docstring (:mod:`labbrdf.adapters`) says;
:func:`input_kind` tells an optical export from a height map before anything is parsed.
"""

from __future__ import annotations

import os
import re
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

from ..dataset import Measurement, concat
from . import (
    accurion,
    astm_brdf,
    avantes,
    cary,
    cid,
    columns,
    filmsense,
    jasco,
    jcamp,
    labbrdf_csv,
    native,
    nexus,
    oceanoptics,
    pab_mountain,
    perkinelmer,
    refused,
    sentech,
    shimadzu,
    spc,
    speos_bsdf,
    wasatch,
    woollam,
    zemax_bsdf,
)
from ._base import AdapterError, Format, check_regular_file
from ._ole2 import is_ole2
from .columns import read_columns as _read_columns
from .topography import HEIGHT_MAP_FORMATS, height_map_format

__all__ = [
    "FormatRow",
    "KINDS",
    "READERS",
    "formats",
    "input_kind",
    "read",
    "read_many",
    "sniff",
]

# One module per vendor; each defines FORMATS: tuple[Format, ...]. The order here is the
# order of formats() and of the candidates named in errors.
_VENDOR_MODULES = (
    woollam,
    accurion,
    filmsense,
    sentech,
    jasco,
    perkinelmer,
    cary,
    jcamp,
    spc,
    shimadzu,
    oceanoptics,
    avantes,
    wasatch,
    cid,
    labbrdf_csv,
    native,
    zemax_bsdf,
    speos_bsdf,
    pab_mountain,
    astm_brdf,
    nexus,
    refused,
    columns,
)


def _registry() -> dict[str, Format]:
    out: dict[str, Format] = {}
    for module in _VENDOR_MODULES:
        for f in module.FORMATS:
            if f.name in out:
                raise RuntimeError(f"duplicate adapter name {f.name!r}")
            out[f.name] = f
    return out


#: name -> Format
READERS: dict[str, Format] = _registry()
#: formats whose files are OLE2 compound documents (the container decides among an
#: extension's formats when no sniffer claims the file)
_OLE2_FORMATS = ("shimadzu-uvprobe-spc", "jasco-jws")

_SNIFF_BYTES = 8192
#: how to force a format, in the words of both interfaces
_FORCE = "pass --format NAME on the command line or format=NAME in Python"
#: a line of only numbers and separators
_NUMBER_LINE = rb"[ \t]*[-+0-9.,;eE \t]+[ \t]*\r?\n"
#: a head of only numbers, separators and line breaks (a headerless column file), after
#: any ``#`` comment and blank lines (the columns reader skips those)
_NUMBERS_ONLY = re.compile(rb"\A(?:[ \t]*(?:#[^\r\n]*)?\r?\n)*(?:" + _NUMBER_LINE + rb"){2,}")
#: the same after a few lines of text (a title, a header): ``--skip-lines`` reads it
_NUMBERS_AFTER_TEXT = re.compile(rb"\A((?:[^\r\n]*\r?\n){1,60}?)(?:" + _NUMBER_LINE + rb"){3,}")


#: the kinds of input a format holds, as :func:`formats` names them
KINDS = {"optical": "optical", "height_map": "height map"}


class FormatRow(dict[str, Any]):
    """One supported format that prints as one line of ``labbrdf formats``.

    A dict with ``name``, ``kind``, ``description``, ``extensions`` and ``quantities``.
    """

    def __str__(self) -> str:
        exts = " ".join(self["extensions"])
        return f"{self['name']:<28} {self['kind']:<10} {exts:<18} {self['description']}"


def formats() -> list[FormatRow]:
    """The supported formats: optical exports, then height maps.

    Returns
    -------
    list of FormatRow
        Per format: ``name`` (the registry key; ``--format`` takes the optical ones),
        ``kind`` (``"optical"`` or ``"height map"``, :data:`KINDS`), ``description``,
        ``extensions`` (lower case, with the dot; for a height map also those it shares
        with optical exports, where its content decides) and ``quantities`` (a height map
        holds ``"height"``). ``str()`` of a row is its line in ``labbrdf formats``.
    """
    optical = [
        FormatRow(
            name=f.name,
            kind=KINDS["optical"],
            description=f.description,
            extensions=list(f.extensions),
            quantities=list(f.quantities),
        )
        for f in READERS.values()
    ]
    maps = [
        FormatRow(
            name=f.name,
            kind=KINDS["height_map"],
            description=f.description,
            extensions=[*f.extensions, *f.shared_extensions],
            quantities=["height"],
        )
        for f in HEIGHT_MAP_FORMATS
    ]
    return optical + maps


def _by_extension(path: Path) -> list[str]:
    name = path.name.lower()
    return [n for n, f in READERS.items() if any(name.endswith(e) for e in f.extensions)]


def _head(path: str | os.PathLike[str]) -> bytes:
    check_regular_file(path)
    try:
        with open(path, "rb") as fh:
            return fh.read(_SNIFF_BYTES)
    except OSError as exc:
        raise AdapterError(path, f"cannot be read ({exc.strerror or exc})") from None


def sniff(path: str | os.PathLike[str]) -> list[str]:
    """Names of the formats whose sniffer claims the file."""
    head = _head(path)
    return [n for n, f in READERS.items() if f.sniff(head)]


def _kind(p: Path, head: bytes) -> str:
    """``"height_map"`` or ``"optical"`` from the name and the first bytes."""
    claim = height_map_format(p, head)
    if claim is None:
        return "optical"
    fmt, own_extension = claim
    if own_extension:
        return "height_map"
    shared = p.name.lower().endswith(fmt.shared_extensions)
    if not shared and _by_extension(p):  # an optical format's own extension
        return "optical"
    return "optical" if any(f.sniff(head) for f in READERS.values()) else "height_map"


def input_kind(path: str | os.PathLike[str]) -> str:
    """Whether a file is an optical export or a height map, before anything is parsed.

    Parameters
    ----------
    path : str or path-like
        The file.

    Returns
    -------
    str
        ``"height_map"`` for an extension only topography instruments write
        (:data:`~labbrdf.adapters.heightmap_formats.HEIGHT_MAP_FORMATS`), or for a file whose
        first bytes a height-map sniffer claims and no optical sniffer does, when its
        extension is one the height-map format shares with optical exports (a MetroPro
        ``.dat`` beside WVASE ``.dat``) or belongs to no format; ``"optical"`` otherwise.

    Raises
    ------
    AdapterError
        The file is missing, not a regular file, or cannot be read.
    """
    p = Path(path)
    return _kind(p, _head(p))


def _height_map_error(path: str | os.PathLike[str]) -> AdapterError:
    return AdapterError(
        path,
        "is a height map (topography file), not an optical export: read it with "
        "labbrdf.read_height_map, or labbrdf.read_inputs for a mix of both kinds",
    )


def _no_match_message(path: Path, by_ext: list[str], head: bytes) -> str:
    """Name the closest candidates: the extension's formats and keyword matches."""
    near = [
        n for n, f in READERS.items() if n not in by_ext and any(k in head for k in f.keywords)
    ]
    parts = []
    if by_ext:
        parts.append(f"formats of the extension {path.suffix.lower()!r}: {by_ext}")
    if near:
        parts.append(f"formats whose keywords occur in the header: {near}")
    hint = ""
    if is_ole2(head):
        hint = (
            "; it is an OLE2 compound document (Microsoft structured storage, magic "
            "D0 CF 11 E0 A1 B1 1A E1), the container of Shimadzu UVProbe .spc "
            "('shimadzu-uvprobe-spc'), legacy JASCO .jws ('jasco-jws') and Office files"
        )
    elif _NUMBERS_ONLY.match(head):
        hint = (
            "; its first lines are bare numbers: declare the columns with --columns on the "
            "command line or columns= in Python (format 'columns'), e.g. "
            "--columns wavelength_nm,absorbance"
        )
    elif m := _NUMBERS_AFTER_TEXT.match(head):
        k = len(re.findall(rb"\n", m.group(1)))
        hint = (
            f"; after {k} line(s) of text it holds bare numbers: declare the columns and skip "
            "the text with --columns and --skip-lines on the command line (columns= with a "
            "skip_lines= entry in Python, format 'columns'), e.g. --columns "
            f"wavelength_nm,absorbance --skip-lines {k}"
        )
    if not parts:
        return (
            "no adapter recognises this file: neither its extension nor its first lines "
            "belong to a supported format; `labbrdf formats` (labbrdf.adapters.formats() in "
            "Python) lists them" + hint
        )
    return (
        "no adapter recognises this file (no header sniffer claims it); closest candidates: "
        + "; ".join(parts)
        + f"; {_FORCE} to read it with one of them and see what does not match"
        + hint
    )


def _read_with(name: str, path: Path) -> Measurement:
    try:
        m = READERS[name].read(path)
    except MemoryError:
        # a file whose content asks for more memory than there is: name the file, and free
        # what the reader held before anything else allocates
        raise AdapterError(
            path,
            f"ran out of memory reading it as {name!r} (file of "
            f"{_size(path)} bytes): corrupt counts or an absurd header?",
        ) from None
    if not isinstance(m, Measurement):  # a reader bug, not a user error
        raise TypeError(f"adapter {name!r} returned {type(m).__name__}, not a Measurement")
    m.meta.setdefault("format", name)
    return m


def _size(path: Path) -> int | str:
    try:
        return path.stat().st_size
    except OSError:
        return "unknown"


def read(
    path: str | os.PathLike[str],
    format: str | None = None,
    *,
    columns: str | Sequence[str] | None = None,
) -> Measurement:
    """Read one instrument export into a validated :class:`~labbrdf.dataset.Measurement`.

    Parameters
    ----------
    path : str or path-like
        The export file.
    format : str, optional
        A registry name (see :func:`formats`); by default chosen from the extension and
        the header.
    columns : str or sequence of str, optional
        The declared columns of a headerless numeric file (format ``"columns"``, implied),
        e.g. ``"wavelength_nm,absorbance"``; see :mod:`labbrdf.adapters.columns`.

    Raises
    ------
    AdapterError
        The file cannot be read, or the format is ambiguous or unknown; or, with no
        ``format`` and no ``columns``, it is a height map (:func:`input_kind`): the message
        says so and names :func:`labbrdf.read_height_map` and :func:`read_inputs`.
    """
    p = Path(path)
    if format is not None and format not in READERS:
        raise AdapterError(
            path, f"unknown format {format!r}; supported formats are {sorted(READERS)}"
        )
    if columns is not None and format not in (None, "columns"):
        raise AdapterError(
            path,
            f"--columns / columns= declare the columns of format 'columns', not of {format!r}",
        )
    # before any reader opens it: /dev/zero never ends, a FIFO blocks open()
    check_regular_file(p)
    if columns is not None:
        try:
            m = _read_columns(p, columns)
        except MemoryError:
            raise AdapterError(
                path, f"ran out of memory reading it as 'columns' (file of {_size(p)} bytes)"
            ) from None
        m.meta.setdefault("format", "columns")
        return m
    if format is not None:
        return _read_with(format, p)
    head = _head(p)
    if _kind(p, head) == "height_map":
        raise _height_map_error(path)
    return _dispatch(path, p, head)


def _dispatch(path: str | os.PathLike[str], p: Path, head: bytes) -> Measurement:
    """The reader the extension and the sniffers choose (see the module docstring)."""
    by_ext = _by_extension(p)
    claimed = [n for n, f in READERS.items() if f.sniff(head)]
    # the extension's formats first; when none of them claims the file, the content decides
    pool = [n for n in claimed if n in by_ext] or claimed
    if len(pool) == 1:
        return _read_with(pool[0], p)
    if pool:
        raise AdapterError(path, f"several adapters claim this file: {pool}; {_FORCE}")
    if is_ole2(head):  # an OLE2 container goes to the extension's OLE2 format, if any
        by_ext = [n for n in by_ext if n in _OLE2_FORMATS] or by_ext
    if len(by_ext) == 1:  # its reader says what is wrong, and where
        return _read_with(by_ext[0], p)
    raise AdapterError(path, _no_match_message(p, by_ext, head))


def read_many(
    paths: Iterable[str | os.PathLike[str]],
    format: str | None = None,
    *,
    columns: str | Sequence[str] | None = None,
) -> Measurement:
    """Read several files and concatenate them (each row keeps its ``source``)."""
    return concat(read(p, format, columns=columns) for p in paths)
