"""Height maps and profiles from instrument files, read through SurfaceTopography.

SurfaceTopography (optional extra ``labbrdf[topography]``) reads the instrument formats
(Zygo MetroPro ``.dat``, Digital Instruments / Nanoscope ``.di``, Bruker ``.opdx``, Gwyddion,
plain XYZ and matrix ASCII, ...); it is imported only when a file is read. Everything is
converted to metres here, so :mod:`labbrdf.topography` never sees a unit.

Plain XYZ (``x y z`` columns on a grid) and matrix ASCII files are also read by
SurfaceTopography; a matrix file carries no lateral size, so ``physical_sizes`` and
``unit`` must then be given.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from labbrdf.adapters._base import AdapterError

__all__ = ["HeightMap", "read_height_map", "topography_statistics"]

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
    """

    heights: NDArray[np.float64]
    pixel_size: tuple[float, ...]
    path: str
    channel: str
    channels: tuple[str, ...] = ()
    meta: dict[str, Any] = field(default_factory=dict)

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


def _json_meta(info: dict[str, Any]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for k, v in info.items():
        if isinstance(v, str | int | float | bool) or v is None:
            out[str(k)] = v
    return out


def read_height_map(
    path: str | os.PathLike[str],
    channel: int | str | None = None,
    *,
    physical_sizes: tuple[float, ...] | None = None,
    unit: str | None = None,
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
        Length unit of heights and sizes, for files that do not carry it.

    Returns
    -------
    HeightMap

    Raises
    ------
    AdapterError
        Missing, unsupported or corrupt file; unknown channel; no lateral size or unit.
    ImportError
        SurfaceTopography is not installed (extra ``labbrdf[topography]``).
    """
    st = _surface_topography()
    p = os.fspath(path)
    if not os.path.isfile(p):
        raise AdapterError(p, "no such file")
    try:
        reader = st.open_topography(p)
    except Exception as exc:  # noqa: BLE001 - the reader's errors vary by format
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise AdapterError(
            p, f"not a topography file SurfaceTopography can read ({first})"
        ) from exc
    chans = list(reader.channels)
    names = tuple(str(c.name) for c in chans)
    if channel is None:
        default = getattr(reader, "default_channel", None)
        index = int(default.index) if default is not None else 0
    elif isinstance(channel, str):
        if channel not in names:
            raise AdapterError(p, f"no channel {channel!r}; channels are {list(names)}")
        index = names.index(channel)
    else:
        if not 0 <= int(channel) < len(chans):
            raise AdapterError(p, f"channel {channel} out of range 0..{len(chans) - 1}")
        index = int(channel)
    kw: dict[str, Any] = {"channel_index": index}
    ch = chans[index]
    if ch.physical_sizes is None:
        if physical_sizes is None:
            raise AdapterError(p, "the file has no lateral size: pass physical_sizes and unit")
        kw["physical_sizes"] = tuple(physical_sizes)
    if ch.unit is None or not isinstance(ch.unit, str):
        if unit is None:
            raise AdapterError(
                p, f"channel {names[index]!r} has no length unit ({ch.unit!r}): pass unit"
            )
        kw["unit"] = unit
    try:
        topo = reader.topography(**kw)
        topo_m = topo.to_unit("m")
        h = topo_m.heights()
        if not getattr(topo_m, "is_uniform", True):
            raise AdapterError(p, "non-uniform line scans are not supported")
        pixel = tuple(float(v) for v in np.atleast_1d(topo_m.pixel_size))
    except AdapterError:
        raise
    except Exception as exc:  # noqa: BLE001
        raise AdapterError(p, f"cannot read the heights ({type(exc).__name__}: {exc})") from exc
    z = np.array(np.ma.getdata(h), dtype=float)
    if np.ma.isMaskedArray(h):
        z[np.ma.getmaskarray(h)] = np.nan
    if not np.isfinite(z).any():
        raise AdapterError(p, "no defined height in the file")
    meta = {"unit_in_file": str(ch.unit), "reader": type(reader).__name__}
    meta.update(_json_meta(dict(getattr(topo, "info", {}) or {})))
    return HeightMap(z, pixel, p, names[index], names, meta)


def topography_statistics(
    path: str | os.PathLike[str],
    channel: int | str | None = None,
    *,
    degree: int = 1,
    blocks: int | None = None,
    require_areal: bool = False,
    **read_kw: Any,
) -> Any:
    """Read a file and compute :func:`labbrdf.topography.roughness_statistics`.

    Parameters
    ----------
    path, channel, read_kw
        As :func:`read_height_map`.
    degree, blocks
        As :func:`labbrdf.topography.roughness_statistics`.
    require_areal : bool
        Raise :class:`AdapterError` for a profile (when an areal map is needed).

    Returns
    -------
    RoughnessStats
    """
    from labbrdf.topography import roughness_statistics

    hm = read_height_map(path, channel, **read_kw)
    if require_areal and hm.is_profile:
        raise AdapterError(hm.path, "is a line profile; an areal height map is needed")
    try:
        return roughness_statistics(hm.heights, hm.pixel_size, degree=degree, blocks=blocks)
    except ValueError as exc:
        raise AdapterError(hm.path, str(exc)) from exc
