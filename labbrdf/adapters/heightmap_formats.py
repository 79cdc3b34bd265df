"""Which files are height maps: their extensions, and the magic bytes that decide a shared one.

:data:`HEIGHT_MAP_FORMATS` lists the extensions only topography instruments write, the ones
shared with optical exports (MetroPro ``.dat`` beside WVASE and Accurion ``.dat``) and the
cheap sniffers that decide for those; :func:`height_map_format` says which format claims a
file, and :func:`labbrdf.adapters.input_kind` weighs that against the optical sniffers.
The files themselves are read by :func:`labbrdf.adapters.topography.read_height_map`.
"""

from __future__ import annotations

import os
import re
from collections.abc import Callable
from dataclasses import dataclass

__all__ = ["HEIGHT_MAP_FORMATS", "HeightMapFormat", "height_map_format"]


#: MetroPro header magic numbers (format 1, 2 and 3), big-endian at byte 0
_METROPRO_MAGIC = (b"\x88\x1b\x03\x6f", b"\x88\x1b\x03\x70", b"\x88\x1b\x03\x71")


def _never(head: bytes) -> bool:
    return False


@dataclass(frozen=True)
class HeightMapFormat:
    """One family of topography files (all read by :func:`read_height_map`).

    The registry entry the dispatcher (:func:`labbrdf.adapters.input_kind`) uses to tell a
    height map from an optical export before anything is parsed.

    Attributes
    ----------
    name : str
        Registry key, e.g. ``"zygo-metropro"``.
    description : str
        One line.
    extensions : tuple of str
        Lower-case extensions (with the dot) that only this kind of instrument writes: a
        file with one of them is a height map.
    shared_extensions : tuple of str
        Extensions optical exports use too (MetroPro ``.dat`` beside WVASE and Accurion
        ``.dat``): such a file is a height map only when :attr:`sniff` claims it and no
        optical sniffer does. A file whose extension belongs to an optical format and is
        not listed here stays optical whatever its content; one whose extension belongs
        to no format is a height map when a sniffer here claims it.
    sniff : callable
        ``sniff(head: bytes) -> bool`` on the first bytes: cheap, never raises.
    shared_only : bool
        The sniffer claims only files with one of :attr:`shared_extensions` (plain numbers
        are a height profile in a ``.asc`` but may be anything in a file of another name).
    """

    name: str
    description: str
    extensions: tuple[str, ...]
    shared_extensions: tuple[str, ...] = ()
    sniff: Callable[[bytes], bool] = _never
    shared_only: bool = False


#: Header keys of ASCII topography exports SurfaceTopography's text reader knows (Gwyddion,
#: Wyko, SPIP, ...), at the start of a line after an optional ``#``.
_ASCII_TOPO_KEYS = re.compile(
    rb"^\s*#?\s*(Width|Height|Value units|Wyko ASCII Data File Format|File Format\s*=\s*ASCII"
    rb"|x-pixels|y-pixels|X Size|Y Size)\b",
    re.IGNORECASE | re.MULTILINE,
)
_NUMBER_ROW = re.compile(rb"^\s*[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?([\s,;]+\S+)*\s*$")


def _ascii_topography(head: bytes) -> bool:
    """An ASCII height profile or matrix: known header keys, or rows of plain numbers.

    A two-column ``x z`` profile (the shape of SurfaceTopography's ``nonuniform.asc``) or a
    matrix of heights; never a file that starts with another format's magic (PerkinElmer's
    ``PE UV``), nor one with a NUL byte.
    """
    if b"\0" in head or head.lstrip().startswith(b"PE UV"):
        return False
    if _ASCII_TOPO_KEYS.search(head[:4096]):
        return True
    rows = [r for r in head.splitlines()[:40] if r.strip() and not r.lstrip().startswith(b"#")]
    if head and not head.endswith((b"\n", b"\r")):
        rows = rows[:-1]  # the last row may be cut mid-number
    return len(rows) >= 2 and all(_NUMBER_ROW.match(r) for r in rows)


#: The height-map formats. SurfaceTopography chooses its own reader from the content; the
#: entries say which files are height maps (extension, or magic bytes for a shared one).
HEIGHT_MAP_FORMATS: tuple[HeightMapFormat, ...] = (
    HeightMapFormat(
        "zygo-metropro",
        "Zygo MetroPro binary height map",
        (),
        (".dat",),
        lambda head: head[:4] in _METROPRO_MAGIC,
    ),
    HeightMapFormat(
        "nanoscope",
        "Digital Instruments / Bruker Nanoscope AFM file",
        (".di", ".spm", ".000", ".001", ".002", ".003", ".004", ".005"),
        sniff=lambda head: head.startswith(b"\\*File list"),
    ),
    HeightMapFormat(
        "bruker-opdx",
        "Bruker OPDx optical profiler file",
        (".opdx",),
        sniff=lambda head: head.startswith(b"VCA DATA"),
    ),
    HeightMapFormat(
        "bcr-stm",
        "BCR-STM / BCRF scanning-probe file",
        (".bcr", ".bcrf"),
        sniff=lambda head: head.startswith((b"fileformat = bcr", b"fileformat = bcrf")),
    ),
    HeightMapFormat(
        "ascii-topography",
        "plain ASCII height profile (x z columns) or height matrix, with or without a"
        " Gwyddion / Wyko / SPIP header (SurfaceTopography's text readers)",
        (),
        (".asc",),
        _ascii_topography,
        shared_only=True,
    ),
    HeightMapFormat(
        "surfacetopography",
        "other topography formats SurfaceTopography reads (Gwyddion, X3P, Keyence, "
        "Olympus LEXT, Wyko OPD, Digital Surf SUR, NT-MDT, ...)",
        (
            ".opd", ".sur", ".gwy", ".ibw", ".mi", ".nc", ".plu", ".plux", ".apx", ".x3p",
            ".datx", ".vk3", ".vk4", ".vk6", ".vk7", ".zmg", ".zon", ".lext", ".os3d", ".frt",
            ".sdf", ".nid", ".ezd", ".mdt", ".al3d", ".tmd", ".jpk", ".mnt", ".oir", ".poir",
            ".nms",
        ),
    ),
)  # fmt: skip


def height_map_format(
    path: str | os.PathLike[str], head: bytes
) -> tuple[HeightMapFormat, bool] | None:
    """Which height-map format claims a file, and whether by an extension of its own.

    Parameters
    ----------
    path : path-like
        The file (its name decides first).
    head : bytes
        Its first bytes (``b""`` to decide by the name alone).

    Returns
    -------
    (HeightMapFormat, bool) or None
        ``(format, True)`` for an extension only height maps have; ``(format, False)`` when
        a sniffer claims the content (the dispatcher weighs that against the optical
        formats, :func:`labbrdf.adapters.input_kind`); None when no height-map format claims
        the file.
    """
    name = os.fspath(path).lower()
    for f in HEIGHT_MAP_FORMATS:
        if name.endswith(f.extensions):
            return f, True
    for f in HEIGHT_MAP_FORMATS:
        if f.shared_only and not name.endswith(f.shared_extensions):
            continue
        if f.sniff(head):
            return f, False
    return None
