"""Harvey-Shack scatter model: the K-correlation form in direction cosines.

Physics layer: numpy only (the TIS quadrature is :func:`labbrdf.models.abg.shift_invariant_tis`).

``f = b0 (1 + |beta - beta0|^2 / L^2)^(S/2)`` [sr^-1] (+ ``kd / pi`` with ``diffuse``), with
``beta`` and ``beta0`` the projected direction cosines of the scatter and specular
directions as in :mod:`labbrdf.models.abg` (and the same transmission form). ``b0`` is the
BSDF at the specular direction, ``L`` the knee (the ``|beta - beta0|`` at which the curve
turns over) and ``S`` (< 0) the log-log slope of the wing. Through the grating equation
``f_spatial = (beta - beta0) / lambda`` it is the K-correlation (ABC) power spectrum
``PSD(f) = A / (1 + (B f)^2)^(C/2)`` of a smooth surface (``L = lambda / B``,
``S = -C``), shift-invariant in direction cosines like ABg, but with a finite correlation
length in place of ABg's ``B``. It is the form of FRED's "Harvey-Shack" scatter type
(``b0``, ``L``, ``S``).

References
----------
.. [1] Harvey J. E., Vernold C. L., "Transfer function characterization of scattering
   surfaces: revisited", Proc. SPIE 3141, 113-127 (1997). doi:10.1117/12.279238
.. [2] Church E. L., Takacs P. Z., Leonard T. A., "The prediction of BRDFs from surface
   profile measurements", Proc. SPIE 1165, 136-150 (1989) (the K-correlation PSD).
   doi:10.1117/12.962842
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .abg import ABg, shift_invariant_tis
from .base import ModelError, Parameters

__all__ = ["HarveyShack", "knee_integral"]


def knee_integral(radius: ArrayLike, L: float, S: float) -> NDArray[np.float64]:
    """``int_0^R rho (1 + rho^2 / L^2)^(S/2) d rho`` in closed form [1].

    ``L^2 ((1 + R^2/L^2)^(S/2 + 1) - 1) / (S + 2)``, and ``L^2 ln(1 + R^2/L^2) / 2`` at
    ``S = -2`` (elementary: substitute ``u = 1 + rho^2 / L^2``).
    """
    r = np.asarray(radius, dtype=float)
    u = np.log1p((r / L) ** 2)
    e = 0.5 * S + 1.0
    if abs(e) < 1e-12:
        return 0.5 * L**2 * u
    return L**2 * np.expm1(e * u) / (2.0 * e)


class HarveyShack(ABg):
    """Harvey-Shack (K-correlation in direction cosines), ``b0 (1 + |beta - beta0|^2/L^2)^(S/2)``.

    Other Parameters
    ----------------
    transmission : bool, default False
        The transmission form, for BTDF data (as :class:`labbrdf.models.abg.ABg`).
    diffuse : bool, default False
        Add a Lambertian floor ``kd / pi`` [sr^-1].

    Parameters: ``b0`` [sr^-1] in [0, 1e4] (linear; the fitting core flags a value within
    1e-6 of the range, 0.01 sr^-1, as at its bound), ``L`` [1] in [1e-6, 1] (log), ``S`` [1]
    in [-6, -0.05]; with ``diffuse``, ``kd`` [1] in [0, 1] (linear).

    Notes
    -----
    Reciprocal for the same reason as ABg (``|beta - beta0| = |beta_s + beta_i|``).
    """

    name = "harvey_shack"
    amplitude = "b0"
    reference = (
        "Harvey J. E., Vernold C. L., Transfer function characterization of scattering "
        "surfaces: revisited, Proc. SPIE 3141 (1997); K-correlation PSD of Church et al. (1989)"
    )
    doi = "10.1117/12.279238"
    reciprocity_note = (
        "harvey_shack is reciprocal by construction (|beta - beta0| = |beta_s + beta_i| is "
        "symmetric in the two directions, and the Lambertian kd / pi is constant)."
    )
    linear: tuple[str, ...] = ("b0",)

    def __init__(self, transmission: bool = False, diffuse: bool = False, **options: Any) -> None:
        if options:
            raise ModelError(
                f"model 'harvey_shack' got unknown options {sorted(options)}; options are "
                "['diffuse', 'transmission']"
            )
        super().__init__(transmission=transmission, diffuse=diffuse)
        self.linear = ("b0", "kd") if diffuse else ("b0",)

    def default_params(self) -> Parameters:
        """b0 10, L 0.01 (log), S -2; kd 0 with ``diffuse``."""
        p = Parameters()
        p.add("b0", 10.0, 0.0, 1e4, units="sr-1", description="BSDF at the specular direction")
        p.add("L", 1e-2, 1e-6, 1.0, units="1", log=True, description="knee in |beta - beta0|")
        p.add("S", -2.0, -6.0, -0.05, units="1", description="log-log slope of the wing")
        if self._diffuse:
            p.add("kd", 0.0, 0.0, 1.0, units="1", description="Lambertian albedo")
        return p

    def lobe_width(self, p: Mapping[str, float]) -> float:
        """Angular scale of the lobe [rad] (a quadrature hint): the knee ``L``."""
        return float(min(max(p["L"], 1e-4), 0.5))

    def _scatter(self, p: Mapping[str, float], ti: NDArray, ts: NDArray, ps: NDArray) -> NDArray:
        L, S = p["L"], p["S"]
        if not L > 0:
            raise ModelError(f"harvey_shack parameter L must be > 0; got {L!r}")
        up = (np.cos(ti) > 0) & (np.cos(ts) > 0)
        x = self.delta_beta(ti, ts, ps) / L
        return np.where(up, (1.0 + x * x) ** (0.5 * S), 0.0)

    def guess(self, theta_i: NDArray, theta_r: NDArray, value: NDArray) -> dict[str, float]:
        """L from the half width of the in-plane lobe, S = -2 and b0 = the peak."""
        g = super().guess(theta_i, theta_r, value)
        if not g:
            return {}
        L = float(np.clip(math.sqrt(g["B"]), 1.1e-6, 0.9))
        return {"L": L, "S": -2.0, "b0": float(np.clip(g["A"] / g["B"], 0.0, 1e4))}

    def hemispherical(
        self, theta_i_deg: ArrayLike, params: Mapping[str, float] | None = None
    ) -> NDArray[np.float64] | None:
        """TIS [1] of the scattered part (+ ``kd``).

        :func:`labbrdf.models.abg.shift_invariant_tis` of :func:`knee_integral`.
        """
        p = self.values(params)
        b0, L, S = p["b0"], p["L"], p["S"]
        if not (L > 0 and b0 >= 0):
            raise ModelError(f"harvey_shack TIS needs b0 >= 0, L > 0; got b0={b0!r}, L={L!r}")
        tis = shift_invariant_tis(theta_i_deg, lambda r: b0 * knee_integral(r, L, S))
        if self._diffuse:
            tis = tis + p["kd"]
        return tis
