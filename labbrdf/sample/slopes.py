"""A sample's facets: its height map read for the tracer, the map's slope table, an alpha's.

- :func:`height_map`: a height-map file read for a tracer run (its geometry doubts passed
  on);
- :func:`pitch` and :func:`areal`: the grid spacing of a map, and a map's heights checked
  areal;
- :func:`roughness_alpha`: the GGX alpha of an areal map (the maximum-likelihood fit of its
  slopes);
- :func:`slope_table`: the measured slope table of an areal map
  (:meth:`labbrdf.Substrate.from_surface`: mean plane removed, 64 slope cells per axis);
- :func:`measured_substrate`: a substrate of index ``n + ik`` whose facets follow a map's
  slopes;
- :func:`analytic_table`: the slope table of an analytic distribution at an alpha (None for
  one the tracer samples in closed form).
"""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..adapters.topography import HeightMap, read_height_map
from ..errors import SampleError, SetupError, escaped
from ..microfacet import DISTRIBUTIONS, TabulatedNDF, ggx
from ..microfacet.interface import table_for
from ..roughness.levelling import level
from ..roughness.slope_fits import SlopeFit, fit_slope_distribution, slopes
from ..tracer.config import Substrate

__all__ = [
    "analytic_table",
    "areal",
    "height_map",
    "measured_substrate",
    "pitch",
    "roughness_alpha",
    "slope_table",
]

PathLike = str | os.PathLike[str]


def height_map(
    source: PathLike | HeightMap,
    keyword: str,
    channel: int | str | None,
    unit: str | None,
    pixel_size: float | tuple[float, ...] | None,
    warn: Callable[[str], None],
) -> HeightMap:
    """``source`` read as a height map (its geometry doubts passed to ``warn``).

    Raises
    ------
    labbrdf.errors.SetupError
        Out of memory while reading (the message names ``keyword`` and the file).
    labbrdf.AdapterError
        The file cannot be read as a height map.
    """
    if isinstance(source, HeightMap):
        return source
    try:
        hm = read_height_map(source, channel, unit=unit, pixel_size=pixel_size)
    except MemoryError:
        raise SetupError(
            f"{{{keyword}}} {escaped(source)}: out of memory while reading the height map"
        ) from None
    for w in hm.warnings:
        warn(f"{source}: {w}")
    return hm


def pitch(hm: HeightMap) -> float | tuple[float, float]:
    """The grid spacing of an areal map [m] (a profile's one pitch as it is)."""
    px = tuple(float(v) for v in hm.pixel_size)
    return (px[0], px[1]) if len(px) == 2 else px[0]


def analytic_table(distribution: str, alpha: float) -> TabulatedNDF | None:
    """The slope table of an analytic distribution at ``alpha`` [1].

    None for GGX, which the tracer samples in closed form; any other registered
    distribution is traced through its slope table
    (``labbrdf.microfacet.interface.table_for``).

    Raises
    ------
    labbrdf.errors.SetupError
        An unknown distribution, or a tabulated one without an alpha > 0.
    """
    if distribution not in DISTRIBUTIONS:
        expected = " or ".join(repr(name) for name in DISTRIBUTIONS)
        raise SetupError(f"{{distribution}} {escaped(repr(distribution))}: expected {expected}")
    dist = DISTRIBUTIONS[distribution]
    if dist is not ggx and not alpha > 0:
        raise SetupError(f"{{distribution}} {dist.NAME} needs a roughness alpha > 0")
    # the walk's one closed form is GGX: any other distribution, closed-form or not, is
    # traced through its slope table, never silently as GGX
    return table_for(distribution, alpha)


def areal(
    heights: Any, pixel_size: float | Sequence[float] | None, what: str
) -> tuple[NDArray, tuple[float, float], str]:
    """Heights [m], pitch per axis [m] and a ``"file: "`` prefix of a map or an array.

    Raises
    ------
    labbrdf.errors.SampleError
        A profile (``what`` needs an areal map) or an array without a pixel size.
    """
    where = ""
    if hasattr(heights, "heights") and hasattr(heights, "pixel_size"):
        where = f"{heights.path}: "
        pixel_size = heights.pixel_size
        heights = heights.heights
    z = np.asarray(heights, dtype=float)
    if z.ndim != 2:
        raise SampleError(f"{where}a line profile; {what} needs an areal height map (2-D)")
    if pixel_size is None:
        raise SampleError("pixel_size is needed for a plain height array")
    px = np.broadcast_to(np.asarray(pixel_size, float), (2,))
    return z, (float(px[0]), float(px[1])), where


def roughness_alpha(
    heights: Any, pixel_size: float | Sequence[float] | None = None, *, degree: int = 1
) -> SlopeFit:
    """GGX roughness of a height map: the maximum-likelihood fit of its slopes.

    Parameters
    ----------
    heights : ndarray (M, N) or HeightMap
        Heights [m] (NaN = missing), or a :class:`labbrdf.adapters.topography.HeightMap`.
    pixel_size : float or (float, float)
        Grid spacing [m] (not needed for a HeightMap).
    degree : int
        Levelling polynomial (1 = mean plane), :func:`labbrdf.roughness.levelling.level`.

    Returns
    -------
    SlopeFit
        ``alpha`` and its uncertainty ``alpha_u`` [1] (the GGX fit of
        :func:`labbrdf.roughness.slope_fits.fit_slope_distribution`, the alpha that
        :meth:`labbrdf.Substrate.from_surface` gives the tracer).

    Raises
    ------
    labbrdf.errors.SampleError
        A profile (a slope distribution of an isotropic surface needs both axes) or a map
        without a pixel size.
    """
    z, px, _ = areal(heights, pixel_size, "the tracer's roughness")
    sx, sy = slopes(level(z, degree), px)
    return fit_slope_distribution(sx, sy).ggx


def slope_table(heights: Any, pixel_size: float | Sequence[float] | None = None) -> TabulatedNDF:
    """The measured slope table of an areal height map (what ``labbrdf trace --surface`` uses).

    :meth:`labbrdf.Substrate.from_surface` (mean plane removed, 64 slope cells per axis).

    Raises
    ------
    labbrdf.errors.SampleError
        A profile, or a map without a pixel size (:func:`areal`).
    """
    z, px, where = areal(heights, pixel_size, "a slope table")
    try:
        ndf = Substrate.from_surface(z, px).ndf
    except ValueError as exc:
        raise SampleError(f"{where}{exc}") from None
    assert ndf is not None
    return ndf


def measured_substrate(hm: HeightMap, index: complex, keyword: str = "surface") -> Substrate:
    """A substrate of index ``n + ik`` [1] whose facets follow the slopes of an areal map.

    :meth:`labbrdf.Substrate.from_surface` on the map's heights and pitch.

    Raises
    ------
    labbrdf.errors.SetupError
        A map the slope table cannot be made of (the message names ``keyword`` and the
        file).
    """
    try:
        return Substrate.from_surface(hm.heights, pitch(hm), n=index.real, k=index.imag)
    except ValueError as exc:
        raise SetupError(f"{{{keyword}}} {escaped(hm.path)}: {escaped(exc)}") from None
