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

import dataclasses
from collections.abc import Mapping
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from ..bsdf_geometry import scatter_to_angles
from ..integrate import grid_integral, hemispherical_reflectance
from ..models import Model

__all__ = ["model_on_grid", "speos_tis_comparison", "tis_comparison"]


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


def speos_tis_comparison(
    model: Model,
    params: Mapping[str, float] | Any | None,
    table: Any,
    wavelength_nm: float,
) -> pd.DataFrame:
    """TIS of the measurement and of the fitted model, per incidence of a Speos table.

    The like-for-like comparison of :func:`tis_comparison` on a Speos
    ``.anisotropicbsdf`` grid: the measurement's integral ``int f cos(theta) d omega`` by
    the reader's trapezoid rule (``labbrdf.adapters.speos_bsdf.hemispherical_integral``)
    with the reader's scaling (the table at the spectrum's incidence integrates to the
    stated coefficient), and the model's on the same nodes.

    Parameters
    ----------
    model : Model
        The fitted model.
    params : mapping or Parameters or None
        Its fitted values.
    table : SpeosTable
        The file's numbers (:func:`labbrdf.adapters.speos_bsdf.read_speos_table`),
        reflection tables of the first sample rotation.
    wavelength_nm : float
        The spectrum's wavelength [nm] whose coefficient scales the tables.

    Returns
    -------
    DataFrame
        One row per incidence: ``theta_i_deg``, ``tis_file`` (the stated coefficient at the
        spectrum's incidence, else NaN), ``grid_measured``, ``grid_model``, ``ratio`` and
        ``tis_model`` (the model over the whole hemisphere) [1].
    """
    from ..adapters.speos_bsdf import hemispherical_integral

    ti = np.asarray(table.theta_i_deg, float)
    th, ph = np.asarray(table.theta_deg, float), np.asarray(table.phi_deg, float)
    k = int(np.argmin(np.abs(np.asarray(table.wavelength_nm, float) - wavelength_nm)))
    coef = float(table.coefficient_pct[k]) / 100.0
    ref = float(table.spectrum_direction_deg[0])
    raw = hemispherical_integral(table)[0]
    meas = raw * coef / float(raw[int(np.argmin(np.abs(ti - ref)))])
    vals = model.values(params)
    tt, pp = np.meshgrid(np.radians(th), np.radians(ph + 180.0), indexing="ij")
    f = np.stack(
        [
            np.asarray(model.evaluate(np.radians(t), tt, pp, wavelength=wavelength_nm,
                                      params=vals), float)
            for t in ti
        ]
    )  # fmt: skip
    mod = hemispherical_integral(dataclasses.replace(table, values=f[None]))[0]
    hemi = hemispherical_reflectance(model, vals, ti)
    return pd.DataFrame(
        {
            "theta_i_deg": ti,
            "tis_file": np.where(np.isclose(ti, ref), coef, np.nan),
            "grid_measured": meas,
            "grid_model": mod,
            "ratio": mod / np.where(meas > 0, meas, np.nan),
            "tis_model": np.asarray(hemi, float),
        }
    )
