"""Three-parameter smooth-sample reflectance model of Zou, Bai and Wu (2013).

Physics layer: numpy only.

References
----------
.. [1] Zou X., Bai L., Wu Z., "Mirror reflectance spectrum modeling of smooth samples",
   Acta Optica Sinica 33(6), 0612008 (2013). doi:10.3788/AOS201333.0612008
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.special import erf

from .base import Model, ModelError, Parameters

__all__ = ["Smooth3", "smooth3_brdf"]


def smooth3_brdf(
    theta_i: NDArray, theta_r: NDArray, k1: float, k2: float, k3: float
) -> NDArray[np.float64]:
    """Zou-Bai-Wu 3-parameter reflectance, eq. (7) of [1]_.

    ``R = k1 / (8 cos(theta_i) cos(theta_r)) * exp(-(theta_i - theta_r - k2)**2 / k3**2)``

    Parameters
    ----------
    theta_i, theta_r : array_like
        Incidence and detector polar angles from the mean normal [rad]; ``theta_r`` on the
        specular side (the specular direction is ``theta_r = theta_i``).
    k1 : float
        Amplitude [1].
    k2 : float
        Lobe shift: the peak sits at ``theta_r = theta_i - k2`` [rad].
    k3 : float
        1/e half-width of the lobe in ``theta_r`` [rad], > 0.

    Returns
    -------
    ndarray
        Reflectance per steradian [sr^-1]; ``inf`` at ``theta = pi/2`` where the cosine vanishes.
    """
    ti = np.asarray(theta_i, dtype=float)
    tr = np.asarray(theta_r, dtype=float)
    with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
        return k1 / (8.0 * np.cos(ti) * np.cos(tr)) * np.exp(-(((ti - tr - k2) / k3) ** 2))


def smooth3_lobe_integral(theta_i: ArrayLike, k2: float, k3: float) -> NDArray[np.float64]:
    """``I(theta_i) = int_0^{pi/2} exp(-(theta_i - k2 - t)^2 / k3^2) sin t dt`` in closed form.

    ``I = Im{k3 e^{ic} e^{-k3^2/4} (sqrt(pi)/2) [erf(u1 - i k3/2) - erf(u0 - i k3/2)]}`` with
    ``c = theta_i - k2``, ``u0 = -c/k3``, ``u1 = (pi/2 - c)/k3`` (docs/models.md 1.2).

    Parameters
    ----------
    theta_i : array_like
        Incidence angle [rad].
    k2 : float
        Lobe shift [rad].
    k3 : float
        Lobe 1/e half-width [rad], > 0.

    Returns
    -------
    ndarray
        I [1], in (0, 1).
    """
    if not k3 > 0:
        raise ValueError(f"k3 must be > 0 [rad]; got {k3!r}")
    c = np.asarray(theta_i, dtype=float) - k2
    w = 0.5j * k3
    diff = erf((math.pi / 2 - c) / k3 - w) - erf(-c / k3 - w)
    return np.imag(k3 * np.exp(1j * c - k3**2 / 4) * (math.sqrt(math.pi) / 2) * diff)


def smooth3_hemispherical(
    theta_i_deg: ArrayLike, k1: float, k2: float, k3: float
) -> NDArray[np.float64]:
    """Closed-form directional-hemispherical reflectance of the smooth3 model.

    ``rho(ti) = 2 pi int_0^{pi/2} R cos(tr) sin(tr) d tr = pi k1 I(ti) / (4 cos ti)``
    with R of eq. (7) of Zou et al. (2013) taken as an azimuth-independent BRDF and ``I`` from
    :func:`smooth3_lobe_integral`.

    Parameters
    ----------
    theta_i_deg : array_like
        Incidence angle [deg], in [0, 90).
    k1 : float
        Amplitude [1].
    k2, k3 : float
        Lobe shift and 1/e half-width [rad].

    Returns
    -------
    ndarray
        rho [1] (a fraction).

    Notes
    -----
    The paper's eq. (8) bounds this by ``2 pi k1 / 8`` and concludes that ``k1 <= 4/pi``
    conserves energy; that holds at normal incidence only (docs/models.md 1.4; see
    :func:`labbrdf.integrate.k1_max_energy`).
    """
    t = np.asarray(theta_i_deg, dtype=float)
    if not np.all(np.isfinite(t)) or np.any(t < 0) or np.any(t >= 90):
        raise ValueError(f"theta_i_deg must be finite and in [0, 90) degrees; got {theta_i_deg!r}")
    ti = np.radians(t)
    return math.pi * k1 * smooth3_lobe_integral(ti, k2, k3) / (4.0 * np.cos(ti))


def guess_smooth3(ti: NDArray, tr: NDArray, y: NDArray) -> dict[str, float]:
    """Starting values for smooth3 from a quadratic fit of log(8 y cos ti cos tr) in ti - tr.

    Eq. (7) of Zou et al. (2013) is log-quadratic in d = ti - tr [rad]:
    ``log(8 R cos ti cos tr) = (log k1 - k2^2/k3^2) + (2 k2/k3^2) d - d^2/k3^2``, so an
    ordinary least-squares parabola gives (k1, k2, k3) when its curvature is negative.
    Returns {} when it is not (noise-dominated scans).
    """
    ok = y > 0
    if ok.sum() < 4:
        return {}
    d = (ti - tr)[ok]
    if np.ptp(d) == 0:
        return {}
    z = np.log(8 * y[ok] * np.cos(ti[ok]) * np.cos(tr[ok]))
    a2, a1, a0 = np.polyfit(d, z, 2)
    if not a2 < 0:
        return {}
    k3 = 1.0 / math.sqrt(-a2)
    k2 = a1 * k3**2 / 2
    k1 = math.exp(a0 + (k2 / k3) ** 2)
    return {"k1": k1, "k2": k2, "k3": k3} if math.isfinite(k1) else {}


class Smooth3(Model):
    """3-parameter smooth-sample model, eq. (7) of Zou, Bai, Wu 2013.

    ``R = k1 / (8 cos theta_i cos theta_r) exp(-(theta_i - theta_r - k2)^2 / k3^2)`` [sr^-1],
    with one parameter triple per wavelength.

    Parameters (docs/models.md 1.5): ``k1`` [1] in [0, 5] (linear, may be profiled out),
    ``k2`` [rad] in [-0.5, 0.5], ``k3`` [rad] in [1e-3, pi/2] searched on a log scale.

    Notes
    -----
    The paper's model is in-plane; here it is used as a BRDF without azimuth dependence
    (``phi_r`` is ignored), which is how its hemispherical integral (paper Table 3) was made.
    The model is reciprocal iff ``k2 == 0`` (docs/models.md 1.3), contrary to the paper's
    claim. Energy is conserved only over a finite incidence range, not for ``k1 <= 4/pi`` as
    the paper's eq. (8) states (docs/models.md 1.4; see :mod:`labbrdf.integrate`).
    On the specular line only ``k1 exp(-k2^2/k3^2)`` is identifiable.
    """

    name = "smooth3"
    reference = (
        "Zou X., Bai L., Wu Z., Mirror reflectance spectrum modeling of smooth "
        "samples, Acta Optica Sinica 33(6) 0612008 (2013), eq. (7)"
    )
    doi = "10.3788/AOS201333.0612008"
    linear = ("k1",)
    # on theta_r == theta_i only k1 exp(-k2^2/k3^2) is identifiable (docs/models.md 1.1)
    specular_line_shape = ("k2", "k3")
    reciprocity_note = "smooth3 is reciprocal only for k2 = 0."
    # the paper's model is of the plane of incidence (a specular scan): fits to points out
    # of that plane are told so (Model.outside_domain)
    domain = "specular_plane"

    def __init__(self, **options: Any) -> None:
        if options:
            raise ModelError(f"model 'smooth3' takes no options; got {sorted(options)}")
        super().__init__()

    def default_params(self) -> Parameters:
        """Defaults near the paper's OSR 550 nm fit; bounds of docs/models.md 1.5."""
        p = Parameters()
        p.add("k1", 1.0, 0.0, 5.0, units="1", description="amplitude")
        p.add("k2", 0.0, -0.5, 0.5, units="rad", description="lobe shift (peak at ti - k2)")
        p.add(
            "k3",
            0.4,
            1e-3,
            math.pi / 2,
            units="rad",
            log=True,
            description="1/e half-width of the lobe",
        )
        return p

    def _evaluate(
        self,
        p: Mapping[str, float],
        theta_i: NDArray,
        theta_r: NDArray,
        phi_r: NDArray,
        wavelength: NDArray | None,
    ) -> NDArray:
        _check_k3(p["k3"])
        return smooth3_brdf(theta_i, theta_r, p["k1"], p["k2"], p["k3"])

    def linear_components(
        self,
        p: Mapping[str, float],
        theta_i: NDArray,
        theta_r: NDArray,
        phi_r: NDArray,
        wavelength: NDArray | None,
    ) -> dict[str, NDArray] | None:
        """``{"k1": R / k1}``: the model is exactly linear in k1."""
        _check_k3(p["k3"])
        return {"k1": smooth3_brdf(theta_i, theta_r, 1.0, p["k2"], p["k3"])}

    def lobe_width(self, p: Mapping[str, float]) -> float:
        """Angular scale of the lobe in theta_r [rad] (a quadrature hint): ``k3``."""
        return float(p["k3"])

    def lobe_centre(self, p: Mapping[str, float], theta_i: float) -> float:
        """Polar angle of the lobe peak [rad] (a quadrature hint): ``theta_i - k2``."""
        return float(theta_i - p["k2"])

    def is_reciprocal(self, params: Mapping[str, float] | None = None) -> bool:
        """True iff ``k2 == 0`` (docs/models.md 1.3)."""
        return self.values(params)["k2"] == 0.0

    def guess(self, theta_i: NDArray, theta_r: NDArray, value: NDArray) -> dict[str, float]:
        """A parabola through log R in ``theta_i - theta_r`` (:func:`guess_smooth3`)."""
        return guess_smooth3(theta_i, theta_r, value)

    def hemispherical(
        self, theta_i_deg: ArrayLike, params: Mapping[str, float] | None = None
    ) -> NDArray[np.float64]:
        """The closed form :func:`smooth3_hemispherical` (docs/models.md 1.2)."""
        p = self.values(params)
        return smooth3_hemispherical(theta_i_deg, p["k1"], p["k2"], p["k3"])


def _check_k3(k3: float) -> None:
    if not k3 > 0:
        raise ModelError(f"smooth3 parameter 'k3' must be > 0 [rad]; got {k3!r}")
