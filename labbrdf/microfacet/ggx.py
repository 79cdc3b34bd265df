"""GGX (Trowbridge-Reitz) distribution: D, Smith Lambda and G1, P22, sampling, slope fit.

Physics layer: numpy only. Directions are unit vectors of shape (3, n) in a local frame
whose +z is the macroscopic normal; functions taking ``wz`` or ``cos_m`` need only the z
component [1]. ``alpha`` is the GGX roughness [1] (not an RMS slope: GGX has infinite slope
variance).

References
----------
.. [1] Walter B., Marschner S. R., Li H., Torrance K. E., "Microfacet models for refraction
   through rough surfaces", Proc. EGSR 2007, eqs. (20), (33), (34).
   doi:10.2312/EGWR/EGSR07/195-206
.. [2] Trowbridge T. S., Reitz K. P., "Average irregularity representation of a rough surface
   for ray reflection", J. Opt. Soc. Am. 65(5), 531-536 (1975). doi:10.1364/JOSA.65.000531
.. [3] Heitz E., "Sampling the GGX distribution of visible normals", JCGT 7(4) (2018).
.. [4] Dupuy J., Benyoub A., "Sampling visible GGX normals with spherical caps", CGF 42(8)
   (2023).
.. [5] Heitz E., Hanika J., d'Eon E., Dachsbacher C., "Multiple-scattering microfacet BSDFs
   with the Smith model", ACM TOG 35(4) (2016).

Notes
-----
Eq. (14) of Dong et al. 2022 omits alpha^2 in the numerator of D (``docs/errata.md``);
:func:`d` uses ``D = alpha^2 / (pi cos^4 g (alpha^2 + tan^2 g)^2)``, which integrates to 1
over the projected hemisphere.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import parts

__all__ = [
    "LABEL",
    "NAME",
    "TABLE_EXTENT",
    "TRACED_IN_CLOSED_FORM",
    "d",
    "fisher_information",
    "ks_cdf",
    "log_likelihood",
    "ml_s",
    "p2",
    "p22",
    "radial_density",
    "sample_cos",
    "sample_visible",
    "smith_g1",
    "smith_g1_closed",
    "smith_lambda",
]

NAME = "ggx"
LABEL = "GGX"
#: largest slope of the distribution's slope table, in units of alpha (the Smith Lambda of
#: GGX depends on the first moment of its x^-3 tail: a table cut at 50 alpha is too short)
TABLE_EXTENT = 1000.0
#: the tracer samples GGX visible normals and evaluates its Lambda in closed form
TRACED_IN_CLOSED_FORM = True


def d(cos_m: ArrayLike, alpha: float) -> NDArray[np.float64]:
    """Distribution of normals D(m) [sr^-1], eq. (33) of [1]_.

    ``D = alpha^2 / (pi (1 + (alpha^2 - 1) cos^2 theta_m)^2)``, normalised so that
    ``int D cos theta_m d omega_m = 1``.

    Parameters
    ----------
    cos_m : array_like
        Cosine of the facet-normal polar angle [1].
    alpha : float
        Roughness [1], > 0.

    Returns
    -------
    ndarray
        D [sr^-1]; 0 where ``cos_m <= 0``.
    """
    c = np.asarray(cos_m, dtype=float)
    c2 = c * c
    with np.errstate(divide="ignore", invalid="ignore"):
        dd = alpha**2 / (np.pi * (c2 * (alpha**2 - 1) + 1) ** 2)
    return np.where(c > 0, dd, 0.0)


def smith_lambda(wz: ArrayLike, alpha: float | NDArray[np.float64]) -> NDArray[np.float64]:
    """Smith Lambda for a direction with cosine ``wz`` to the normal [1].

    For upward directions (wz > 0), ``Lambda = (-1 + sqrt(1 + alpha^2 tan^2 theta)) / 2``;
    for downward ones ``Lambda(w) = -1 - Lambda(-w)`` ([5]_), so that the height sampling of
    the multiple-scattering walk works in both directions.
    """
    z, t2 = parts.tan2(wz)
    lam = 0.5 * (-1.0 + np.sqrt(1.0 + alpha * alpha * t2))
    return parts.both_ways(z, lam)


def smith_g1(wz: ArrayLike, alpha: float | NDArray[np.float64]) -> NDArray[np.float64]:
    """Smith masking ``G1 = 1 / (1 + Lambda)`` for wz > 0, else 0 (the tracer's form)."""
    return parts.smith_g1(smith_lambda, wz, alpha)


def smith_g1_closed(cos_v: ArrayLike, alpha: float) -> NDArray[np.float64]:
    """Smith masking ``G1 = 2 / (1 + sqrt(1 + alpha^2 tan^2 theta_v))``, eq. (34) of [1]_.

    Algebraically :func:`smith_g1`; this form is the one the ``microfacet`` model
    evaluates (the two differ in the last bits).

    Parameters
    ----------
    cos_v : array_like
        Cosine of the direction's polar angle [1].
    alpha : float
        Roughness [1].

    Returns
    -------
    ndarray
        G1 [1] in [0, 1]; 0 where ``cos_v <= 0``.
    """
    c = np.asarray(cos_v, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        tan2 = np.where(c > 0, (1.0 - c * c) / (c * c), np.inf)
        return np.where(c > 0, 2.0 / (1.0 + np.sqrt(1.0 + alpha**2 * tan2)), 0.0)


def p22(x: NDArray, y: NDArray, alpha: float) -> NDArray[np.float64]:
    """Slope density ``P22 = 1 / (pi a^2 (1 + r^2/a^2)^2)`` [1] of slopes (x, y)."""
    return 1.0 / (np.pi * alpha**2 * (1.0 + (x * x + y * y) / alpha**2) ** 2)


def p2(x: NDArray, alpha: float) -> NDArray[np.float64]:
    """Marginal density of one slope component, ``1 / (2 a (1 + x^2/a^2)^(3/2))`` [1]."""
    t = (x / alpha) ** 2
    return 1 / (2 * alpha * (1 + t) ** 1.5)


def radial_density(r: NDArray, alpha: float) -> NDArray[np.float64]:
    """Density of the slope magnitude ``r = |grad z|``, ``2 r / (a^2 (1 + r^2/a^2)^2)`` [1]."""
    t = (r / alpha) ** 2
    return 2 * r / alpha**2 / (1 + t) ** 2


def sample_cos(alpha: float, u1: NDArray[np.float64], u2: NDArray[np.float64]) -> NDArray:
    """Sample normals with pdf D(m) cos(theta_m), eq. (15) of Dong 2022.

    ``theta_m = arctan(alpha sqrt(u1 / (1 - u1)))``, ``phi_m = 2 pi u2``. Kept for the
    closed-form albedo test and the paper's algorithm; the tracer samples visible normals.
    """
    tan2 = alpha * alpha * u1 / (1.0 - u1)
    cos_t = 1.0 / np.sqrt(1.0 + tan2)
    sin_t = np.sqrt(np.maximum(0.0, 1.0 - cos_t * cos_t))
    phi = 2.0 * np.pi * u2
    return np.stack([sin_t * np.cos(phi), sin_t * np.sin(phi), cos_t])


def sample_visible(
    wi: NDArray[np.float64],
    alpha: float | NDArray[np.float64],
    u1: NDArray[np.float64],
    u2: NDArray[np.float64],
) -> NDArray[np.float64]:
    """Sample visible normals for the direction ``wi`` (pointing away from the surface).

    Parameters
    ----------
    wi : ndarray, shape (3, n)
        Unit directions towards where the light comes from, in the local frame; wi_z may be
        negative (a ray travelling upwards inside the microsurface).
    alpha : float or ndarray
        Roughness [1], >= 0 (0 returns the macroscopic normal).
    u1, u2 : ndarray, shape (n,)
        Uniform numbers in [0, 1).

    Returns
    -------
    ndarray, shape (3, n)
        Unit facet normals with pdf ``max(0, wi.m) D(m) / (projected area)``.

    Notes
    -----
    Stretch to the alpha = 1 configuration, sample the visible hemisphere by the spherical
    cap method ([4]_): ``h = c + v`` with ``c`` uniform on the cap ``z > -v_z``, then
    unstretch ([3]_, section 3). Valid for directions below the horizon too, which the
    multiple-scattering walk needs.
    """
    vx = alpha * wi[0]
    vy = alpha * wi[1]
    vz = wi[2]
    inv = 1.0 / np.sqrt(vx * vx + vy * vy + vz * vz)
    vx, vy, vz = vx * inv, vy * inv, vz * inv
    phi = 2.0 * np.pi * u1
    z = (1.0 - u2) * (1.0 + vz) - vz
    sin_t = np.sqrt(np.clip(1.0 - z * z, 0.0, 1.0))
    hx = alpha * (sin_t * np.cos(phi) + vx)
    hy = alpha * (sin_t * np.sin(phi) + vy)
    hz = np.maximum(z + vz, 1e-300)
    inv = 1.0 / np.sqrt(hx * hx + hy * hy + hz * hz)
    return np.stack([hx * inv, hy * inv, hz * inv])


# ------------------------------------------------------------------ slope fit of a height map
def ml_s(q: NDArray, areal: bool) -> float:
    """Maximum-likelihood ``s = alpha^2`` of squared slopes ``q`` [1].

    The root of the score equation ``mean(s / (s + q)) = 1/2`` (``q = x^2 + y^2``, 2-D) or
    ``= 2/3`` (``q = x^2``, the 1-D marginal). The left side increases with s; the root is
    bracketed by stepping a factor 4 from the mean of q (one temporary of q's size per
    evaluation), then polished by Brent's method to a relative 1e-13 inside the bracket
    (:func:`labbrdf.microfacet.parts.score_root`). 0 when every q is 0.
    """
    frac = 0.5 if areal else 2.0 / 3.0
    qpos = q[q > 0]
    if qpos.size == 0:
        return 0.0
    lo_lim, hi_lim = float(np.min(qpos)) * 1e-6, float(np.max(q)) * 1e6
    del qpos
    # q and the scratch array live in a list emptied at the end: brentq leaves g in a
    # reference cycle, which would otherwise keep both alive until the next GC
    arrays = [q, np.empty_like(q)]

    def g(s: float) -> float:
        qq, t = arrays
        np.add(qq, s, out=t)
        np.divide(s, t, out=t)
        return float(np.mean(t)) - frac

    root = parts.score_root(g, float(np.mean(q)), lo_lim, hi_lim)
    arrays.clear()
    return root


def log_likelihood(q: NDArray, s: float, n: int, areal: bool) -> float:
    """Log-likelihood of ``n`` slopes with squares ``q`` at ``s = alpha^2``.

    2-D: ``log P22 = ln s - 2 ln(s + q) - ln pi``; 1-D (the marginal):
    ``log P2 = ln s - 3/2 ln(s + q) - ln 2``.
    """
    if areal:
        return float(n * math.log(s) - 2 * parts.sum_log(q, s) - n * math.log(math.pi))
    return float(n * math.log(s) - 1.5 * parts.sum_log(q, s) - n * math.log(2.0))


def ks_cdf(s: float, areal: bool) -> Callable[[NDArray], NDArray]:
    """CDF of the squared radial slope ``q`` (2-D) or of the slope x (1-D) at ``s``."""
    if areal:
        return lambda v: v / (s + v)
    return lambda v: 0.5 + 0.5 * v / np.sqrt(s + v * v)


def fisher_information(q: NDArray, s: float, n: int, areal: bool) -> float:
    """Observed Fisher information of ``s`` for ``n`` independent slopes with squares q."""
    k = 2.0 if areal else 1.5
    return n / s**2 - k * float(np.sum(1.0 / (s + q) ** 2))
