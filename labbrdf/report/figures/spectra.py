"""Curves against wavelength, and plain x-y curves.

Fitted parameters with their intervals (:func:`spectra_figure`), hemispherical reflectance
(:func:`hemispherical_figure`), a spectrum as measured and as used (:func:`spectrum_figure`),
and any labelled lines or points (:func:`xy_figure`).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import matplotlib.pyplot as plt
import numpy as np

from ..._plotting import COLOURS as _COLOURS
from ..._plotting import MARKERS as _MARKERS
from ..._plotting import text as _text
from ...figstyle import grid_shape, styled
from ._common import finish, finish_below

__all__ = ["hemispherical_figure", "spectra_figure", "spectrum_figure", "xy_figure"]


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
    return finish_below(fig, axes[0, 0], title)


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
    return finish(fig, ax, title)


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
    return finish(fig, ax, title)


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
    return finish(fig, ax, title)
