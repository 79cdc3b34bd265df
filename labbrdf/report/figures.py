"""Figures of the report: matplotlib (Agg backend), returned as base64 PNG data URIs.

Every function takes plain arrays and labels (never file text into code paths other than
labels, which matplotlib draws as text), labels its axes with units, and returns a
``data:image/png;base64,...`` string. Figures are closed after rendering.
"""

from __future__ import annotations

import base64
import io
from collections.abc import Mapping, Sequence
from typing import Any

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

from .._brdf_maps import (  # noqa: E402
    draw_brdf_maps,
    draw_disc,
    is_half,
    map_panels,
    maps_size,
    triangulate,
)
from .._plotting import COLOURS as _COLOURS  # noqa: E402
from .._plotting import MARKERS as _MARKERS  # noqa: E402
from .._plotting import (  # noqa: E402
    draw_panel,
    draw_polar_maps,
    draw_scan,
    legend_below,
    legend_outside,
    polar_maps_size,
)
from .._plotting import text as _text  # noqa: E402
from ..figstyle import DPI, PAGE_WIDTH_IN, PANEL_MIN_IN, grid_shape, styled  # noqa: E402

__all__ = [
    "save_trace_maps_png",
    "compare_models_figure",
    "hemispherical_figure",
    "polar_maps_figure",
    "reflectance_comparison_figure",
    "scan_figure",
    "spectra_figure",
    "spectrum_figure",
    "to_uri",
    "xy_figure",
]


def to_uri(fig: Figure, dpi: int = DPI) -> str:
    """Render ``fig`` to PNG and return it as a data URI; the figure is closed."""
    buf = io.BytesIO()
    try:
        fig.savefig(buf, format="png", dpi=dpi, bbox_inches="tight")
    finally:
        plt.close(fig)
    return "data:image/png;base64," + base64.b64encode(buf.getvalue()).decode("ascii")


def _layout(fig: Any, title: str | None) -> None:
    """The figure's title (if any) in a band of its own above the tight layout."""
    if not title:
        fig.tight_layout()
        return
    fig.suptitle(_text(title))
    fig.tight_layout(rect=(0.0, 0.0, 1.0, 1.0 - 0.32 / fig.get_size_inches()[1]))


def _finish(fig: Any, ax: Any, title: str | None) -> str:
    """Grid, title and the legend below the axes, then the figure as a PNG data URI."""
    ax.grid(alpha=0.3)
    if title:
        ax.set_title(_text(title))
    fig.tight_layout()
    legend_outside(ax, ncol=2)
    return to_uri(fig)


def _finish_below(fig: Any, ax: Any, title: str | None) -> str:
    """Title, tight layout and the legend of ``ax`` below the figure, as a PNG data URI."""
    _layout(fig, title)
    legend_outside(ax)
    return to_uri(fig)


def _finish_grid(fig: Any, title: str | None) -> str:
    """Figure title (if any), tight layout, then the figure as a PNG data URI."""
    _layout(fig, title)
    return to_uri(fig)


@styled
def scan_figure(panels: Sequence[Mapping[str, Any]], title: str = "") -> str:
    """Measured points and model curves per incidence angle, with residuals (Figs. 2-3 style).

    Parameters
    ----------
    panels : sequence of mappings
        One per wavelength: ``{"label": str, "series": [{"theta_i": float,
        "theta_r": array [deg], "value": array [sr^-1], "sigma": array or None,
        "curve_theta_r": array [deg], "curves": {model_name: array [sr^-1]},
        "residual": {model_name: array [%]}}]}``.
    title : str
        Figure title.

    Returns
    -------
    str
        PNG data URI.
    """
    n = max(1, len(panels))
    nrow, ncol, w = grid_shape(n, 4, min(PAGE_WIDTH_IN / min(n, 4), 6.5))
    fig, axes = plt.subplots(
        2 * nrow,
        ncol,
        figsize=(ncol * w, 5.2 * nrow),
        squeeze=False,
        gridspec_kw={"height_ratios": [3, 1.4] * nrow},
    )
    scales: dict[int, Any] = {}
    for j in range(nrow * ncol):
        ax, axr = axes[2 * (j // ncol), j % ncol], axes[2 * (j // ncol) + 1, j % ncol]
        if j >= len(panels):
            ax.set_visible(False)
            axr.set_visible(False)
            continue
        panel = panels[j]
        scales[j] = draw_scan(ax, axr, panel["series"])
        ax.set_title(_text(panel["label"]))
        if j % ncol == 0:
            ax.set_ylabel(r"BRDF [sr$^{-1}$]")
            axr.set_ylabel("residual [%]")
    _layout(fig, title)
    _scan_legend(fig, axes, scales)
    return to_uri(fig)


def _scan_legend(fig: Any, axes: Any, scales: Mapping[int, Any]) -> None:
    """One legend below the figure; the incidence angle's colour bar beside each panel.

    Only panels whose scans are coloured by the angle (:func:`labbrdf._plotting.draw_scan`)
    get one.
    """
    ncol = axes.shape[1]
    for j, scale in scales.items():
        if scale is not None:
            pair = [axes[2 * (j // ncol), j % ncol], axes[2 * (j // ncol) + 1, j % ncol]]
            fig.colorbar(scale, ax=pair, pad=0.02).set_label(r"$\theta_i$ [deg]")
    legend_outside(axes[0, 0], None)


@styled
def spectra_figure(
    params: Sequence[str],
    units: Mapping[str, str],
    series: Sequence[Mapping[str, Any]],
    title: str = "",
) -> str:
    """Fitted parameters against wavelength with 95 % error bars.

    Parameters
    ----------
    params : sequence of str
        Parameter names, one panel each.
    units : mapping
        Parameter -> unit label.
    series : sequence of mappings
        ``{"label": str, "wavelength": array [nm], "values": {p: array},
        "lo": {p: array}, "hi": {p: array}, "style": "fit" | "published"}``.
    """
    n = max(1, len(params))
    nrow, ncol, w = grid_shape(n, 4, 3.6)
    fig, axes = plt.subplots(nrow, ncol, figsize=(ncol * w, 3.2 * nrow), squeeze=False)
    for ax in axes.ravel()[n:]:
        ax.set_visible(False)
    for j, p in enumerate(params):
        ax = axes.ravel()[j]
        for k, s in enumerate(series):
            wl = np.asarray(s["wavelength"], float)
            v = np.asarray(s["values"][p], float)
            if s.get("style") == "published":
                ax.plot(wl, v, "k*", ms=7, label=_text(s["label"]))
                continue
            lo = s.get("lo", {}).get(p)
            hi = s.get("hi", {}).get(p)
            yerr = None
            if lo is not None and hi is not None:
                lo = np.asarray(lo, float)
                hi = np.asarray(hi, float)
                ok = np.isfinite(lo) & np.isfinite(hi)
                yerr = np.where(ok, np.vstack([v - lo, hi - v]), 0.0)
                yerr = np.clip(yerr, 0.0, None)
            ax.errorbar(
                wl,
                v,
                yerr=yerr,
                fmt=_MARKERS[k % 7] + "-",
                color=_COLOURS[k % 7],
                ms=4,
                mfc="none",
                capsize=2,
                lw=0.9,
                label=_text(s["label"]),
            )
        ax.set_xlabel("wavelength [nm]")
        ax.set_ylabel(f"{p} [{units.get(p, '1')}]")
        ax.grid(alpha=0.3)
    return _finish_below(fig, axes[0, 0], title)


@styled
def compare_models_figure(panels: Sequence[Mapping[str, Any]], title: str = "") -> str:
    """Measured BRDF against two fitted models at one incidence angle (Fig. 4 style).

    ``panels``: ``{"label", "theta_r" [deg], "value" [sr^-1], "curve_theta_r" [deg],
    "curves": {name: array}}``.
    """
    n = max(1, len(panels))
    nrow, ncol, w = grid_shape(n, 3, 3.6)
    fig, axes = plt.subplots(nrow, ncol, figsize=(ncol * w, 3.4 * nrow), squeeze=False)
    for ax in axes.ravel()[n:]:
        ax.set_visible(False)
    for j, p in enumerate(panels):
        ax = axes.ravel()[j]
        ax.plot(p["theta_r"], p["value"], "*", color="0.15", ms=6, label="measured")
        for q, (name, curve) in enumerate(p["curves"].items()):
            ax.plot(
                p["curve_theta_r"],
                curve,
                ("-s", "--v", ":o")[q % 3],
                ms=3,
                markevery=10,
                color=_COLOURS[q + 1],
                lw=1.2,
                label=_text(name),
            )
        ax.set_title(_text(p["label"]))
        ax.set_xlabel(r"$\theta_r$ [deg]")
        if j % ncol == 0:
            ax.set_ylabel(r"BRDF [sr$^{-1}$]")
        ax.grid(alpha=0.3)
    return _finish_below(fig, axes[0, 0], title)


@styled
def hemispherical_figure(
    measured: Mapping[str, Any] | None,
    points: Sequence[Mapping[str, Any]],
    title: str = "",
) -> str:
    """Hemispherical reflectance [%] against wavelength: spectrophotometer and integrals.

    ``measured``: ``{"label", "wavelength" [nm], "value" [fraction]}`` or None;
    ``points``: ``{"label", "wavelength", "value" [fraction], "marker"}``.
    """
    fig, ax = plt.subplots(figsize=(6.2, 3.8))
    if measured is not None:
        ax.plot(
            measured["wavelength"],
            100 * np.asarray(measured["value"], float),
            "-",
            color="0.3",
            lw=1.2,
            label=_text(measured["label"]),
        )
    for k, p in enumerate(points):
        ax.plot(
            p["wavelength"],
            100 * np.asarray(p["value"], float),
            p.get("marker", _MARKERS[k % 7]),
            ms=6,
            mfc="none",
            color=p.get("color", _COLOURS[k % 7]),
            label=_text(p["label"]),
        )
    ax.set_xlabel("wavelength [nm]")
    ax.set_ylabel("hemispherical reflectance [%]")
    return _finish(fig, ax, title)


@styled
def spectrum_figure(
    wavelength: Any,
    value: Any,
    used_wavelength: Any,
    used_value: Any,
    title: str = "",
    ylabel: str = "reflectance [%]",
) -> str:
    """A measured spectrum (points) and the spectrum used after inter/extrapolation (line)."""
    fig, ax = plt.subplots(figsize=(6.2, 3.4))
    ax.plot(
        used_wavelength,
        100 * np.asarray(used_value, float),
        "-",
        color="C0",
        lw=1.2,
        label="used (interpolated / extrapolated)",
    )
    ax.plot(wavelength, 100 * np.asarray(value, float), "o", color="k", ms=4, label="measured")
    ax.set_xlabel("wavelength [nm]")
    ax.set_ylabel(ylabel)
    return _finish(fig, ax, title)


@styled
def xy_figure(
    series: Sequence[Mapping[str, Any]],
    xlabel: str,
    ylabel: str,
    title: str = "",
    logy: bool = False,
) -> str:
    """Generic lines/points: ``{"x", "y", "label", "style"}`` per series."""
    fig, ax = plt.subplots(figsize=(6.2, 3.6))
    for k, s in enumerate(series):
        ax.plot(
            s["x"],
            s["y"],
            s.get("style", "-"),
            color=s.get("color", _COLOURS[k % 7]),
            ms=3.5,
            mfc="none",
            lw=1.1,
            label=_text(s["label"]),
        )
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    if logy:
        ax.set_yscale("log")
    return _finish(fig, ax, title)


@styled
def polar_maps_figure(
    labels: Sequence[str],
    s0: Sequence[np.ndarray],
    dop: Sequence[np.ndarray],
    theta_edges_deg: np.ndarray,
    phi_edges_deg: np.ndarray,
    title: str = "",
    s0_max: Sequence[float | None] | None = None,
) -> str:
    """Hemisphere maps of S0 and DOP, one column per case (2022 paper Figs. 7-14 style).

    Polar axes: azimuth = phi_r (outward, source at 0, specular half-plane at 180 deg),
    radius = theta_r [deg]. S0 is the pBRDF element M00 [sr^-1] for unpolarized input
    (shared colour scale per row is NOT used: each case gets its own, the paper's way;
    but all are log scales when one case needs it, ``labbrdf._plotting.map_scale``);
    DOP is dimensionless in [0, 1].

    Parameters
    ----------
    labels : sequence of str
    s0, dop : sequence of (n_theta, n_phi) arrays
    theta_edges_deg : (n_theta + 1,) array
    phi_edges_deg : (n_phi + 1,) array
    title : str
    s0_max : sequence of float or None, optional
        Upper end of each S0 colour scale (e.g. ignoring bins with few rays).
    """
    fig = plt.figure(figsize=polar_maps_size(len(labels)))
    draw_polar_maps(fig, labels, (s0, dop), (theta_edges_deg, phi_edges_deg), s0_max)
    return _finish_grid(fig, title)


def save_trace_maps_png(result: Any, path: str | Any, stokes_in: Any = (1, 0, 0, 0)) -> Any:
    """Write the S0 and DOP hemisphere maps and the in-plane cut of a tracer result to PNG.

    The figure is :meth:`labbrdf.TraceResult.plot` (the same as in a notebook) at
    :data:`labbrdf.figstyle.DPI`.

    Parameters
    ----------
    result : labbrdf.tracer.TraceResult
    path : path-like
        Output ``.png``.
    stokes_in : sequence of 4 floats
        Input Stokes vector (default unpolarized).

    Returns
    -------
    pathlib.Path
    """
    return save_png(to_uri(result.plot(stokes_in)), path)


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
    return _finish_grid(fig, title)


def save_png(uri: str, path: Any) -> Any:
    """Write a figure's PNG data URI to ``path`` atomically (never a half-written file).

    Parameters
    ----------
    uri : str
        ``data:image/png;base64,...`` as the figure functions return it.
    path : path-like
        Output ``.png``.

    Returns
    -------
    pathlib.Path
    """
    from pathlib import Path

    from labbrdf.outputs import atomic_output

    data = base64.b64decode(uri.split(",", 1)[1])
    with atomic_output(path) as tmp:
        Path(tmp).write_bytes(data)
    return Path(path)


# --------------------------------------------------------------------------- measured BRDF


@styled
def brdf_maps_figure(panels: Sequence[Mapping[str, Any]], title: str = "") -> str:
    """Measured BRDF, fitted model and relative residual per angle of incidence (one row each).

    Drawn by ``labbrdf._brdf_maps.draw_brdf_maps`` (as ``fit --residual-maps`` and
    :meth:`labbrdf.FitResult.plot` of hemispherical data).

    Parameters
    ----------
    panels : sequence of mappings
        ``{"label": str, "theta_r": array [deg], "phi_r": array [deg], "measured": array
        [sr^-1], "model": array [sr^-1], "residual": array [1]}``; optional
        ``"model_label"`` (default "model (per-incidence fit)") and ``"residual_label"``
        (default "(model - measured) / measured"), e.g. for a prediction.
    title : str

    Returns
    -------
    str
        PNG data URI. Projected hemisphere: x = theta_r cos phi_r, y = theta_r sin phi_r
        [deg]; BRDF on a log10 colour scale shared by measured and model in a row.
    """
    fig = plt.figure(figsize=maps_size(panels, PAGE_WIDTH_IN), layout="constrained")
    draw_brdf_maps(fig, panels)
    if title:
        fig.suptitle(_text(title))
    return to_uri(fig)


@styled
def brdf_residual_grid_figure(panels: Sequence[Mapping[str, Any]], title: str = "") -> str:
    """Relative residual maps of every angle of incidence as small multiples (5 per row).

    ``panels`` as for :func:`brdf_maps_figure` (``residual`` [1] is used).
    """
    n = max(1, len(panels))
    ncol = min(4, n)
    nrow = -(-n // ncol)
    half = is_half(panels)
    fig, axes = plt.subplots(
        nrow,
        ncol,
        figsize=(2.5 * ncol + 1.0, (1.6 if half else 2.6) * nrow + 0.6),
        squeeze=False,
    )
    mesh = None
    for k, ax in enumerate(axes.ravel()):
        if k >= len(panels):
            ax.axis("off")
            continue
        p = panels[k]
        tri, zt = triangulate(p, np.clip(np.asarray(p["residual"], float), -1.0, 1.0))
        mesh = ax.tripcolor(tri, facecolors=zt, cmap="RdBu_r", vmin=-1.0, vmax=1.0)
        draw_disc(ax, half)
        ax.set_title(_text(p["label"]))
    if mesh is not None:
        cb = fig.colorbar(mesh, ax=axes.ravel().tolist(), shrink=0.8)
        cb.set_label("(model - measured) / measured [1]")
    fig.text(0.01, 0.005, r"axes: $\theta_r\cos\varphi_r$, $\theta_r\sin\varphi_r$ [deg]")
    if title:
        fig.suptitle(_text(title))
    return to_uri(fig)


@styled
def brdf_cuts_figure(panels: Sequence[Mapping[str, Any]], title: str = "") -> str:
    """In-plane BRDF cuts with model curves, one small panel per angle of incidence.

    Parameters
    ----------
    panels : sequence of mappings
        ``{"label": str, "x": array (signed theta_r [deg]), "y": array [sr^-1],
        "grid": array [deg], "curves": {name: array [sr^-1]}, "specular": float [deg]}``.
    title : str
    """
    n = max(1, len(panels))
    nrow, ncol, w = grid_shape(n, 3, 3.6)
    fig, axes = plt.subplots(
        nrow, ncol, figsize=(ncol * w, 2.8 * nrow + 0.4), squeeze=False, sharex=True
    )
    for k, ax in enumerate(axes.ravel()):
        if k >= len(panels):
            ax.axis("off")
            continue
        p = panels[k]
        x, y = np.asarray(p["x"], float), np.asarray(p["y"], float)
        ok = y > 0
        ax.semilogy(x[ok], y[ok], "o", ms=3, color="k", label="measured")
        for j, (name, c) in enumerate(p["curves"].items()):
            c = np.asarray(c, float)
            ax.semilogy(
                p["grid"],
                np.where(c > 0, c, np.nan),
                ls=("-", "--")[j % 2],
                color=_COLOURS[j],
                lw=1.1,
                label=_text(name),
            )
        ax.axvline(float(p["specular"]), color="0.5", ls=":", lw=0.8)
        if ok.any():
            ax.set_ylim(0.5 * float(y[ok].min()), 2.0 * float(y[ok].max()))
        ax.set_title(_text(p["label"]))
        ax.tick_params(which="both", labelbottom=True)
        ax.grid(alpha=0.3)
        if k % ncol == 0:
            ax.set_ylabel(r"BRDF [sr$^{-1}$]")
        if k >= len(panels) - ncol:
            ax.set_xlabel(r"signed $\theta_r$ [deg] (+: specular side)")
    return _finish_below(fig, axes[0, 0], title)


# --------------------------------------------------------------------------- measured data


@styled
def panels_figure(
    panels: Sequence[Mapping[str, Any]],
    title: str = "",
    ncols: int = 3,
    panel_size: tuple[float, float] = (4.6, 3.2),
) -> str:
    """A grid of line/point panels, each with its own axes labels (measured quantities).

    Parameters
    ----------
    panels : sequence of mappings
        ``{"title": str, "xlabel": str, "ylabel": str, "logy": bool (optional),
        "series": [{"label": str, "x": array, "y": array, "yerr": array or None,
        "band": array or None, "style": "line" | "points", "colour": str (optional)}]}``.
        ``yerr`` draws error bars (1 sigma), ``band`` a shaded y +- band; ``colour`` (a
        matplotlib colour) pairs series, e.g. a measurement and its model.
    title : str
        Figure title.
    ncols : int
        Panels per row.
    panel_size : (float, float)
        Width and height of one panel [inch].

    Returns
    -------
    str
        PNG data URI.
    """
    n = max(1, len(panels))
    nrows, ncols, w = grid_shape(n, ncols, panel_size[0])
    h = max(panel_size[1] * w / panel_size[0], PANEL_MIN_IN[1]) + _legend_height(panels)
    fig, axes = plt.subplots(
        nrows,
        ncols,
        figsize=(w * ncols, h * nrows + (0.4 if title else 0.0)),
        squeeze=False,
    )
    shared = _same_legend(panels)
    for j, ax in enumerate(axes.ravel()):
        if j >= len(panels):
            ax.set_visible(False)
            continue
        draw_panel(ax, panels[j], legend=not shared)
    if shared:
        return _finish_below(fig, axes[0, 0], title)
    return _finish_grid(fig, title)


def _legend_height(panels: Sequence[Mapping[str, Any]]) -> float:
    """Height [inch] the longest legend below a panel needs (two or four columns)."""
    n = max((sum(1 for s in p.get("series", []) if s.get("label")) for p in panels), default=0)
    return 0.0 if n <= 2 or n > 16 or _same_legend(panels) else 0.2 * -(-n // (4 if n > 8 else 2))


def _same_legend(panels: Sequence[Mapping[str, Any]]) -> bool:
    """Whether every panel has the same, non-empty series labels (one legend for all)."""
    keys = {tuple(str(s.get("label", "")) for s in p.get("series", [])) for p in panels}
    return len(panels) > 1 and len(keys) == 1 and any(next(iter(keys)))


@styled
def map_figure(
    panels: Sequence[Mapping[str, Any]],
    title: str = "",
    ncols: int = 4,
) -> str:
    """Stage maps: one scatter panel per angle or wavelength, colour = measured value.

    Parameters
    ----------
    panels : sequence of mappings
        ``{"title": str, "x": array [mm], "y": array [mm], "value": array,
        "label": str (colour-bar label with units)}``.
    title : str
        Figure title.
    ncols : int
        Panels per row.

    Returns
    -------
    str
        PNG data URI.
    """
    n = max(1, len(panels))
    nrows, ncols, w = grid_shape(n, ncols, 3.6)
    fig, axes = plt.subplots(nrows, ncols, figsize=(w * ncols, 0.88 * w * nrows), squeeze=False)
    for j, ax in enumerate(axes.ravel()):
        if j >= len(panels):
            ax.set_visible(False)
            continue
        p = panels[j]
        sc = ax.scatter(p["x"], p["y"], c=p["value"], s=60, cmap="viridis", edgecolors="k")
        cb = fig.colorbar(sc, ax=ax)
        cb.set_label(_text(p.get("label", "")))
        ax.set_xlabel("stage x [mm]")
        ax.set_ylabel("stage y [mm]")
        ax.set_title(_text(p.get("title", "")))
        ax.set_aspect("equal", adjustable="datalim")
        ax.grid(alpha=0.3)
    return _finish_grid(fig, title)


def reflectance_comparison_figure(
    measured: list[dict[str, Any]],
    difference: list[dict[str, Any]],
    panel_size: tuple[float, float] = (5.0, 3.2),
) -> str:
    """Two panels: measured and predicted reflectance, and their difference [1].

    ``measured`` and ``difference`` are :func:`panels_figure` series lists; the sections
    that set a model's prediction beside a spectrophotometer or ellipsometer reflectance
    (the bulk n, k and the fitted film stack) draw it the same way.
    """
    return panels_figure(
        [
            {
                "title": "reflectance",
                "xlabel": "wavelength [nm]",
                "ylabel": "R [1]",
                "series": measured,
            },
            {
                "title": "difference",
                "xlabel": "wavelength [nm]",
                "ylabel": "measured - predicted [1]",
                "series": difference,
            },
        ],
        ncols=2,
        panel_size=panel_size,
    )


@styled
def fit_maps_figure(model: Any, params: Mapping[str, float], rows: Any, title: str = "") -> str:
    """Measured BRDF, one fitted model and the relative residual, one row per incidence.

    For a joint fit over several incidences (``labbrdf fit --residual-maps``): the model
    with ``params`` is evaluated at every row and the panels of :func:`brdf_maps_figure`
    are drawn (relative residual ``(model - measured) / measured``, blank where the
    measurement is 0).

    Parameters
    ----------
    model : labbrdf.models.Model
    params : mapping
        Fitted values (name -> value).
    rows : pandas.DataFrame
        ``theta_i_deg``, ``theta_r_deg``, ``phi_r_deg``, ``value`` [sr^-1] and
        ``wavelength_nm`` (optional).
    title : str

    Returns
    -------
    str
        PNG data URI.
    """
    ti = rows["theta_i_deg"].to_numpy(float)
    tr = rows["theta_r_deg"].to_numpy(float)
    pr = rows["phi_r_deg"].to_numpy(float)
    v = rows["value"].to_numpy(float)
    wl = rows["wavelength_nm"].to_numpy(float) if "wavelength_nm" in rows else None
    f = np.asarray(
        model.evaluate(
            np.radians(ti), np.radians(tr), np.radians(pr), wavelength=wl, params=dict(params)
        ),
        float,
    )
    panels = map_panels(ti, tr, pr, v, f, "model (one fit, all incidences)")
    return brdf_maps_figure(panels, title=title)
