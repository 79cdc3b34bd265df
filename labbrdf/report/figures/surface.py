"""A measured surface: its height map (or profile), autocorrelation and slope distribution."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import matplotlib.pyplot as plt
import numpy as np

from ..._plotting import legend_below
from ...figstyle import PAGE_WIDTH_IN, styled
from ._common import finish_grid

__all__ = ["height_map_image", "surface_figure"]


def height_map_image(heights_m: Any, pixel_size_m: Sequence[float]) -> tuple[Any, list[float]]:
    """Image and extent [um] that show a map as the instrument and Gwyddion do.

    Parameters
    ----------
    heights_m : ndarray (M, N)
        ``heights[i, j]`` at ``(x, y) = (i dx, j dy)`` (SurfaceTopography's order).
    pixel_size_m : sequence of float
        (dx, dy) [m].

    Returns
    -------
    image : ndarray (N, M)
        ``image[j, i] = heights[i, j]``: x along the columns (horizontal), y along the rows.
    extent : list of float
        ``[0, L_x, L_y, 0]`` [um] for ``imshow(..., origin="upper")``: the origin at the
        top left and y growing downwards, as Gwyddion draws a map.
    """
    z = np.asarray(heights_m)
    dx, dy = (float(p) for p in pixel_size_m)
    return z.T, [0.0, z.shape[0] * dx * 1e6, z.shape[1] * dy * 1e6, 0.0]


@styled
def surface_figure(
    heights_m: Any, pixel_size_m: Sequence[float], stats: Any, title: str = ""
) -> str:
    """Height map (or profile), autocorrelation and slope histogram of a measured surface.

    Parameters
    ----------
    heights_m : ndarray (M, N) or (M,)
        Levelled heights [m] (NaN = missing).
    pixel_size_m : sequence of float
        Grid spacing per axis [m].
    stats : labbrdf.roughness.topography.RoughnessStats
        Its correlation lengths and slope fits are drawn.
    title : str
        Figure title.

    Returns
    -------
    str
        PNG data URI.

    Notes
    -----
    The colour scale of a map spans the 0.5 to 99.5 percentiles of the heights (arrows on
    the colour bar: values beyond). The slope panel of an areal map shows the slope
    magnitude ``q = |grad z|`` against the
    densities of the fitted 2-D slope distributions in q: GGX ``2 q / (a^2 (1 + q^2/a^2)^2)``
    and Beckmann ``2 q / a^2 exp(-q^2/a^2)`` (the slope-space densities times ``2 pi q``). A
    profile shows dz/dx against the 1-D densities of its fits, GGX
    ``1 / (2 a (1 + x^2/a^2)^(3/2))`` and Beckmann ``exp(-x^2/a^2) / (a sqrt(pi))``.
    """
    from labbrdf.microfacet import DISTRIBUTIONS
    from labbrdf.roughness.topography import autocorrelation, slopes

    z = np.asarray(heights_m, float)
    px = tuple(float(p) for p in pixel_size_m)
    valid = np.isfinite(z)
    fig, axes = plt.subplots(1, 3, figsize=(PAGE_WIDTH_IN, 4.2))
    ax = axes[0]
    if z.ndim == 2:
        img, ext = height_map_image(z, px)
        # colour range of the central 99 % of the heights: a few spikes would flatten it
        lo_nm, hi_nm = (float(v) * 1e9 for v in np.nanpercentile(z, [0.5, 99.5]))
        im = ax.imshow(
            img * 1e9,
            extent=ext,
            origin="upper",
            cmap="viridis",
            aspect="equal",
            vmin=lo_nm,
            vmax=hi_nm,
        )
        fig.colorbar(im, ax=ax, label="height [nm]", extend="both")
        ax.set_xlabel("x [\u00b5m]")
        ax.set_ylabel("y [\u00b5m]")
        ax.set_title("levelled height map")
    else:
        ax.plot(np.arange(z.size) * px[0] * 1e6, z * 1e9, lw=0.7)
        ax.set_xlabel("x [\u00b5m]")
        ax.set_ylabel("height [nm]")
        ax.set_title("levelled profile")
    ax = axes[1]
    r = autocorrelation(z, valid)  # zero lag at the centre
    if r.ndim == 2:
        i0, j0 = (n // 2 for n in r.shape)
        rx, ry = r[i0:, j0], r[i0, j0:]
        ax.plot(np.arange(rx.size) * px[0] * 1e6, rx, label="along x")
        ax.plot(np.arange(ry.size) * px[1] * 1e6, ry, label="along y")
    else:
        r1 = r[r.size // 2 :]
        ax.plot(np.arange(r1.size) * px[0] * 1e6, r1, label="along x")
    ax.axhline(np.exp(-1.0), color="0.5", ls=":", lw=1, label="1/e")
    ax.set_xlabel("lag [\u00b5m]")
    ax.set_ylabel("normalised ACF [1]")
    c_txt = f"{stats.c * 1e6:.3g} \u00b5m" if np.isfinite(stats.c) else "undefined"
    ax.set_title(f"autocorrelation (c = {c_txt})")
    legend_below(ax)
    ax = axes[2]
    sx, sy = slopes(z, px, valid)
    areal = sy is not None
    q = np.hypot(sx, sy) if sy is not None else sx
    fits = stats.slope_fits
    if q.size:
        hi = float(np.quantile(np.abs(q), 0.995)) or 1.0
        lo = 0.0 if areal else -hi
        ax.hist(q, bins=60, range=(lo, hi), density=True, color="0.75", label="measured")
        x = np.linspace(lo, hi, 400)
        for i, fit in enumerate(fits.fits.values()):
            style = ("-", "--", ":", "-.")[i % 4]
            a = fit.alpha
            if not (np.isfinite(a) and a > 0):
                continue
            dist = DISTRIBUTIONS[fit.model]
            # the density of the slope magnitude |grad z| for the 2-D fit, the 1-D marginal
            # density for the fit to a profile
            d = dist.radial_density(x, a) if areal else dist.p2(x, a)
            ax.plot(x, d, style, label=f"{fit.model} \u03b1 = {a:.3g} (KS {fit.ks:.2f})")
    ax.set_xlabel("slope magnitude |grad z| [1]" if areal else "slope dz/dx [1]")
    ax.set_ylabel("probability density [1]")
    ax.set_title("slope distribution")
    legend_below(ax)
    return finish_grid(fig, title)
