"""Measured data as grids of panels: line/point panels, stage maps, a reflectance comparison."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import matplotlib.pyplot as plt

from ..._plotting import draw_panel
from ..._plotting import text as _text
from ...figstyle import PANEL_MIN_IN, grid_shape, styled
from ._common import finish_below, finish_grid

__all__ = ["map_figure", "panels_figure", "reflectance_comparison_figure"]


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
        return finish_below(fig, axes[0, 0], title)
    return finish_grid(fig, title)


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
    return finish_grid(fig, title)


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
