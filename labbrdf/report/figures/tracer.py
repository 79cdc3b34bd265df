"""The tracer's hemisphere maps of S0 and DOP, in the report and as a PNG of a trace."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import matplotlib.pyplot as plt
import numpy as np

from ..._plotting import draw_polar_maps, polar_maps_size
from ...figstyle import styled
from ._common import finish_grid, save_png, to_uri

__all__ = ["polar_maps_figure", "save_trace_maps_png"]


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
    return finish_grid(fig, title)


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
