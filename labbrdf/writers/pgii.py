"""Export to pab-opto pgII ASCII files: a model at one incidence, ``theta phi BSDF`` lines.

Workflow layer, the counterpart of the reader :mod:`labbrdf.adapters.pab_mountain` (one file
per incident direction, incident and scattered angles in one frame, the source's azimuth
``inphi`` 0 so that ``phi = phi_r``).
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ..outputs import atomic_output, check_file_output

__all__ = ["model_to_pgii"]

#: the default grid [deg]: theta 0..89 step 1, phi 0..355 step 5
THETA_DEG = tuple(float(x) for x in range(90))
PHI_DEG = tuple(float(x) for x in range(0, 360, 5))


def model_to_pgii(
    model: Any,
    params: Mapping[str, float] | Any,
    path: str | os.PathLike[str],
    *,
    theta_i_deg: float,
    wavelength_nm: float | None = None,
    theta_deg: ArrayLike = THETA_DEG,
    phi_deg: ArrayLike = PHI_DEG,
) -> Path:
    """Evaluate a labbrdf model at one incidence and write it as a pgII ASCII file.

    Parameters
    ----------
    model : labbrdf.models.Model
        E.g. ``labbrdf.models.get("smooth3")``.
    params : mapping or Parameters
        Parameter values (None: the model's current values).
    path : str or path-like
        Output file (``.txt``), checked before any work and written atomically through
        :mod:`labbrdf.outputs`.
    theta_i_deg : float
        The incidence [deg] in [0, 90) (``#incident_angle theta_i 0``).
    wavelength_nm : float, optional
        Passed to the model [nm]; the format has no wavelength field, so it is written in
        a ``#wavelength_nm`` comment line (which the reader keeps in ``meta["header"]``).
    theta_deg, phi_deg : array_like
        The scattered directions [deg]: theta from the normal in [0, 90), phi with the
        source at 0.

    Returns
    -------
    pathlib.Path
        The file written.
    """
    target = check_file_output(path, suffixes=(".txt",))
    th = np.atleast_1d(np.asarray(theta_deg, float))
    ph = np.atleast_1d(np.asarray(phi_deg, float))
    if not 0.0 <= float(theta_i_deg) < 90.0 or th.min() < 0 or th.max() >= 90:
        raise ValueError("expected theta_i in [0, 90) and theta in [0, 90) deg")
    g_th, g_ph = (a.ravel() for a in np.meshgrid(th, ph, indexing="ij"))
    f = np.broadcast_to(
        np.asarray(
            model.evaluate(
                np.radians(float(theta_i_deg)),
                np.radians(g_th),
                np.radians(g_ph),
                wavelength=wavelength_nm,
                params=params,
            ),
            float,
        ),
        g_th.shape,
    )
    if not np.isfinite(f).all():
        raise ValueError("the model is not finite on the grid")
    name = getattr(model, "name", type(model).__name__)
    lines = [
        f'#sample_name "labbrdf model {name}"',
        "#format: theta phi BSDF",
        f"#incident_angle {float(theta_i_deg)!r} 0",
        "#colorimetry: CIE-Y",
        *([f"#wavelength_nm {float(wavelength_nm)!r}"] if wavelength_nm else []),
    ]
    lines += [
        f"{float(t)!r}\t{float(p)!r}\t{float(v)!r}" for t, p, v in zip(g_th, g_ph, f, strict=True)
    ]
    with atomic_output(target) as tmp, open(tmp, "w", encoding="ascii", newline="\n") as fh:
        fh.write("\n".join(lines) + "\n")
    return target
