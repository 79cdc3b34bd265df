"""Hemisphere maps of a measured BRDF, its model and their relative residual.

One drawing for every place that shows BRDF data over the hemisphere: the report's map
figures, ``labbrdf fit --residual-maps`` and :meth:`labbrdf.FitResult.plot` of
hemispherical data. Like :mod:`labbrdf._plotting` it draws on a figure it is given and
imports matplotlib only when drawing.

Projection: x = theta_r cos phi_r, y = theta_r sin phi_r [deg] (the projected hemisphere,
specular direction at phi_r = 0 or 180 deg as the file has it); each point is a vertex of a
Delaunay triangulation coloured by the mean of its corners.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from ._plotting import text

__all__ = [
    "draw_brdf_maps",
    "draw_disc",
    "is_half",
    "map_panels",
    "maps_size",
    "triangulate",
]

#: no triangle wider than this [deg] (it would bridge a hole in the sampling)
MAX_SPAN_DEG = 25.0
RESIDUAL_LABEL = "(model - measured) / measured"


def is_half(panels: Sequence[Mapping[str, Any]]) -> bool:
    """Whether every panel lies in the half-plane phi_r <= 180 deg (a plane-symmetric file)."""
    return all(np.all(np.asarray(p["phi_r"]) <= 180.0 + 1e-9) for p in panels)


def maps_size(panels: Sequence[Mapping[str, Any]], width_in: float) -> tuple[float, float]:
    """Figure size [inch] of :func:`draw_brdf_maps`: three maps per row, one row per panel."""
    h = (0.42 if is_half(panels) else 0.8) * width_in / 3.0 + 0.25
    return width_in, h * max(1, len(panels)) + 0.5


def draw_disc(ax: Any, half: bool) -> None:
    """Guide circles at theta_r = 30, 60, 90 deg on a projected-hemisphere axis [deg]."""
    t = np.linspace(0.0, np.pi if half else 2.0 * np.pi, 181)
    for r in (30.0, 60.0, 90.0):
        ax.plot(r * np.cos(t), r * np.sin(t), color="0.6", lw=0.5)
    ax.set_aspect("equal")
    ax.set_xlim(-92, 92)
    ax.set_ylim(-2 if half else -92, 92)


def triangulate(panel: Mapping[str, Any], z: np.ndarray) -> tuple[Any, np.ndarray]:
    """Delaunay triangulation of a panel's directions in the projected disc; z per triangle."""
    from matplotlib.tri import Triangulation

    tr = np.radians(np.asarray(panel["phi_r"], float))
    x = np.asarray(panel["theta_r"], float) * np.cos(tr)
    y = np.asarray(panel["theta_r"], float) * np.sin(tr)
    tri = Triangulation(x, y)
    zt = np.mean(np.asarray(z, float)[tri.triangles], axis=1)
    bad = ~np.isfinite(zt)
    xy = np.stack([x, y], axis=1)[tri.triangles]
    span = np.max(np.linalg.norm(xy - np.roll(xy, 1, axis=1), axis=2), axis=1)
    tri.set_mask(bad | (span > MAX_SPAN_DEG))
    return tri, np.where(bad, 0.0, zt)


def map_panels(
    theta_i: np.ndarray,
    theta_r: np.ndarray,
    phi_r: np.ndarray,
    measured: np.ndarray,
    model: np.ndarray,
    model_label: str,
) -> list[dict[str, Any]]:
    """One panel per angle of incidence: the points, measured and model values, residual.

    Parameters
    ----------
    theta_i, theta_r, phi_r : arrays
        Directions of the points [deg].
    measured, model : arrays
        BRDF at the points [sr^-1].
    model_label : str
        Heading of the model's column.

    Returns
    -------
    list of dict
        Panels for :func:`draw_brdf_maps`; the residual is ``(model - measured) /
        measured`` [1], blank (NaN) where the measurement is 0.
    """
    ti = np.round(np.asarray(theta_i, float), 6)
    panels = []
    for t in np.unique(ti):
        sel = ti == t
        v = np.asarray(measured, float)[sel]
        f = np.asarray(model, float)[sel]
        with np.errstate(divide="ignore", invalid="ignore"):
            res = np.where(v > 0, (f - v) / v, np.nan)
        panels.append(
            {
                "label": f"\u03b8i = {float(t):g}\u00b0",
                "theta_r": np.asarray(theta_r, float)[sel],
                "phi_r": np.asarray(phi_r, float)[sel],
                "measured": v,
                "model": f,
                "residual": res,
                "model_label": model_label,
            }
        )
    return panels


def draw_brdf_maps(fig: Any, panels: Sequence[Mapping[str, Any]]) -> Any:
    """Measured BRDF, model and relative residual, one row of three maps per panel.

    Parameters
    ----------
    fig : matplotlib Figure
        Empty; sized by :func:`maps_size`.
    panels : sequence of mappings
        ``{"label": str, "theta_r": array [deg], "phi_r": array [deg], "measured": array
        [sr^-1], "model": array [sr^-1], "residual": array [1]}``; optional
        ``"model_label"`` (default "model (per-incidence fit)") and ``"residual_label"``
        (default "(model - measured) / measured"), e.g. for a prediction.

    Returns
    -------
    ndarray of Axes, shape (len(panels), 3)

    Notes
    -----
    The BRDF is on a log10 colour scale shared by measured and model in a row, from the
    1st percentile of the positive values to the largest; the residual is clipped to
    [-1, 1]. Column headings on the first row, the angle of incidence on each row's left.
    """
    n = max(1, len(panels))
    half = is_half(panels)
    axes = fig.subplots(n, 3, squeeze=False)
    mesh = None
    for i, p in enumerate(panels):
        mesh = _draw_row(fig, axes[i], p, half)
        axes[i, 0].set_ylabel(f"{text(p['label'])}\n" + r"$\theta_r \sin\varphi_r$ [deg]")
    if mesh is not None:  # one scale for every residual map
        cb = fig.colorbar(mesh, ax=axes[:, 2].tolist(), shrink=min(0.9, 0.3 + 0.2 * n))
        cb.set_label("relative residual [1]")
    for j, name in enumerate(
        (
            "measured",
            str(panels[0].get("model_label", "model (per-incidence fit)")) if panels else "",
            str(panels[0].get("residual_label", RESIDUAL_LABEL)) if panels else "",
        )
    ):
        axes[0, j].set_title(text(name))
    for ax in axes[-1]:
        ax.set_xlabel(r"$\theta_r \cos\varphi_r$ [deg]")
    return axes


def _draw_row(fig: Any, axes: Sequence[Any], p: Mapping[str, Any], half: bool) -> Any:
    """The three maps of one angle of incidence; one colour bar for measured and model.

    Returns the residual map (for the colour bar the rows share).
    """
    from matplotlib.ticker import FuncFormatter, LogLocator, NullLocator

    meas = np.asarray(p["measured"], float)
    mod = np.asarray(p["model"], float)
    pos = np.concatenate([meas[meas > 0], mod[mod > 0]])
    vmin = float(np.percentile(pos, 1)) if pos.size else 1e-3
    vmax = float(np.max(pos)) if pos.size else 1.0
    mesh = None
    for j, z in enumerate((meas, mod)):
        zz = np.where(z > 0, np.clip(z, vmin, None), np.nan)
        tri, zt = triangulate(p, zz)
        mesh = axes[j].tripcolor(
            tri,
            facecolors=np.where(zt > 0, zt, vmin),
            cmap="inferno",
            norm="log",
            vmin=vmin,
            vmax=max(vmax, vmin * 10),
        )
        draw_disc(axes[j], half)
    cb = fig.colorbar(mesh, ax=list(axes[:2]), shrink=0.8 if half else 0.9)
    cb.ax.set_title(r"BRDF [sr$^{-1}$]", loc="left")  # above: not read as the next map's
    # ticks at 1, 2 and 5 per decade over a short scale, decades only over a long one; all
    # labelled, no crowded minor labels
    subs = (1.0, 2.0, 5.0) if vmax < 30.0 * vmin else (1.0,)
    cb.ax.yaxis.set_major_locator(LogLocator(subs=subs))
    cb.ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:.3g}"))
    cb.ax.yaxis.set_minor_locator(NullLocator())
    tri, zt = triangulate(p, np.clip(np.asarray(p["residual"], float), -1.0, 1.0))
    res = axes[2].tripcolor(tri, facecolors=zt, cmap="RdBu_r", vmin=-1.0, vmax=1.0)
    draw_disc(axes[2], half)
    return res
