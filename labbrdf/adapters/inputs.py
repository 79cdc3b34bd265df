"""One reader for a list of input paths: optical exports and height maps, each file once.

>>> inputs = labbrdf.read_inputs(["w2_10102006.dat", "afm.di"])   # doctest: +SKIP
>>> inputs.measurement, inputs.height_maps, inputs.failures          # doctest: +SKIP

Every path is classified first (:func:`labbrdf.adapters.input_kind`: the name and the first
bytes, nothing parsed), then read once by the reader of its kind: an optical export with the
dispatch of :func:`labbrdf.adapters.read` into a :class:`~labbrdf.dataset.Measurement`, a
height map with :func:`~labbrdf.adapters.topography.read_height_map`. A file that cannot be
read is a failure that names the file and says why; the others are still read (or, with
``on_error="raise"``, the first failure is raised).
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

from ..dataset import Measurement, concat
from ._base import AdapterError, check_regular_file
from .topography import HeightMap, height_map_format, read_height_map

__all__ = ["KINDS", "InputFile", "Inputs", "read_inputs"]

#: the input kinds: optical exports (a Measurement) and height maps (a HeightMap)
KINDS = ("optical", "height_map")


@dataclass(frozen=True)
class InputFile:
    """One input path and what reading it gave.

    Attributes
    ----------
    path : str
        The path as given.
    kind : str
        ``"optical"`` or ``"height_map"`` (what the file was read as).
    measurement : Measurement or None
        The optical data (kind ``"optical"``, read).
    height_map : HeightMap or None
        The height map (kind ``"height_map"``, read).
    error : str
        Why the file could not be read, starting with the file's name (``""`` when read).
    """

    path: str
    kind: str
    measurement: Measurement | None = None
    height_map: HeightMap | None = None
    error: str = ""

    @property
    def ok(self) -> bool:
        """True when the file was read."""
        return not self.error


@dataclass(frozen=True)
class Inputs:
    """What :func:`read_inputs` read: one :class:`InputFile` per path, in the given order.

    Attributes
    ----------
    files : tuple of InputFile
        Every path, read or failed.
    """

    files: tuple[InputFile, ...]

    @property
    def measurements(self) -> tuple[Measurement, ...]:
        """The optical data, one Measurement per optical file read."""
        return tuple(f.measurement for f in self.files if f.measurement is not None)

    @property
    def measurement(self) -> Measurement | None:
        """All optical data as one Measurement (each row keeps its ``source``), or None."""
        ms = self.measurements
        return concat(ms) if ms else None

    @property
    def height_maps(self) -> tuple[HeightMap, ...]:
        """The height maps and profiles read."""
        return tuple(f.height_map for f in self.files if f.height_map is not None)

    @property
    def failures(self) -> tuple[InputFile, ...]:
        """The files that could not be read (``error`` says why)."""
        return tuple(f for f in self.files if f.error)


def _kind_of(
    path: str | os.PathLike[str],
    kind: str | None,
    format: str | None,
    columns: str | Sequence[str] | None,
) -> str:
    """The kind to read ``path`` as: forced, implied by ``format``/``columns``, or sniffed."""
    from .registry import _head, _kind

    if kind is not None:
        return kind
    if format is not None or columns is not None:
        return "optical"
    return _kind(Path(path), _head(path))


def _read_as(
    path: str | os.PathLike[str],
    kind: str,
    format: str | None,
    columns: str | Sequence[str] | None,
    height_map_kw: dict[str, Any],
) -> InputFile:
    """Read one path as ``kind``; raise what the reader raises."""
    from .registry import _dispatch, _head, read

    if kind == "height_map":
        return InputFile(str(path), kind, height_map=read_height_map(path, **height_map_kw))
    if format is not None or columns is not None:
        return InputFile(str(path), kind, measurement=read(path, format, columns=columns))
    p = Path(path)
    check_regular_file(p)
    return InputFile(str(path), kind, measurement=_dispatch(path, p, _head(p)))


def _guessed_kind(path: str | os.PathLike[str]) -> str:
    """The kind of a file that could not even be opened: its extension's, else optical."""
    claim = height_map_format(path, b"")
    return "height_map" if claim is not None and claim[1] else "optical"


#: the errors of a file that cannot be read; any other is unexpected and named as such
_READ_ERRORS = (ValueError, NotImplementedError, OSError, ImportError, MemoryError)


def _message(path: str | os.PathLike[str], exc: BaseException) -> str:
    """The error as a line that starts with the file (an AdapterError already does)."""
    text = " ".join(str(exc).split())
    if isinstance(exc, AdapterError):
        return text
    if isinstance(exc, _READ_ERRORS):
        return f"{path}: {text or type(exc).__name__}"
    return f"{path}: unexpected {type(exc).__name__} while reading{': ' + text if text else ''}"


def read_inputs(
    paths: Iterable[str | os.PathLike[str]],
    format: str | None = None,
    *,
    columns: str | Sequence[str] | None = None,
    kind: Literal["optical", "height_map"] | None = None,
    channel: int | str | None = None,
    unit: str | None = None,
    pixel_size: float | tuple[float, ...] | None = None,
    on_error: Literal["collect", "raise"] = "collect",
) -> Inputs:
    """Read a list of paths, optical exports and height maps alike, each file once.

    Parameters
    ----------
    paths : iterable of path-like
        The input files, in order.
    format : str, optional
        Read every file as this optical format (:func:`labbrdf.adapters.formats`); implies
        ``kind="optical"``.
    columns : str or sequence of str, optional
        The declared columns of headerless numeric files (:func:`labbrdf.adapters.read`);
        implies ``kind="optical"``.
    kind : {"optical", "height_map"}, optional
        Read every file as this kind; by default each file's kind is decided by
        :func:`labbrdf.adapters.input_kind` (name and first bytes).
    channel, unit, pixel_size
        For height maps: as :func:`~labbrdf.adapters.topography.read_height_map`.
    on_error : {"collect", "raise"}
        ``"collect"``: a file that cannot be read becomes a failure and the others are read;
        ``"raise"``: the first such error is raised, and later files are not read.

    Returns
    -------
    Inputs
        One :class:`InputFile` per path; ``.measurement`` (all optical data),
        ``.height_maps`` and ``.failures``.

    Raises
    ------
    ValueError
        An unknown ``kind`` or ``on_error``, or ``format`` / ``columns`` with
        ``kind="height_map"``.
    AdapterError
        With ``on_error="raise"``: the first file that cannot be read.
    ImportError
        With ``on_error="raise"``: a height map and no SurfaceTopography.

    Notes
    -----
    With ``"collect"``, whatever reading one file raises makes that file a failure and the
    others are still read: the errors of a file that cannot be read (:class:`AdapterError`
    and the dataset's validation errors, both ``ValueError``; ``NotImplementedError`` for a
    recognised but unsupported format; ``OSError``; ``MemoryError``; for a height map the
    ``ImportError`` of a missing SurfaceTopography) and any other, which the message names
    as unexpected. One file never takes the others down.
    """
    if kind not in (None, *KINDS):
        raise ValueError(f"kind {kind!r}: expected one of {KINDS} or None")
    if on_error not in ("collect", "raise"):
        raise ValueError(f"on_error {on_error!r}: expected 'collect' or 'raise'")
    if kind == "height_map" and (format is not None or columns is not None):
        raise ValueError("format= and columns= are for optical exports, not kind='height_map'")
    hm_kw = {"channel": channel, "unit": unit, "pixel_size": pixel_size}
    files: list[InputFile] = []
    for path in paths:
        k: str | None = kind
        try:
            k = _kind_of(path, kind, format, columns)
            files.append(_read_as(path, k, format, columns, hm_kw))
        except Exception as exc:  # noqa: BLE001 - one file's failure, whatever it is
            if on_error == "raise":
                raise
            files.append(InputFile(str(path), k or _guessed_kind(path), error=_message(path, exc)))
    return Inputs(tuple(files))
