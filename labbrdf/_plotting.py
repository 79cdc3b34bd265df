"""Axes-level drawing shared by the ``plot()`` methods and the report's figures.

Each function draws plain arrays on matplotlib Axes it is given and returns nothing or the
artist a caller needs (a colour mesh for its colour bar). It never creates, renders or
closes a figure, and never imports matplotlib itself: the objects' ``plot()`` methods (which
create a figure only when the caller passes no Axes) and ``labbrdf.report.figures`` (which
renders the report's PNGs) draw through the same code, so a notebook figure and a report
figure of the same thing look the same.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

__all__ = [
    "COLOURS",
    "MARKERS",
    "curve_grid",
    "draw_cut",
    "draw_panel",
    "draw_polar_map",
    "draw_scan",
    "text",
]

MARKERS = ("s", "^", "v", "o", "D", "P", "X")
COLOURS = ("C0", "C1", "C2", "C3", "C4", "C5", "C6")


def text(s: Any) -> str:
    """``s`` as literal text: matplotlib's mathtext would interpret ``$...$`` in file text."""
    return str(s).replace("$", r"\$")


def curve_grid(theta_r: np.ndarray) -> np.ndarray:
    """121 detector angles [deg] spanning the measured ones with a 5 % margin."""
    lo, hi = float(np.min(theta_r)), float(np.max(theta_r))
    pad = 0.05 * max(hi - lo, 0.5)
    return np.linspace(max(0.0, lo - pad), min(89.9, hi + pad), 121)


def draw_scan(ax: Any, axr: Any, series: Sequence[Mapping[str, Any]]) -> None:
    """Measured points with 1-sigma bars, model curves and residuals of one scan panel.

    Parameters
    ----------
    ax, axr : matplotlib Axes
        The data axes and the residual axes below it.
    series : sequence of mappings
        One per incidence angle: ``{"theta_i": float, "theta_r": array [deg], "value":
        array, "sigma": array or None, "curve_theta_r": array [deg], "curves": {name:
        array}, "residual": {name: array}, "label": str (optional, default the angle)}``.
        The residuals are drawn at ``theta_r`` in whatever unit the caller labels.
    """
    for k, s in enumerate(series):
        c = COLOURS[k % len(COLOURS)]
        m = MARKERS[k % len(MARKERS)]
        lab = text(s.get("label", f"{s['theta_i']:g}\u00b0"))
        ax.errorbar(
            s["theta_r"],
            s["value"],
            yerr=s.get("sigma"),
            fmt=m,
            ms=3.5,
            color=c,
            mfc="none",
            lw=0.8,
            alpha=0.6,
            zorder=1,
            label=f"measured {lab}",
        )
        for q, (name, curve) in enumerate(s.get("curves", {}).items()):
            ax.plot(
                s["curve_theta_r"],
                curve,
                ls=("-", "--", ":")[q % 3],
                lw=1.4,
                zorder=3,
                color="k" if q else c,
                label=f"{name} {lab}",
            )
        for q, (name, res) in enumerate(s.get("residual", {}).items()):
            axr.plot(s["theta_r"], res, m, color=c, ms=3, mfc="none" if q else c, label=name)
    ax.set_xlabel(r"$\theta_r$ [deg]")
    axr.set_xlabel(r"$\theta_r$ [deg]")
    axr.axhline(0.0, color="0.4", lw=0.6)
    ax.grid(alpha=0.3)
    axr.grid(alpha=0.3)


def draw_panel(ax: Any, panel: Mapping[str, Any]) -> None:
    """Lines or points with optional 1-sigma error bars or bands, with labelled axes.

    Parameters
    ----------
    ax : matplotlib Axes
    panel : mapping
        ``{"title": str, "xlabel": str, "ylabel": str, "logy": bool (optional),
        "series": [{"label": str, "x": array, "y": array, "yerr": array or None,
        "band": array or None, "style": "line" | "points", "colour": str (optional)}]}``.
        ``yerr`` draws error bars (1 sigma), ``band`` a shaded y +- band; ``colour`` (a
        matplotlib colour) pairs series, e.g. a measurement and its model. Points are
        drawn in order of increasing x.
    """
    series = list(panel.get("series", []))
    for k, s in enumerate(series):
        c = COLOURS[k % len(COLOURS)] if len(series) <= len(COLOURS) else None
        c = s.get("colour", c)
        x = np.asarray(s["x"], float)
        y = np.asarray(s["y"], float)
        order = np.argsort(x, kind="stable")
        x, y = x[order], y[order]
        yerr = s.get("yerr")
        band = s.get("band")
        points = s.get("style") == "points" or len(x) < 3
        kw: dict[str, Any] = {"label": text(s.get("label", "")) or None}
        if c is not None:
            kw["color"] = c
        if yerr is not None and np.any(np.isfinite(yerr)):
            e = np.asarray(yerr, float)[order]
            every = max(1, len(x) // 60)
            ax.errorbar(
                x,
                y,
                yerr=np.where(np.isfinite(e), e, 0.0),
                fmt="o" if points else "-",
                ms=2.5,
                lw=0.9,
                elinewidth=0.6,
                capsize=0,
                errorevery=every,
                **kw,
            )
        else:
            ax.plot(x, y, "o" if points else "-", ms=2.5, lw=0.9, **kw)
        if band is not None and np.any(np.isfinite(band)):
            b = np.asarray(band, float)[order]
            ax.fill_between(x, y - b, y + b, alpha=0.25, lw=0, color=c)
    if panel.get("logy"):
        ax.set_yscale("log")
    ax.set_xlabel(text(panel.get("xlabel", "")), fontsize=8)
    ax.set_ylabel(text(panel.get("ylabel", "")), fontsize=8)
    ax.set_title(text(panel.get("title", "")), fontsize=8.5)
    ax.tick_params(labelsize=7)
    ax.grid(alpha=0.3)
    if any(s.get("label") for s in series) and len(series) <= 12:
        ax.legend(fontsize=6, loc="best")


def draw_polar_map(
    ax: Any,
    data: np.ndarray,
    theta_edges_deg: np.ndarray,
    phi_edges_deg: np.ndarray,
    *,
    title: str,
    cmap: str,
    vmin: float | None = None,
    vmax: float | None = None,
) -> Any:
    """A hemisphere map on polar Axes: azimuth phi_r, radius theta_r [deg].

    Parameters
    ----------
    ax : matplotlib Axes with ``projection="polar"``
    data : (n_theta, n_phi) array
        One value per bin; NaN bins are left blank.
    theta_edges_deg, phi_edges_deg : arrays
        Bin edges [deg] (n_theta + 1 and n_phi + 1 of them).
    title : str
        Axes title (literal text and mathtext both allowed: the caller escapes file text).
    cmap : str
        Colour map name.
    vmin, vmax : float, optional
        Colour scale limits; default the data's range.

    Returns
    -------
    matplotlib QuadMesh
        For the caller's colour bar.
    """
    ph = np.deg2rad(np.asarray(phi_edges_deg, float))
    th = np.asarray(theta_edges_deg, float)
    P, T = np.meshgrid(ph, th)
    z = np.ma.masked_invalid(np.asarray(data, float))
    mesh = ax.pcolormesh(P, T, z, cmap=cmap, shading="flat", vmin=vmin, vmax=vmax)
    ax.set_ylim(0, th[-1])
    ax.set_yticks([30, 60, 90])
    ax.set_yticklabels(["30\u00b0", "60\u00b0", "90\u00b0"], fontsize=6, color="w")
    ax.tick_params(axis="x", labelsize=6)
    ax.set_title(title, fontsize=8)
    return mesh


def draw_cut(
    ax: Any,
    theta_deg: np.ndarray,
    s0: np.ndarray,
    s0_err: np.ndarray | None,
    dop: np.ndarray,
    dop_err: np.ndarray | None,
) -> Any:
    """S0 (left axis) and DOP (right axis) along a cut, with 1-sigma bars or band.

    Parameters
    ----------
    ax : matplotlib Axes
    theta_deg : array
        Position along the cut [deg] (e.g. signed theta_r of the plane of incidence).
    s0, dop : arrays
        S0 [sr^-1] and DOP [1] at those positions; NaN points are skipped.
    s0_err, dop_err : arrays or None
        Their standard errors (error bars for S0, a shaded band for DOP); None: none.

    Returns
    -------
    matplotlib Axes
        The twin axes of the DOP.
    """
    if s0_err is not None and np.any(np.isfinite(s0_err)):
        s0_err = np.where(np.isfinite(s0_err), s0_err, 0.0)
    else:
        s0_err = None
    ax.errorbar(
        theta_deg, s0, yerr=s0_err, fmt="-", color="C3", lw=1.1, elinewidth=0.6, label="S0"
    )
    ax.set_xlabel(r"$\theta_r$ [deg] (negative: back-scatter half-plane $\varphi_r$ = 0)")
    ax.set_ylabel(r"$S_0$ [sr$^{-1}$]", color="C3")
    ax.grid(alpha=0.3)
    axd = ax.twinx()
    axd.plot(theta_deg, dop, "-", color="C0", lw=1.1, label="DOP")
    if dop_err is not None and np.any(np.isfinite(dop_err)):
        axd.fill_between(theta_deg, dop - dop_err, dop + dop_err, color="C0", alpha=0.25, lw=0)
    axd.set_ylim(0.0, 1.05)
    axd.set_ylabel("DOP [1]", color="C0")
    return axd
