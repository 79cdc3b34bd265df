"""Measured hemispherical BRDF against a model: maps, residual maps and in-plane cuts."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import matplotlib.pyplot as plt
import numpy as np

from ..._brdf_maps import (
    draw_brdf_maps,
    draw_disc,
    is_half,
    map_panels,
    maps_size,
    triangulate,
)
from ..._plotting import COLOURS as _COLOURS
from ..._plotting import text as _text
from ...figstyle import PAGE_WIDTH_IN, grid_shape, styled
from ._common import finish_below, to_uri

__all__ = ["brdf_cuts_figure", "brdf_maps_figure", "brdf_residual_grid_figure", "fit_maps_figure"]


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
    return finish_below(fig, axes[0, 0], title)


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
