"""Measured BRDF scans beside fitted models.

Per-incidence scans with their residuals (:func:`scan_figure`) and two models against one
measurement (:func:`compare_models_figure`).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import matplotlib.pyplot as plt

from ..._plotting import COLOURS as _COLOURS
from ..._plotting import draw_scan, legend_outside
from ..._plotting import text as _text
from ...figstyle import PAGE_WIDTH_IN, grid_shape, styled
from ._common import finish_below, layout, to_uri

__all__ = ["scan_figure", "compare_models_figure"]


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
    layout(fig, title)
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
    return finish_below(fig, axes[0, 0], title)
