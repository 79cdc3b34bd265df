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
    "draw_polar_maps",
    "draw_polar_pair",
    "axes_size_in",
    "draw_scan",
    "legend_below",
    "legend_outside",
    "scan_colours",
    "map_scale",
    "polar_maps_size",
    "robust_ylim",
    "text",
    "wrap_label",
]

MARKERS = ("s", "^", "v", "o", "D", "P", "X")
COLOURS = ("C0", "C1", "C2", "C3", "C4", "C5", "C6")
LINESTYLES = ("-", "--", ":")


def text(s: Any) -> str:
    """``s`` as literal text: matplotlib's mathtext would interpret ``$...$`` in file text."""
    return str(s).replace("$", r"\$")


def curve_grid(theta_r: np.ndarray) -> np.ndarray:
    """121 detector angles [deg] spanning the measured ones with a 5 % margin."""
    lo, hi = float(np.min(theta_r)), float(np.max(theta_r))
    pad = 0.05 * max(hi - lo, 0.5)
    return np.linspace(max(0.0, lo - pad), min(89.9, hi + pad), 121)


def scan_colours(series: Sequence[Mapping[str, Any]]) -> tuple[list[Any], Any]:
    """One colour per scan, and the colour scale of the incidence angle if there is one.

    Up to ``len(COLOURS)`` scans get the distinct colours of :data:`COLOURS` (a legend
    tells them apart); more get the colour of their incidence angle on a continuous
    scale, and the returned ``ScalarMappable`` is for a colour bar (theta_i [deg]).
    """
    if len(series) <= len(COLOURS):
        return [COLOURS[k] for k in range(len(series))], None
    import matplotlib as mpl  # drawing only: matplotlib is imported by then

    ti = np.array([float(s["theta_i"]) for s in series])
    lo, hi = float(ti.min()), float(ti.max())
    norm = mpl.colors.Normalize(lo, hi if hi > lo else lo + 1.0)
    sm = mpl.cm.ScalarMappable(norm=norm, cmap="viridis")
    return [sm.to_rgba(t) for t in ti], sm


def draw_scan(ax: Any, axr: Any, series: Sequence[Mapping[str, Any]]) -> Any:
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

    Returns
    -------
    matplotlib ScalarMappable or None
        With more scans than :data:`COLOURS` the colour is the incidence angle
        (:func:`scan_colours`) and only the first scan's artists carry legend labels (one
        per marker or line style); the caller draws the returned colour scale as a colour
        bar. None: one labelled colour per scan.
    """
    colours, scale = scan_colours(series)
    for k, s in enumerate(series):
        c = colours[k]
        m = MARKERS[k % len(MARKERS)] if scale is None else "o"
        lab = text(s.get("label", f"{s['theta_i']:g}\u00b0"))
        labelled = scale is None or k == 0
        ax.errorbar(
            s["theta_r"],
            s["value"],
            yerr=s.get("sigma"),
            fmt=m,
            ms=4,
            color=c,
            mfc="none",
            lw=0.8,
            alpha=0.6,
            zorder=1,
            label=(f"measured, \u03b8i {lab}" if scale is None else "measured")
            if labelled
            else None,
        )
        for q, (name, curve) in enumerate(s.get("curves", {}).items()):
            ax.plot(
                s["curve_theta_r"],
                curve,
                ls=LINESTYLES[q % 3],
                lw=1.4,
                zorder=3,
                color="k" if q and scale is None else c,
                gid=name,  # the legend keys are drawn once per model (_model_keys)
            )
        for q, (name, res) in enumerate(s.get("residual", {}).items()):
            axr.plot(s["theta_r"], res, m, color=c, ms=3.5, mfc="none" if q else c, label=name)
    _model_keys(ax, series, scale is not None)
    robust_ylim(axr, [r for s in series for r in s.get("residual", {}).values()])
    ax.set_xlabel(r"$\theta_r$ [deg]")
    axr.set_xlabel(r"$\theta_r$ [deg]")
    axr.axhline(0.0, color="0.4", lw=0.6)
    ax.grid(alpha=0.3)
    axr.grid(alpha=0.3)
    return scale


def _viridis(x: float) -> Any:
    """The viridis colour at ``x`` in [0, 1] (0.9 at most: the palest yellow is hard to see)."""
    import matplotlib as mpl  # drawing only: matplotlib is imported by then

    return mpl.colormaps["viridis"](0.9 * x)


def robust_ylim(ax: Any, values: Sequence[Any]) -> int:
    """Limit the y axis to the bulk of ``values`` when a few outliers would flatten it.

    When a value lies more than ten interquartile ranges beyond the quartiles (e.g. a
    relative residual where the model is nearly 0), the axis shows the quartiles with a
    margin of three interquartile ranges and says how many points are off scale.

    Returns
    -------
    int
        Points off scale (0: the axis is left to matplotlib).
    """
    parts = [np.ravel(np.asarray(v, float)) for v in values]
    v = np.concatenate(parts) if parts else np.empty(0)
    v = v[np.isfinite(v)]
    if v.size < 5:
        return 0
    lo, hi = (float(x) for x in np.percentile(v, [25.0, 75.0]))
    span = (hi - lo) or abs(hi) or 1.0
    lim = (lo - 3.0 * span, hi + 3.0 * span)
    if v.min() >= lo - 10.0 * span and v.max() <= hi + 10.0 * span:
        return 0
    off = int(np.count_nonzero((v < lim[0]) | (v > lim[1])))
    ax.set_ylim(*lim)
    ax.text(
        0.99,
        0.96,
        f"{off} point(s) off scale",
        transform=ax.transAxes,
        ha="right",
        va="top",
        color="0.3",
    )
    return off


def _model_keys(ax: Any, series: Sequence[Mapping[str, Any]], by_angle: bool) -> None:
    """Legend keys of the model curves: one per model (line style), not one per scan.

    Drawn as empty lines (no data, no effect on the axes' limits).
    """
    names: list[str] = []
    for s in series:
        names += [n for n in s.get("curves", {}) if n not in names]
    for q, name in enumerate(names):
        coloured = by_angle or q == 0
        note = " (colour of the scan)" if coloured else ""
        ax.plot(
            [],
            [],
            ls=LINESTYLES[q % 3],
            lw=1.4,
            color="0.45" if coloured else "k",
            label=f"{text(name)}{note}",
        )


def legend_outside(ax: Any, scale: Any = None, ncol: int = 4) -> None:
    """The legend of ``ax`` below the figure, never over the data.

    The colour bar of the incidence angle (:func:`draw_scan`'s scale) goes beside ``ax``
    if there is one. With the constrained layout the legend takes its place below the
    axes; otherwise it hangs below the figure's bottom edge, inside a
    ``bbox_inches="tight"`` save.
    """
    fig = ax.figure
    if scale is not None:
        cb = fig.colorbar(scale, ax=ax, pad=0.02)
        cb.set_label(r"$\theta_i$ [deg]")
    handles, labels = ax.get_legend_handles_labels()
    if not handles:
        return
    ncol = max(1, min(ncol, len(handles)))
    engine = fig.get_layout_engine()
    if engine is not None and type(engine).__name__ == "ConstrainedLayoutEngine":
        fig.legend(handles, labels, loc="outside lower center", ncol=ncol)
    else:
        fig.legend(handles, labels, loc="upper center", bbox_to_anchor=(0.5, 0.0), ncol=ncol)


def draw_panel(ax: Any, panel: Mapping[str, Any], legend: bool = True) -> None:
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
    legend : bool
        Draw the panel's legend (below the axes, never over the data); False when the
        caller draws one legend for several panels (:func:`legend_outside`).
    """
    series = list(panel.get("series", []))
    # more series than distinct colours: a sequential scale in their order (never a
    # repeated colour)
    many = [_viridis(k / max(1, len(series) - 1)) for k in range(len(series))]
    for k, s in enumerate(series):
        c = COLOURS[k % len(COLOURS)] if len(series) <= len(COLOURS) else many[k]
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
    w_in, h_in = axes_size_in(ax)
    ax.set_xlabel(wrap_label(text(panel.get("xlabel", "")), w_in))
    ax.set_ylabel(wrap_label(text(panel.get("ylabel", "")), h_in))
    ax.set_title(wrap_label(text(panel.get("title", "")), w_in))
    ax.grid(alpha=0.3)
    if legend and any(s.get("label") for s in series) and len(series) <= 16:
        legend_below(ax)


def legend_below(ax: Any, ncol: int = 2) -> None:
    """The legend of ``ax`` below its tick labels and x label: inside it would cover data.

    The gap is set in font sizes (``borderaxespad``), so it holds whatever the axes'
    final size after the layout; more than eight entries take four columns.
    """
    lines = max(1, ax.get_xlabel().count("\n") + 1) if ax.get_xlabel() else 0
    n = len(ax.get_legend_handles_labels()[0])
    ax.legend(
        loc="upper center",
        bbox_to_anchor=(0.5, 0.0),
        borderaxespad=2.2 + 1.4 * lines,
        ncol=4 if n > 8 else ncol,
    )


def axes_size_in(ax: Any) -> tuple[float, float]:
    """Width and height of ``ax`` [inch] as laid out now."""
    fw, fh = ax.figure.get_size_inches()
    box = ax.get_position()
    return float(box.width * fw), float(box.height * fh)


def wrap_label(label: str, length_in: float, fontsize_pt: float = 10.0) -> str:
    """``label`` broken into lines that fit ``length_in`` [inch] at ``fontsize_pt``.

    A label with mathtext (``$``) is left whole (a break inside ``$...$`` would break
    it); an average glyph is taken as 0.55 em wide.
    """
    import textwrap

    width = max(12, int(length_in * 72.0 / (0.55 * fontsize_pt)))
    if "$" in label.replace(r"\$", "") or len(label) <= width:
        return label
    return "\n".join(textwrap.wrap(label, width))


#: an S0 map whose top exceeds its median bin this many times is drawn on a log scale
LOG_RANGE = 30.0
#: the log scale spans at most this many decades below its top
LOG_DECADES = 4.0


def map_scale(
    data: np.ndarray, vmax: float | None = None, log: bool | None = None
) -> dict[str, Any]:
    """Colour scale of a non-negative map (e.g. S0 [sr^-1]): linear, or log over a peak.

    A specular spike many times the diffuse level would paint the rest of a linear map in
    the colour of zero (a black disc). When the top of the scale exceeds the median of the
    positive bins :data:`LOG_RANGE` times, the scale is logarithmic from the 5th percentile
    of the positive bins (at most :data:`LOG_DECADES` decades below the top) to the top;
    lower positive bins take the lowest colour, and bins that no light reached (0) are
    left blank (:func:`draw_polar_map`).

    Parameters
    ----------
    data : array
        The map; NaN bins are ignored.
    vmax : float, optional
        Top of the scale (default the largest bin).
    log : bool, optional
        Force a log (True) or linear (False) scale; default chosen as above (maps set
        side by side share the kind of scale: the caller forces it).

    Returns
    -------
    dict
        ``{"vmin": float, "vmax": float, "log": bool, "note": str}``; ``note`` is
        ``"log scale, blank: 0"`` or ``""``, for the colour bar's label.
    """
    z = np.asarray(data, float)
    pos = z[np.isfinite(z) & (z > 0)]
    if pos.size == 0:
        return {"vmin": 0.0, "vmax": 1.0, "log": False, "note": ""}
    top = float(vmax) if vmax is not None and vmax > 0 else float(pos.max())
    if log is None:
        log = top > LOG_RANGE * float(np.median(pos))
    if not log:
        return {"vmin": 0.0, "vmax": top, "log": False, "note": ""}
    lo = max(float(np.percentile(pos, 5)), top * 10.0**-LOG_DECADES)
    return {"vmin": min(lo, top / 10.0), "vmax": top, "log": True, "note": "log scale, blank: 0"}


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
    log: bool = False,
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
    log : bool
        Logarithmic colour scale from ``vmin`` (> 0) to ``vmax``; positive bins below
        ``vmin`` take the lowest colour, bins of 0 are left blank (see :func:`map_scale`).

    Returns
    -------
    matplotlib QuadMesh
        For the caller's colour bar.
    """
    ph = np.deg2rad(np.asarray(phi_edges_deg, float))
    th = np.asarray(theta_edges_deg, float)
    P, T = np.meshgrid(ph, th)
    z = np.asarray(data, float)
    if log and vmin is not None and vmin > 0:
        z = np.where(np.isfinite(z) & (z > 0), np.maximum(z, vmin), np.nan)
    z = np.ma.masked_invalid(z)
    norm = "log" if log and vmin is not None and vmin > 0 else None
    mesh = ax.pcolormesh(P, T, z, cmap=cmap, shading="flat", vmin=vmin, vmax=vmax, norm=norm)
    ax.set_ylim(0, th[-1])
    ax.set_yticks([30, 60, 90])
    from matplotlib import patheffects  # drawing only: matplotlib is imported by then

    halo = [patheffects.withStroke(linewidth=2.5, foreground="w")]
    # dark labels with a white halo: readable on a dark map and on blank bins alike (90 deg
    # is the rim, unlabelled: its label would sit on the azimuth labels)
    ax.set_yticklabels(["30\u00b0", "60\u00b0", ""], color="0.15", path_effects=halo)
    ax.set_title(title)
    return mesh


def polar_maps_size(n: int) -> tuple[float, float]:
    """Figure size [inch] of :func:`draw_polar_maps` for ``n`` cases (3 per row at most)."""
    from .figstyle import PAGE_WIDTH_IN

    ncol = max(1, min(n, 3))
    w = min(PAGE_WIDTH_IN / ncol, 4.6)
    return w * ncol, 0.95 * w * 2 * (-(-max(n, 1) // ncol))


def draw_polar_maps(
    fig: Any,
    labels: Sequence[str],
    maps: tuple[Sequence[np.ndarray], Sequence[np.ndarray]],
    edges: tuple[np.ndarray, np.ndarray],
    s0_max: Sequence[float | None] | None = None,
) -> None:
    """S0 maps above DOP maps, one column per case, wrapped three cases to a row.

    Parameters
    ----------
    fig : matplotlib Figure
        Empty; sized by :func:`polar_maps_size`.
    labels : sequence of str
        One per case (literal text).
    maps : (sequence of arrays, sequence of arrays)
        The S0 [sr^-1] and the DOP [1] maps, (n_theta, n_phi) each.
    edges : (array, array)
        theta_r and phi_r bin edges [deg].
    s0_max : sequence of float or None, optional
        Top of each S0 scale. The cases share the kind of scale: all log when one needs
        it (:func:`map_scale`), so that side-by-side maps read alike.
    """
    s0, dop = maps
    n = max(1, len(labels))
    ncol = min(n, 3)
    nblk = -(-n // ncol)
    axes = fig.subplots(2 * nblk, ncol, subplot_kw={"projection": "polar"}, squeeze=False)
    tops = [None if s0_max is None else s0_max[j] for j in range(len(labels))]
    log = any(map_scale(s0[j], tops[j])["log"] for j in range(len(labels)))
    for j in range(nblk * ncol):
        pair = (axes[2 * (j // ncol), j % ncol], axes[2 * (j // ncol) + 1, j % ncol])
        if j >= len(labels):
            pair[0].set_visible(False)
            pair[1].set_visible(False)
            continue
        label = text(labels[j])
        scale = map_scale(s0[j], tops[j], log=log)
        draw_polar_pair(pair, (label, label), (s0[j], dop[j]), scale, edges)
    fig.text(
        0.01,
        0.0,
        r"angle: $\varphi_r$ [deg] (specular at 180); radius: $\theta_r$ [deg]",
        va="top",
    )


def draw_polar_pair(
    axes: tuple[Any, Any],
    titles: tuple[str, str],
    maps: tuple[np.ndarray, np.ndarray],
    sc: Mapping[str, Any],
    edges: tuple[np.ndarray, np.ndarray],
) -> None:
    """An S0 map and a DOP map on polar Axes, each with its colour bar.

    ``maps`` = (S0 [sr^-1], DOP [1]), ``sc`` the S0 scale (:func:`map_scale`; the colour
    bar says "log scale" when it is one, with arrows where bins lie beyond it), ``edges``
    = (theta_r, phi_r) bin edges [deg].
    """
    s0, dop = maps
    fig = axes[0].figure
    s0_name = r"$S_0$ [sr$^{-1}$]" + (f", {sc['note']}" if sc["note"] else "")
    over = bool(np.nanmax(np.asarray(s0, float), initial=0.0) > sc["vmax"])
    s0_ext = ("both" if over else "min") if sc["log"] else ("max" if over else "neither")
    for ax, title, data, name, cmap, lim, log, ext in (
        (axes[0], titles[0], s0, s0_name, "inferno", (sc["vmin"], sc["vmax"]), sc["log"], s0_ext),
        (axes[1], titles[1], dop, "DOP [1]", "viridis", (0.0, 1.0), False, "neither"),
    ):
        mesh = draw_polar_map(
            ax, data, *edges, title=title, cmap=cmap, vmin=lim[0], vmax=lim[1], log=log
        )
        fig.colorbar(mesh, ax=ax, shrink=0.8, pad=0.12, extend=ext).set_label(name)


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
