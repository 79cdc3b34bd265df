"""Panels and plots of n, k tables: one panel per series member (time, stage position)."""

from __future__ import annotations

from typing import Any

import numpy as np
import pandas as pd

_SERIES = ("time_s", "x_mm", "y_mm")


def series_members(table: pd.DataFrame) -> list[tuple[str, pd.DataFrame]]:
    """(label, rows) per member of a series (time or spot) of an n, k table, or the whole.

    The label names the member (``"time 12"``, ``"x 3 y 4"``), empty when the table is no
    series (module Grouping).
    """
    keys = [k for k in _SERIES if k in table.columns]
    if not keys:
        return [("", table)]
    out = []
    for key, g in table.groupby(keys, sort=True, dropna=False):
        key = key if isinstance(key, tuple) else (key,)
        lab = ", ".join(f"{k.split('_')[0]} {v:g}" for k, v in zip(keys, key, strict=True))
        out.append((lab, g))
    return out


def nk_panels(table: pd.DataFrame, *, max_series: int | None = None) -> list[dict[str, Any]]:
    """The two panels (n, k against wavelength) that draw an n, k table.

    Parameters
    ----------
    table : pandas.DataFrame
        A :func:`combined_table` (one line per series member, shaded +-1 sigma band) or an
        :func:`nk_table` (one series per angle of incidence, 1-sigma error bars).
    max_series : int, optional
        Draw at most this many members or angles (the first ones).

    Returns
    -------
    list of dict
        Panel descriptions (``title``, ``xlabel``, ``ylabel``, ``series``), as the
        report's ``panels_figure`` and :func:`plot_table` draw them.
    """
    if not {"wavelength_nm", "n", "k", "n_sigma", "k_sigma"} <= set(table.columns):
        raise ValueError(
            "not an n, k table: expected the columns wavelength_nm, n, k, n_sigma, k_sigma "
            f"(of nk_table or combined_table), got {list(table.columns)}"
        )
    per_angle = "theta_i_deg" in table.columns
    if per_angle:
        p = table.assign(theta=table["theta_i_deg"].round(2))
        groups = [(f"\u03b8i {th:g}\u00b0", g) for th, g in p.groupby("theta", sort=True)]
    else:
        groups = series_members(table)
    groups = groups[:max_series] if max_series is not None else groups
    by_wl = table["wavelength_nm"].round(6).nunique() > 1
    panels = []
    for q in ("n", "k"):
        series = []
        for lab, g in groups:
            s: dict[str, Any] = {
                "label": lab,
                "x": g["wavelength_nm"].to_numpy(float),
                "y": g[q].to_numpy(float),
            }
            if per_angle:
                s["yerr"] = g[f"{q}_sigma"].to_numpy(float)
                s["style"] = "points" if g["wavelength_nm"].nunique() < 3 else "line"
            else:
                s["band"] = g[f"{q}_sigma"].to_numpy(float)
                s["style"] = "line" if by_wl else "points"
            series.append(s)
        panels.append(
            {
                "title": f"pseudo-{q} per angle of incidence" if per_angle else f"combined {q}",
                "xlabel": "wavelength [nm]",
                "ylabel": f"<{q}> [1]" if per_angle else f"{q} [1]",
                "series": series,
            }
        )
    return panels


def plot_table(table: pd.DataFrame, ax: Any = None) -> Any:
    """n and k against wavelength with their 1-sigma uncertainties, for notebooks.

    Parameters
    ----------
    table : pandas.DataFrame
        A :func:`combined_table` (lines with shaded +-1 sigma bands, one per series member)
        or an :func:`nk_table` (the pseudo-constants, one series per angle of incidence,
        with 1-sigma error bars). The report's n, k figures draw the same panels
        (:func:`nk_panels`).
    ax : pair of matplotlib Axes, optional
        Where to draw n and k; default a new figure with two side-by-side axes.

    Returns
    -------
    numpy.ndarray of matplotlib Axes
        The n and the k axes.

    Raises
    ------
    ValueError
        The table lacks the n, k columns.

    Examples
    --------
    >>> from labbrdf import nk  # doctest: +SKIP
    >>> nk.plot_table(nk.combined_table(measurement))  # doctest: +SKIP
    """
    from .._plotting import draw_panel  # matplotlib only when drawing

    panels = nk_panels(table)
    if ax is None:
        import matplotlib.pyplot as plt

        _, ax = plt.subplots(1, 2, figsize=(9.2, 3.4), layout="constrained")
    axes = np.asarray(ax, dtype=object).ravel()
    if axes.size != 2:
        raise ValueError(f"ax: expected two Axes (n, k), got {axes.size}")
    for a, panel in zip(axes, panels, strict=True):
        draw_panel(a, panel)
    return axes
