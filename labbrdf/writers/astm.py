"""Export to ASTM E1392-style BRDF tables (``.astm``): a model on in-plane or full grids.

Workflow layer, the counterpart of the reader :mod:`labbrdf.adapters.astm_brdf` (layout,
radians, ``phi_r = phi_s - phi_i``): one comma-separated row per direction, the incident
azimuth 0, the value column named by the wavelength (``633nm``), ``NUM_POINTS`` stated so a
cut file is refused.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ..outputs import atomic_output, check_file_output

__all__ = ["model_to_astm"]

#: the default grid [deg]: the plane of incidence, theta_r 0..89 step 1 on both sides
THETA_R_DEG = tuple(float(x) for x in range(90))
PHI_R_DEG = (0.0, 180.0)


def model_to_astm(
    model: Any,
    params: Mapping[str, float] | Any,
    path: str | os.PathLike[str],
    *,
    theta_i_deg: ArrayLike,
    wavelength_nm: float,
    theta_r_deg: ArrayLike = THETA_R_DEG,
    phi_r_deg: ArrayLike = PHI_R_DEG,
) -> Path:
    """Evaluate a labbrdf model on a grid and write it as an ASTM-style BRDF table.

    Parameters
    ----------
    model : labbrdf.models.Model
        E.g. ``labbrdf.models.get("smooth3")``.
    params : mapping or Parameters
        Parameter values (None: the model's current values).
    path : str or path-like
        Output file (``.astm``), checked before any work and written atomically through
        :mod:`labbrdf.outputs`.
    theta_i_deg : array_like
        Incidences [deg] in [0, 90).
    wavelength_nm : float
        Passed to the model and written as the value column's name [nm].
    theta_r_deg, phi_r_deg : array_like
        The scattered directions [deg]: theta in [0, 90], phi with the source at 0; by
        default the plane of incidence (phi 0 and 180), theta 0..89 step 1.

    Returns
    -------
    pathlib.Path
        The file written.

    Raises
    ------
    ValueError
        Angles out of range, a wavelength that is not > 0, or a model value that is not
        finite.
    """
    target = check_file_output(path, suffixes=(".astm",))
    ti = np.atleast_1d(np.asarray(theta_i_deg, float))
    tr = np.atleast_1d(np.asarray(theta_r_deg, float))
    pr = np.atleast_1d(np.asarray(phi_r_deg, float))
    if ti.min() < 0 or ti.max() >= 90 or tr.min() < 0 or tr.max() > 90:
        raise ValueError("expected theta_i in [0, 90) and theta_r in [0, 90] deg")
    if not (np.isfinite(wavelength_nm) and wavelength_nm > 0):
        raise ValueError(f"wavelength_nm={wavelength_nm!r}: expected a number > 0")
    g_ti, g_tr, g_pr = (a.ravel() for a in np.meshgrid(ti, tr, pr, indexing="ij"))
    f = np.asarray(
        model.evaluate(
            np.radians(g_ti),
            np.radians(g_tr),
            np.radians(g_pr),
            wavelength=wavelength_nm,
            params=params,
        ),
        float,
    )
    f = np.broadcast_to(f, g_ti.shape)
    if not np.isfinite(f).all():
        raise ValueError("the model is not finite on the grid")
    name = getattr(model, "name", type(model).__name__)
    lines = [
        f'NAME "labbrdf model {name}"',
        f"NUM_POINTS {g_ti.size}",
        f"VARS theta_i,phi_i,theta_s,phi_s,{float(wavelength_nm):g}nm",
    ]
    rad = np.radians(np.stack([g_ti, np.zeros_like(g_ti), g_tr, np.mod(g_pr, 360.0)], axis=1))
    lines += [",".join(repr(float(x)) for x in (*a, v)) for a, v in zip(rad, f, strict=True)]
    with atomic_output(target) as tmp, open(tmp, "w", encoding="ascii", newline="\n") as fh:
        fh.write("\n".join(lines) + "\n")
    return target
