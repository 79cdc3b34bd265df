"""Export to Ansys Speos ``.anisotropicbsdf`` text files: arrays and fitted models.

Workflow layer, the counterpart of :mod:`labbrdf.writers.zemax` for Speos. The layout, the
normal-reference angles (theta from the normal, phi = 0 at the specular direction, so
``phi = phi_r - 180``) and the units (tables proportional to the BRDF, scaled by the spectrum
so that the table at the spectrum's incidence integrates to its coefficient) are those of
the reader, :mod:`labbrdf.adapters.speos_bsdf`. The writer puts the BRDF [sr-1] itself in the
tables and, as the spectrum, the hemispherical integral ``int f cos(theta) d omega`` of the
first incidence's table (the reader's trapezoid rule) x 100 [%], at the one wavelength of the
model: the reader then gives back the values written.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..adapters.speos_bsdf import MAGIC, SpeosTable, hemispherical_integral
from ..outputs import atomic_output, check_file_output

__all__ = ["binned_to_speos", "model_to_speos", "write_speos_bsdf"]

#: the default table grid [deg]: theta from the normal step 1, phi step 5
THETA_DEG = tuple(float(x) for x in range(91))
PHI_DEG = tuple(float(x) for x in range(0, 361, 5))
#: the wavelength label written when none is given [nm] (the photopic peak, as for .bsdf)
DEFAULT_WAVELENGTH_NM = 555.0


def _grid(name: str, a: ArrayLike, lo: float, hi: float) -> NDArray[np.float64]:
    v = np.atleast_1d(np.asarray(a, float))
    if v.ndim != 1 or not np.isfinite(v).all() or v.min() < lo or v.max() > hi:
        raise ValueError(f"{name}: expected finite angles in [{lo:g}, {hi:g}] deg")
    if v.size > 1 and not np.all(np.diff(v) > 0):
        raise ValueError(f"{name}: expected strictly increasing angles")
    return v


def _spectrum_pct(values: NDArray[np.float64], theta: Any, phi: Any, ti: Any) -> float:
    """100 x the hemispherical integral of the first incidence's table [%]."""
    t = SpeosTable(
        version="v8.0",
        anisotropy_vector=np.array([0.0, 1.0, 0.0]),
        rotation_deg=np.zeros(1),
        theta_i_deg=ti,
        theta_deg=theta,
        phi_deg=phi,
        values=values[None],
        spectrum_direction_deg=(float(ti[0]), 0.0),
        wavelength_nm=np.ones(1),
        coefficient_pct=np.ones(1),
    )
    pct = 100.0 * float(hemispherical_integral(t)[0, 0])
    if not 0.0 < pct <= 100.0:
        raise ValueError(
            f"the table at incidence {ti[0]:g} deg integrates to {pct / 100:.6g}: a Speos "
            "spectrum needs a reflectance in (0, 1]"
        )
    return pct


def write_speos_bsdf(
    path: str | os.PathLike[str],
    *,
    theta_i_deg: ArrayLike,
    theta_deg: ArrayLike,
    phi_deg: ArrayLike,
    values: ArrayLike,
    wavelength_nm: float | None = None,
    comment: str = "labbrdf",
    description: str = "",
) -> Path:
    """Write a Speos ``.anisotropicbsdf`` text file (reflection, one anisotropy angle).

    Parameters
    ----------
    path : str or path-like
        Output file (``.anisotropicbsdf``), checked before any work and written
        atomically through :mod:`labbrdf.outputs` (under a write policy, an existing file
        is refused unless overwriting).
    theta_i_deg : array_like
        Incidences [deg], increasing in [0, 90); the first is the spectrum's.
    theta_deg, phi_deg : array_like
        The table grid [deg]: polar angle from the normal in [0, 90], azimuth in [0, 360]
        with the specular direction at 0.
    values : array_like
        ``(incidence, theta, phi)`` BRDF [sr-1], finite and >= 0.
    wavelength_nm : float, optional
        The spectrum's one wavelength [nm]; by default :data:`DEFAULT_WAVELENGTH_NM`.
    comment, description : str
        The comment line and the measurement description (one line each).

    Returns
    -------
    pathlib.Path
        The file written.

    Raises
    ------
    ValueError
        A grid out of range, values of the wrong shape or negative, or a first table
        whose integral is not a reflectance in (0, 1].
    """
    target = check_file_output(path, suffixes=(".anisotropicbsdf",))
    ti = _grid("theta_i_deg", theta_i_deg, 0.0, 89.999999)
    th = _grid("theta_deg", theta_deg, 0.0, 90.0)
    ph = _grid("phi_deg", phi_deg, 0.0, 360.0)
    v = np.asarray(values, float)
    if v.shape != (ti.size, th.size, ph.size) or not np.isfinite(v).all() or v.min() < 0:
        raise ValueError(
            f"values: expected finite BRDF >= 0 of shape {(ti.size, th.size, ph.size)}, "
            f"got {v.shape}"
        )
    wl = DEFAULT_WAVELENGTH_NM if wavelength_nm is None else float(wavelength_nm)
    if not (np.isfinite(wl) and wl > 0):
        raise ValueError(f"wavelength_nm={wavelength_nm!r}: expected a number > 0")
    pct = _spectrum_pct(v, th, ph, ti)
    one_line = [s.replace("\n", " ").replace("\r", " ") for s in (comment, description)]
    lines = [
        f"{MAGIC} v8.0",
        "0",
        one_line[0],
        str(len(one_line[1])),
        one_line[1],
        "0\t1\t0",
        "1\t0",
        "1",
        "1",
        "0",
        str(ti.size),
        "\t".join(repr(float(a)) for a in ti),
        f"{float(ti[0])!r}\t0",
        "",
        "1",
        f"{wl!r}\t{pct!r}",
    ]
    head = "\t" + "\t".join(repr(float(p)) for p in ph)
    for block in v:
        lines += [f"{th.size} {ph.size}", head]
        lines += [
            repr(float(t)) + "\t" + "\t".join(repr(float(x)) for x in row)
            for t, row in zip(th, block, strict=True)
        ]
    lines.append("End of file")
    with atomic_output(target) as tmp, open(tmp, "w", encoding="ascii", newline="\n") as fh:
        fh.write("\n".join(lines) + "\n")
    return target


def model_to_speos(
    model: Any,
    params: Mapping[str, float] | Any,
    path: str | os.PathLike[str],
    *,
    theta_i_deg: ArrayLike,
    theta_deg: ArrayLike = THETA_DEG,
    phi_deg: ArrayLike = PHI_DEG,
    wavelength_nm: float | None = None,
) -> Path:
    """Evaluate a labbrdf model on the Speos grid and write it (see :func:`write_speos_bsdf`).

    Table point ``(theta, phi)`` at incidence ``theta_i`` is the dataset direction
    ``theta_r = theta``, ``phi_r = phi + 180`` (source at 0).

    Parameters
    ----------
    model : labbrdf.models.Model
        E.g. ``labbrdf.models.get("smooth3")``.
    params : mapping or Parameters
        Parameter values (None: the model's current values).
    path : str or path-like
        Output file.
    theta_i_deg, theta_deg, phi_deg : array_like
        The grid [deg]; by default theta 0..90 step 1 and phi 0..360 step 5.
    wavelength_nm : float, optional
        Passed to the model's ``evaluate`` and written as the spectrum's wavelength [nm].
    """
    ti = np.atleast_1d(np.asarray(theta_i_deg, float))
    th = np.atleast_1d(np.asarray(theta_deg, float))
    ph = np.atleast_1d(np.asarray(phi_deg, float))
    f = model.evaluate(
        np.radians(ti[:, None, None]),
        np.radians(th[None, :, None]),
        np.radians(np.mod(ph[None, None, :] + 180.0, 360.0)),
        wavelength=wavelength_nm,
        params=params,
    )
    v = np.broadcast_to(np.asarray(f, float), (ti.size, th.size, ph.size))
    name = getattr(model, "name", type(model).__name__)
    return write_speos_bsdf(
        path,
        theta_i_deg=ti,
        theta_deg=th,
        phi_deg=ph,
        values=v,
        wavelength_nm=wavelength_nm,
        comment=f"labbrdf model {name}",
        description=f"labbrdf model {name}, BRDF [sr-1] at {wavelength_nm or '-'} nm",
    )


def binned_to_speos(
    path: str | os.PathLike[str],
    *,
    theta_i_deg: float,
    values: ArrayLike,
    theta_edges_deg: ArrayLike,
    phi_edges_deg: ArrayLike,
    wavelength_nm: float | None = None,
    comment: str = "labbrdf trace",
) -> Path:
    """Write a BRDF binned on a (theta_r, phi_r) grid (a tracer's S0) as a Speos file.

    The table's nodes are the bin centres (theta), and the bin centres' azimuths turned to
    the normal reference (``phi = phi_r - 180``, sorted): the values are written as binned,
    without interpolation.

    Parameters
    ----------
    path : str or path-like
        Output file (see :func:`write_speos_bsdf`).
    theta_i_deg : float
        Angle of incidence [deg].
    values : array_like, shape (n_theta, n_phi)
        Bin-averaged BRDF [sr^-1], e.g. :meth:`labbrdf.TraceResult.s0`; empty bins (NaN)
        are written as 0.
    theta_edges_deg, phi_edges_deg : array_like
        Bin edges [deg], ``n_theta + 1`` in [0, 90] and ``n_phi + 1`` in [0, 360] (source
        at 0).
    wavelength_nm : float, optional
        The spectrum's wavelength [nm].
    comment : str
        The comment line.

    Notes
    -----
    The spectrum is the trapezoid integral over the span of the bin centres, so a trace
    whose bins do not reach the pole or the horizon states a slightly smaller reflectance
    than its rays carried; the reader scales back by the same integral, so the values read
    are the values written.
    """
    te = np.asarray(theta_edges_deg, float)
    pe = np.asarray(phi_edges_deg, float)
    v = np.nan_to_num(np.asarray(values, float), nan=0.0)
    if v.shape != (te.size - 1, pe.size - 1):
        raise ValueError(f"values: expected shape {(te.size - 1, pe.size - 1)}, got {v.shape}")
    theta = 0.5 * (te[1:] + te[:-1])
    phi = np.mod(0.5 * (pe[1:] + pe[:-1]) - 180.0, 360.0)
    order = np.argsort(phi)
    return write_speos_bsdf(
        path,
        theta_i_deg=[float(theta_i_deg)],
        theta_deg=theta,
        phi_deg=phi[order],
        values=v[None][..., order],
        wavelength_nm=wavelength_nm,
        comment=comment,
        description=comment,
    )
