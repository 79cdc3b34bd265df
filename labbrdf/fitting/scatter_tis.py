"""Total integrated scatter of a fitted model against that of a measured scatter grid.

Workflow layer: takes a ``.bsdf`` table (:class:`labbrdf.adapters.zemax_bsdf.BsdfTable`)
and a model with its fitted values, and puts side by side, for every angle of incidence,
the file's own TIS, the grid integral of the measurement
(:func:`labbrdf.integrate.grid_integral`), the same grid integral of the model evaluated on
the file's grid (the like-for-like comparison: same nodes, same cells, same uncovered
part of the hemisphere) and the model's TIS over the whole hemisphere (its closed form
where it has one, :meth:`labbrdf.models.Model.hemispherical`, else quadrature).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from ..bsdf_geometry import scatter_to_angles
from ..integrate import grid_integral, hemispherical_reflectance
from ..models import Model

__all__ = ["model_on_grid", "tis_comparison"]


def model_on_grid(
    model: Model,
    params: Mapping[str, float] | None,
    theta_i_deg: NDArray[np.float64],
    azimuth_deg: NDArray[np.float64],
    radial_deg: NDArray[np.float64],
    wavelength_nm: float | None = None,
) -> NDArray[np.float64]:
    """The model's BSDF [sr^-1] on a scatter grid, ``(aoi, azimuth, radial)``; 0 below the horizon.

    The grid is that of a ``.bsdf`` file: specular angles, scatter azimuths and radial
    angles about the specular direction [deg] (:func:`labbrdf.bsdf_geometry.scatter_to_angles`).
    """
    ti = np.asarray(theta_i_deg, float)
    tr, pr, above = scatter_to_angles(
        ti[:, None, None],
        np.asarray(radial_deg, float)[None, None, :],
        np.asarray(azimuth_deg, float)[None, :, None],
    )
    tib = np.broadcast_to(ti[:, None, None], tr.shape)
    f = model.evaluate(
        np.radians(tib),
        np.radians(np.where(above, tr, 0.0)),
        np.radians(pr),
        wavelength=wavelength_nm,
        params=params,
    )
    return np.where(above, np.asarray(f, float), 0.0)


def tis_comparison(
    model: Model, params: Mapping[str, float] | Any | None, table: Any
) -> pd.DataFrame:
    """TIS of the measurement and of the fitted model, per block of a ``.bsdf`` table.

    Parameters
    ----------
    model : Model
        The fitted model (e.g. ``labbrdf.models.get("abg")``).
    params : mapping or Parameters or None
        Its fitted values (``FitResult.params``); None: the model's current values.
    table : BsdfTable
        The file's numbers (:func:`labbrdf.adapters.zemax_bsdf.read_table`).

    Returns
    -------
    DataFrame
        One row per rotation, channel and angle of incidence: ``rotation_deg``,
        ``channel``, ``theta_i_deg``, ``tis_file`` (the file's TIS line), ``grid_measured``
        and ``grid_model`` (the grid integral of the measured and of the model's values on
        the file's grid) [1], ``ratio`` = grid_model / grid_measured, ``tis_model`` (the
        model's integral over the whole hemisphere) [1] and ``uncovered_fraction`` (of the
        projected solid angle, outside the grid).
    """
    ti, az, rad = table.theta_i_deg, table.azimuth_deg, table.radial_deg
    vals = model.values(params)
    f = model_on_grid(model, vals, ti, az, rad, table.wavelength_nm)
    meas = grid_integral(table.values, ti, az, rad, symmetry=table.symmetry, tis=table.tis)
    mod = grid_integral(f[None, None], ti, az, rad, symmetry=table.symmetry)
    hemi = hemispherical_reflectance(model, vals, ti)
    rows = []
    for r, rot in enumerate(table.rotation_deg):
        for c, ch in enumerate(table.channels):
            for a, t in enumerate(ti):
                gm, gf = float(meas["integral"][r, c, a]), float(mod["integral"][0, 0, a])
                rows.append(
                    {
                        "rotation_deg": float(rot),
                        "channel": ch,
                        "theta_i_deg": float(t),
                        "tis_file": float(meas["tis"][r, c, a]),
                        "grid_measured": gm,
                        "grid_model": gf,
                        "ratio": gf / gm if gm else np.nan,
                        "tis_model": float(hemi[a]),
                        "uncovered_fraction": float(meas["uncovered_fraction"][a]),
                    }
                )
    return pd.DataFrame(rows)
