"""Height maps and profiles from instrument files, read through SurfaceTopography.

SurfaceTopography (optional extra ``labbrdf[topography]``) reads the instrument formats
(Zygo MetroPro ``.dat``, Digital Instruments / Nanoscope ``.di``, Bruker ``.opdx``, Gwyddion,
plain XYZ and matrix ASCII, ...); it is imported only when a file is read. Everything is
converted to metres here, so :mod:`labbrdf.roughness.topography` never sees a unit.

Which files are height maps is :mod:`labbrdf.adapters.heightmap_formats`' knowledge (offered
here too): :data:`HEIGHT_MAP_FORMATS` lists the extensions only topography instruments write,
the ones shared with optical exports (MetroPro ``.dat``) and the magic bytes that decide for
those (:func:`height_map_format`); :func:`labbrdf.adapters.input_kind` weighs them against
the optical sniffers.

Plain XYZ (``x y z`` columns on a grid) and matrix ASCII files are also read by
SurfaceTopography; a matrix file carries no lateral size, so ``physical_sizes`` (or
``pixel_size``) and ``unit`` must then be given.

Geometry check
--------------
A misread header gives a map whose numbers are wrong by orders of magnitude yet still
produce statistics (a pitch of 4.9e-39 m from a corrupt header; a confocal map whose
312.5 nm pitch is read as 0.3125 m, so every slope is a million times too small). Before
anything is computed :func:`check_geometry` refuses a grid that no areal or profiling
instrument records -- a pitch outside :data:`PITCH_RANGE_M`, a lateral size beyond
:data:`MAX_EXTENT_M`, pixels more than :data:`MAX_PIXEL_ASPECT` times longer along one
axis than the other -- and warns when the pitch and the height scale disagree: an RMS
forward-difference slope above :data:`MAX_SLOPE_RMS` (steeper than any instrument
measures) or below :data:`MIN_SLOPE_RMS` (a pitch too large for the heights). The user
states the true geometry with ``pixel_size`` and ``unit`` (CLI ``--pixel-size``,
``--unit``).

Non-uniform line scans (stylus profilometer exports with irregular x) are interpolated
linearly onto a uniform grid at their finest spacing by SurfaceTopography's ``to_uniform``
(every statistic here needs a uniform grid; a coarser step would lose slope); the
warnings say so.
"""

from __future__ import annotations

import functools
import os
import re
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from labbrdf.adapters._base import AdapterError
from labbrdf.adapters.heightmap_formats import (
    HEIGHT_MAP_FORMATS,
    HeightMapFormat,
    height_map_format,
)

__all__ = [
    "HEIGHT_MAP_FORMATS",
    "MAX_EXTENT_M",
    "MAX_PIXEL_ASPECT",
    "MAX_SLOPE_RMS",
    "MIN_SLOPE_RMS",
    "PITCH_RANGE_M",
    "HeightMap",
    "HeightMapFormat",
    "check_geometry",
    "height_map_format",
    "length_m",
    "nanoscope_scale_warnings",
    "read_height_map",
    "topography_statistics",
]

#: Plausible lateral pitch of a topography instrument [m]: 10 pm (below any AFM pixel) to
#: 1 mm (a coarse large-aperture interferometer or a stylus trace sampled sparsely).
PITCH_RANGE_M = (1e-11, 1e-3)
#: Largest plausible lateral size of one map or profile [m].
MAX_EXTENT_M = 1.0
#: Largest plausible ratio of the pitches along the two axes of a map [1].
MAX_PIXEL_ASPECT = 100.0
#: RMS forward-difference slope above which the pitch is too small for the heights [1]
#: (tan 84 deg: no optical or stylus instrument follows steeper slopes).
MAX_SLOPE_RMS = 10.0
#: RMS forward-difference slope below which the pitch is too large for the heights [1]
#: (a super-polished mirror, 0.1 nm over a 100 um correlation, still has 1e-6).
MIN_SLOPE_RMS = 1e-7

_UNITS_M = {
    "m": 1.0,
    "mm": 1e-3,
    "um": 1e-6,
    "µm": 1e-6,
    "μm": 1e-6,
    "nm": 1e-9,
    "pm": 1e-12,
    "A": 1e-10,
    "Å": 1e-10,
}


def _surface_topography() -> Any:
    try:
        import SurfaceTopography
    except ImportError as exc:  # pragma: no cover - depends on the environment
        raise ImportError(
            "reading topography files needs SurfaceTopography: pip install 'labbrdf[topography]'"
        ) from exc
    return SurfaceTopography


@dataclass(frozen=True)
class HeightMap:
    """A height map or profile in metres.

    Attributes
    ----------
    heights : ndarray, shape (M, N) or (M,)
        Heights [m]; NaN at undefined points. ``heights[i, j]`` is at ``(i dx, j dy)``.
    pixel_size : tuple of float
        Grid spacing per axis [m].
    path : str
        The file.
    channel : str
        Channel name in the file.
    channels : tuple of str
        All channel names of the file.
    meta : dict
        Whatever else the reader reported (JSON-safe subset).
    warnings : tuple of str
        Doubts about the geometry (:func:`check_geometry`) or the reading (interpolation
        of a non-uniform line scan).
    points : (ndarray, ndarray) or None
        A non-uniform line scan's measured positions and heights [m], as in the file
        (``heights`` is then their interpolation onto a uniform grid); None otherwise.
        :func:`labbrdf.roughness.topography.on_measured_points` computes sigma and the RMS slope
        on them.
    """

    heights: NDArray[np.float64]
    pixel_size: tuple[float, ...]
    path: str
    channel: str
    channels: tuple[str, ...] = ()
    meta: dict[str, Any] = field(default_factory=dict)
    warnings: tuple[str, ...] = ()
    points: tuple[NDArray[np.float64], NDArray[np.float64]] | None = None

    @property
    def mask(self) -> NDArray[np.bool_]:
        """True where a point is undefined."""
        return ~np.isfinite(self.heights)

    @property
    def is_profile(self) -> bool:
        """True for a line profile (1-D heights)."""
        return self.heights.ndim == 1

    @property
    def physical_sizes(self) -> tuple[float, ...]:
        """Extent per axis [m] (points x spacing, SurfaceTopography's convention)."""
        return tuple(n * p for n, p in zip(self.heights.shape, self.pixel_size, strict=True))

    def summary(self) -> dict[str, Any]:
        """What the map holds, JSON-safe: kind, reader, channel, points, size, pitch, warnings."""
        return {
            "kind": "profile" if self.is_profile else "areal map",
            "reader": self.meta.get("reader", ""),
            "channel": self.channel,
            "points": list(self.heights.shape),
            "size_um": [s * 1e6 for s in self.physical_sizes],
            "pixel_nm": [s * 1e9 for s in self.pixel_size],
            "missing": int(self.mask.sum()),
            "warnings": list(self.warnings),
        }

    def summary_line(self) -> str:
        """One line: ``areal map, 512 x 512 points, 10 x 10 um, pixel 19.53 nm, ...``.

        The reading's warnings (:attr:`warnings`) follow, each as ``; warning: ...``.
        """
        s = self.summary()
        size = " x ".join(f"{v:.4g}" for v in s["size_um"])
        pixel = " x ".join(f"{v:.4g}" for v in s["pixel_nm"])
        return (
            f"{s['kind']}, {' x '.join(map(str, s['points']))} points, {size} um, pixel "
            f"{pixel} nm, channel {s['channel']}, {s['missing']} missing points"
            f" ({s['reader']})" + "".join(f"; warning: {w}" for w in self.warnings)
        )


def _json_meta(info: dict[str, Any]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for k, v in info.items():
        if isinstance(v, str | int | float | bool) or v is None:
            out[str(k)] = v
    return out


def length_m(text: str | float, unit: str | None = None) -> float:
    """A length like ``"312.5nm"``, ``"2 um"`` or ``0.5`` (in ``unit``, default m) in metres.

    Parameters
    ----------
    text : str or float
        Number with an optional unit suffix (m, mm, um, µm, nm, pm, A).
    unit : str, optional
        Unit of a bare number (default metres).

    Returns
    -------
    float
        The length [m], positive and finite.

    Raises
    ------
    ValueError
        Not a positive finite length, or an unknown unit.
    """
    t = str(text).strip()
    num = t.rstrip("".join(sorted({c for u in _UNITS_M for c in u}))).strip()
    suffix = t[len(num) :].strip() or unit or "m"
    if suffix not in _UNITS_M:
        raise ValueError(f"length {text!r}: unknown unit {suffix!r}; use one of {list(_UNITS_M)}")
    try:
        v = float(num) * _UNITS_M[suffix]
    except ValueError:
        raise ValueError(f"length {text!r}: expected a number with a unit, e.g. 312.5nm") from None
    if not (np.isfinite(v) and v > 0):
        raise ValueError(f"length {text!r}: must be positive and finite")
    return v


def check_geometry(
    path: str, heights: NDArray[np.float64], pixel_size: tuple[float, ...]
) -> tuple[str, ...]:
    """Refuse implausible grids; return warnings when pitch and heights disagree.

    Parameters
    ----------
    path : str
        The file (for the messages).
    heights : ndarray
        Heights [m], NaN at undefined points.
    pixel_size : tuple of float
        Pitch per axis [m].

    Returns
    -------
    tuple of str
        Warnings naming the numbers (empty when the geometry is plausible).

    Raises
    ------
    AdapterError
        Non-finite or non-positive pitch, a pitch outside :data:`PITCH_RANGE_M`, a lateral
        size beyond :data:`MAX_EXTENT_M` or pixels more than :data:`MAX_PIXEL_ASPECT` times
        longer along one axis; the message says how to state the true geometry.
    """
    fix = "if the file is right, state the geometry with --pixel-size / --unit"
    px = np.asarray(pixel_size, dtype=float)
    if not np.all(np.isfinite(px)) or np.any(px <= 0):
        raise AdapterError(path, f"pixel size {tuple(px.tolist())} m is not positive and finite")
    lo, hi = PITCH_RANGE_M
    if np.any(px < lo) or np.any(px > hi):
        raise AdapterError(
            path,
            f"pixel size {', '.join(f'{v:.4g}' for v in px)} m is outside the {lo:g}..{hi:g} m"
            f" of topography instruments: a misread header? ({fix})",
        )
    ext = np.asarray(heights.shape, dtype=float) * px
    if np.any(ext > MAX_EXTENT_M):
        size = " x ".join(f"{v:.4g}" for v in ext)
        grid = " x ".join(map(str, heights.shape))
        raise AdapterError(
            path,
            f"lateral size {size} m ({grid} points) exceeds {MAX_EXTENT_M:g} m:"
            f" a misread header? ({fix})",
        )
    if px.size == 2 and max(px) / min(px) > MAX_PIXEL_ASPECT:
        raise AdapterError(
            path,
            f"pixels {px[0]:.4g} m x {px[1]:.4g} m differ by more than {MAX_PIXEL_ASPECT:g}"
            f" times between the axes: a misread header? ({fix})",
        )
    warnings = []
    z = heights
    if z.ndim == 1:
        d = np.diff(z) / px[0]
    else:
        d = (z[1:, :] - z[:-1, :]) / px[0]
    d = d[np.isfinite(d)]
    if d.size:
        srms = float(np.sqrt(np.mean(d * d)))
        if srms > MAX_SLOPE_RMS or 0 < srms < MIN_SLOPE_RMS:
            warnings.append(
                f"RMS slope along x {srms:.3g} at a pixel size of {px[0]:.4g} m is outside"
                f" {MIN_SLOPE_RMS:g}..{MAX_SLOPE_RMS:g}: pixel size or height unit is likely"
                f" misread ({fix})"
            )
    return tuple(warnings)


#: Extensions SurfaceTopography's readers do not list although the instrument writes them.
_EXT_FORMAT = {"di": "di"}
#: SurfaceTopography's plain-text formats: a file with their extensions (.txt, .csv, .asc)
#: may be any of them, so detection decides, not the extension.
_TEXT_FORMATS = frozenset({"asc", "xyz"})


def _extension_readers(st: Any, p: str) -> list[Any]:
    """SurfaceTopography's readers whose file extensions include that of ``p``."""
    ext = os.path.splitext(p)[1].lstrip(".").lower()
    out = []
    for r in getattr(st.IO, "readers", ()):
        try:
            exts = [e.lower() for e in (r.file_extensions() or ())]
            fmt = r.format()
        except Exception:  # noqa: BLE001 - a reader without extensions
            continue
        if ext and (ext in exts or _EXT_FORMAT.get(ext) == fmt):
            out.append(r)
    return out


def _try_open(open_reader: Callable[[], Any]) -> tuple[Any, str, BaseException | None]:
    """Open a reader and list its channels, whatever it raises (but MemoryError).

    ``(reader, "", None)`` for a reader that opens and lists a channel, else
    ``(None, why, error)``.
    """
    try:
        reader = open_reader()
    except MemoryError:
        raise
    except Exception as exc:  # noqa: BLE001 - the readers' errors vary by format
        return None, _one_line(exc), exc
    name = type(reader).__name__
    try:
        chans = list(reader.channels)
    except MemoryError:
        raise
    except Exception as exc:  # noqa: BLE001
        return None, f"{name} cannot list the channels: {_one_line(exc)}", exc
    if not chans:
        return None, f"{name} found no data channel in the file", None
    return reader, "", None


def _open(st: Any, p: str) -> Any:
    """The reader of ``p``, with at least one channel.

    A file whose extension only one reader lists (``.nms``, ``.opdx``, ``.di``) is opened
    with that reader first: formats without magic bytes (Nanofocus ``.nms``) are otherwise
    claimed by whichever reader detection tries first (a MATLAB v4 reader that finds no
    matrix in a confocal map's header); when it refuses the file, its error is the answer,
    except for plain text (:data:`_TEXT_FORMATS`, which several readers take), where
    SurfaceTopography's detection follows. On failure, the error of the reader the
    extension names, else what detection tried.
    """
    named = _extension_readers(st, p)
    if len(named) == 1:
        fmt = named[0].format()
        reader, why, err = _try_open(lambda: st.open_topography(p, format=fmt))
        if reader is not None:
            return reader
        if fmt not in _TEXT_FORMATS:
            raise AdapterError(
                p, f"not a {fmt} file SurfaceTopography can read (as {fmt}: {why})"
            ) from err
    reader, why, err = _try_open(lambda: st.open_topography(p))
    if reader is not None:
        return reader
    raise AdapterError(
        p,
        "not a topography file SurfaceTopography can read"
        f" ({_cause(p, named, str(err) if err is not None and str(err).strip() else why)})",
    ) from err


def _cause(p: str, named: list[Any], detect: str) -> str:
    """Why no reader could read ``p``.

    The errors of the readers its extension names, or what detection tried (``detect``,
    SurfaceTopography's list of tries).
    """
    causes = []
    for r in named:
        reader, why, _ = _try_open(functools.partial(r, p))
        if reader is None:
            causes.append(f"as {r.format()}: {why}")
    if causes:
        return "; ".join(causes)
    tried = [ln for ln in detect.splitlines() if ln.strip()]
    causes = [
        f"{a.strip().removeprefix('tried ').rstrip(': ')}: {b.strip()}"
        for a, b in zip(tried[::2], tried[1::2], strict=False)
        if a.strip().startswith("tried")
    ]
    return "; ".join(causes[:4]) or " ".join(detect.split())


def _one_line(exc: BaseException) -> str:
    text = " ".join(str(exc).split())
    return f"{type(exc).__name__}: {text}" if text else type(exc).__name__


def read_height_map(
    path: str | os.PathLike[str],
    channel: int | str | None = None,
    *,
    physical_sizes: tuple[float, ...] | None = None,
    unit: str | None = None,
    pixel_size: float | tuple[float, ...] | None = None,
) -> HeightMap:
    """Read one height channel of a topography file, in metres.

    Parameters
    ----------
    path : path-like
        The file (any format SurfaceTopography reads).
    channel : int or str, optional
        Channel index or name; default the reader's default channel (the first height).
    physical_sizes : tuple of float, optional
        Lateral size per axis in ``unit``, for files that do not carry it (matrix ASCII).
    unit : str, optional
        Length unit of the numbers in the file (heights, and sizes unless ``pixel_size``
        is given); replaces the file's own unit when it has one.
    pixel_size : float or tuple of float, optional
        Pitch per axis [m]; replaces the file's lateral calibration (a header that states
        it wrongly), or gives it when the file has none.

    Returns
    -------
    HeightMap
        ``warnings`` holds the doubts of :func:`check_geometry`.

    Raises
    ------
    AdapterError
        Missing, unsupported or corrupt file; unknown channel; no lateral size or unit;
        implausible geometry (:func:`check_geometry`).
    ImportError
        SurfaceTopography is not installed (extra ``labbrdf[topography]``).
    """
    st = _surface_topography()
    p = os.fspath(path)
    if not os.path.isfile(p):
        raise AdapterError(p, "no such file")
    if unit is not None and unit not in _UNITS_M:
        raise AdapterError(p, f"unit {unit!r} unknown; use one of {list(_UNITS_M)}")
    reader = _open(st, p)
    with _reader_errors(p, reader):
        chans = list(reader.channels)
        names = tuple(str(c.name) for c in chans)
        index = _channel_index(p, reader, names, channel)
        ch = chans[index]
        kw = _topography_kwargs(p, ch, names[index], index, physical_sizes, unit, pixel_size)
        z, pixel, topo, warnings, points = _heights_m(p, reader, kw, unit)
        unit_in_file = str(ch.unit)
        info = dict(getattr(topo, "info", {}) or {})
    if pixel_size is not None:
        pixel = tuple(float(v) for v in np.broadcast_to(np.asarray(pixel_size, float), (z.ndim,)))
    if not np.isfinite(z).any():
        raise AdapterError(p, "no defined height in the file")
    if type(reader).__name__ == "DIReader":
        warnings.extend(nanoscope_scale_warnings(p, index))
    warnings[:0] = check_geometry(p, z, pixel)
    meta: dict[str, Any] = {"unit_in_file": unit_in_file, "reader": type(reader).__name__}
    if unit is not None:
        meta["unit_stated"] = unit
    if pixel_size is not None:
        meta["pixel_size_stated_m"] = list(pixel)
    meta.update(_json_meta(info))
    if pixel_size is not None:
        points = None  # the stated pitch replaces the file's positions
    return HeightMap(z, pixel, p, names[index], names, meta, tuple(warnings), points)


@contextmanager
def _reader_errors(p: str, reader: Any) -> Iterator[None]:
    """Any error of SurfaceTopography's reader as an :class:`AdapterError`.

    The message names the file and the reader (the errors vary by format: IndexError,
    KeyError, struct.error, ...).
    """
    try:
        yield
    except (AdapterError, MemoryError):
        raise
    except Exception as exc:  # noqa: BLE001 - whatever the reader raises
        raise AdapterError(
            p, f"SurfaceTopography's {type(reader).__name__} cannot read it ({_one_line(exc)})"
        ) from exc


#: Most header bytes read for :func:`nanoscope_scale_warnings` (headers are 8-80 KiB).
_DI_HEADER_MAX = 1 << 20
_DI_Z_SCALE = re.compile(r"^\\@([24]):Z scale:.*?(-?[0-9.]+(?:[eE][-+]?[0-9]+)?)\s*(\S*)\s*$")


def nanoscope_scale_warnings(path: str, index: int) -> tuple[str, ...]:
    """Doubts about the Z scale of image ``index`` of a Nanoscope file.

    A Nanoscope header states the Z scale of an image as ``@2:Z scale`` and, from
    version 9 on, also as ``@4:Z scale``; SurfaceTopography uses the ``@4`` one when both
    are there. When the two disagree, the file contradicts itself about the heights: the
    warning names both values, their ratio, and the one used.

    Parameters
    ----------
    path : str
        The file.
    index : int
        The image (channel) index, in the order of the header's image lists.

    Returns
    -------
    tuple of str
        One warning, or none.
    """
    with open(path, "rb") as f:
        head = f.read(_DI_HEADER_MAX).decode("latin-1")
    head = head.split("\\*File list end", 1)[0]
    images = head.split("\\*Ciao image list")[1:]
    if not 0 <= index < len(images):
        return ()
    found: dict[str, tuple[float, str, str]] = {}
    for line in images[index].splitlines():
        m = _DI_Z_SCALE.match(line.strip())
        if m and m.group(1) not in found:
            found[m.group(1)] = (float(m.group(2)), m.group(3), line.strip())
    if "2" not in found or "4" not in found:
        return ()
    (v4, u4, l4), (v2, u2, l2) = found["4"], found["2"]
    if v4 == v2 and u4 == u2:
        return ()
    ratio = f" ({v4 / v2:.4g} times)" if v2 and u4 == u2 else ""
    return (
        f"the file states two Z scales for image {index}: '{l4}' and '{l2}'{ratio}; the"
        " heights use the @4:Z scale (SurfaceTopography's choice): the file disagrees with"
        " itself, check the heights against a known step",
    )


def _channel_index(p: str, reader: Any, names: tuple[str, ...], channel: int | str | None) -> int:
    """Index of the asked channel (by index or name), or of the reader's default one."""
    if channel is None:
        default = getattr(reader, "default_channel", None)
        return int(default.index) if default is not None else 0
    if isinstance(channel, str):
        if channel not in names:
            raise AdapterError(p, f"no channel {channel!r}; channels are {list(names)}")
        return names.index(channel)
    if not 0 <= int(channel) < len(names):
        raise AdapterError(p, f"channel {channel} out of range 0..{len(names) - 1}")
    return int(channel)


def _topography_kwargs(
    p: str,
    ch: Any,
    name: str,
    index: int,
    physical_sizes: tuple[float, ...] | None,
    unit: str | None,
    pixel_size: float | tuple[float, ...] | None,
) -> dict[str, Any]:
    """The reader's ``topography()`` keywords: the channel, and what the file lacks.

    The lateral size (from ``physical_sizes`` or ``pixel_size``) and the unit.
    """
    kw: dict[str, Any] = {"channel_index": index}
    if ch.physical_sizes is None:
        if physical_sizes is not None:
            kw["physical_sizes"] = tuple(physical_sizes)
        elif pixel_size is not None:
            grid = tuple(int(n) for n in ch.nb_grid_pts)
            pxm = np.broadcast_to(np.asarray(pixel_size, dtype=float), (len(grid),))
            su = unit if unit is not None else ch.unit
            scale = _UNITS_M.get(su, 1.0) if isinstance(su, str) else 1.0
            kw["physical_sizes"] = tuple(
                float(n * v / scale) for n, v in zip(grid, pxm, strict=True)
            )
        else:
            raise AdapterError(
                p,
                "the file has no lateral size: give it with --pixel-size"
                " (Python: pixel_size= or physical_sizes=)",
            )
    if not isinstance(ch.unit, str):
        if unit is None:
            raise AdapterError(
                p,
                f"channel {name!r} has no length unit ({ch.unit!r}): give it with"
                " --unit (Python: unit=)",
            )
        kw["unit"] = unit
    return kw


#: Most points of a non-uniform line scan put on a uniform grid (32 MiB of float64
#: heights): the grid's step is the scan's finest spacing unless that needs more.
MAX_PROFILE_POINTS = 2**22


def _uniform(p: str, topo: Any, warnings: list[str]) -> Any:
    """A non-uniform line scan interpolated onto its finest spacing (said in ``warnings``).

    Linear interpolation at a step no coarser than any measured spacing keeps every
    segment between measured points: the RMS height and slope of the grid are those of
    the measured points (SurfaceTopography's piecewise-linear ``rms_height_from_profile``,
    ``rms_slope_from_profile``) up to the grid steps that straddle a measured point. A
    coarser step (the median) would smooth the short segments and lose slope.
    """
    if getattr(topo, "is_uniform", True):
        return topo
    x = np.asarray(topo.positions(), dtype=float)
    dx = np.diff(x)
    if not (dx.size and np.all(dx > 0)):
        raise AdapterError(p, "the line scan's x positions do not increase")
    length = float(x[-1] - x[0])
    step = float(np.min(dx))
    how = "its finest spacing"
    if length / step + 1 > MAX_PROFILE_POINTS:
        step = length / (MAX_PROFILE_POINTS - 1)
        how = f"a step coarser than its finest spacing (at most {MAX_PROFILE_POINTS} points)"
    n_in = x.size
    topo = topo.to_uniform(pixel_size=step)
    warnings.append(
        f"non-uniform line scan ({n_in} points, spacing {np.min(dx):.4g}"
        f"..{np.max(dx):.4g} {topo.unit}) interpolated linearly onto"
        f" {topo.nb_grid_pts[0]} points at {how}, {step:.4g} {topo.unit}"
    )
    return topo


def _heights_m(
    p: str, reader: Any, kw: dict[str, Any], unit: str | None
) -> tuple[NDArray[np.float64], tuple[float, ...], Any, list[str], Any]:
    """Heights [m] and pitch [m] of the channel the keywords ``kw`` select.

    Returns (heights with NaN where undefined, pitch, the topography, warnings, the
    measured (x, heights) [m] of a non-uniform line scan or None).
    """
    warnings: list[str] = []
    points = None
    try:
        raw = reader.topography(**kw)
        topo = _uniform(p, raw, warnings)
        tunit = unit if unit is not None else topo.unit
        if tunit in _UNITS_M:
            scale = _UNITS_M[tunit]
            h = topo.heights()
            pixel = tuple(float(v) * scale for v in np.atleast_1d(topo.pixel_size))
            if topo is not raw:
                x, hx = raw.positions_and_heights()
                points = (np.asarray(x, float) * scale, np.asarray(hx, float) * scale)
        else:
            topo_m = topo.to_unit("m")
            scale = 1.0
            h = topo_m.heights()
            pixel = tuple(float(v) for v in np.atleast_1d(topo_m.pixel_size))
    except AdapterError:
        raise
    except Exception as exc:  # noqa: BLE001
        raise AdapterError(
            p, f"{type(reader).__name__} cannot read the heights ({_one_line(exc)})"
        ) from exc
    z = np.array(np.ma.getdata(h), dtype=float)
    if scale != 1.0:
        z *= scale
    if np.ma.isMaskedArray(h):
        z[np.ma.getmaskarray(h)] = np.nan
    return z, pixel, topo, warnings, points


def topography_statistics(
    path: str | os.PathLike[str],
    channel: int | str | None = None,
    *,
    degree: int = 1,
    blocks: int | None = None,
    require_areal: bool = False,
    **read_kw: Any,
) -> Any:
    """Read a file and compute :func:`labbrdf.roughness.topography.roughness_statistics`.

    Parameters
    ----------
    path, channel, read_kw
        As :func:`read_height_map`.
    degree, blocks
        As :func:`labbrdf.roughness.topography.roughness_statistics`.
    require_areal : bool
        Raise :class:`AdapterError` for a profile (when an areal map is needed).

    Returns
    -------
    RoughnessStats
    """
    from labbrdf.roughness.topography import on_measured_points, roughness_statistics

    hm = read_height_map(path, channel, **read_kw)
    if require_areal and hm.is_profile:
        raise AdapterError(hm.path, "is a line profile; an areal height map is needed")
    try:
        st = roughness_statistics(hm.heights, hm.pixel_size, degree=degree, blocks=blocks)
        return on_measured_points(st, hm.points, degree)
    except ValueError as exc:
        raise AdapterError(hm.path, str(exc)) from exc
