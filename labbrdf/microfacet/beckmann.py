"""Beckmann microfacet distribution: D, Smith Lambda and G1, P22, slope fit.

Physics layer: numpy (and scipy's erf). ``alpha`` is the Beckmann roughness [1]: ``alpha^2/2``
is the variance of each slope component, so ``alpha = RMS slope of |grad z| = sqrt(<x^2 +
y^2>)``. The tracer traces Beckmann through its slope table
(:meth:`labbrdf.microfacet.TabulatedNDF.of`), which gives D, Lambda and the visible-normal
sampling from this module's :func:`p22`.

References
----------
.. [1] Walter B., Marschner S. R., Li H., Torrance K. E., "Microfacet models for refraction
   through rough surfaces", Proc. EGSR 2007, eqs. (25), (27). doi:10.2312/EGWR/EGSR07/195-206
.. [2] Heitz E., "Understanding the masking-shadowing function in microfacet-based BRDFs",
   JCGT 3(2) (2014), sec. 5.2.
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
    "smith_g1",
    "smith_lambda",
]

NAME = "beckmann"
LABEL = "Beckmann"
#: largest slope of the distribution's slope table, in units of alpha
TABLE_EXTENT = 6.0
#: the tracer traces Beckmann through its slope table (no closed-form sampler here)
TRACED_IN_CLOSED_FORM = False


def d(cos_m: ArrayLike, alpha: float) -> NDArray[np.float64]:
    """Distribution of normals ``D = exp(-tan^2/a^2) / (pi a^2 cos^4)`` [sr^-1], eq. (25) of [1]_.

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
        tan2 = (1.0 - c2) / c2
        dd = np.exp(-tan2 / alpha**2) / (np.pi * alpha**2 * c2 * c2)
    return np.where(c > 0, dd, 0.0)


def smith_lambda(wz: ArrayLike, alpha: float | NDArray[np.float64]) -> NDArray[np.float64]:
    """Smith Lambda for a direction with cosine ``wz`` [1], eq. (27) of [1]_.

    ``Lambda = (erf(a) - 1) / 2 + exp(-a^2) / (2 a sqrt(pi))`` with
    ``a = 1 / (alpha tan theta)`` for wz > 0; ``Lambda(w) = -1 - Lambda(-w)`` below.
    """
    from scipy import special  # imported here: the command line starts without scipy

    z, t2 = parts.tan2(wz)
    tan = np.sqrt(t2)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        a = 1.0 / (alpha * tan)
        lam = 0.5 * (special.erf(a) - 1.0) + np.exp(-a * a) / (2.0 * a * math.sqrt(math.pi))
    lam = np.where(np.isfinite(a), lam, 0.0)
    return parts.both_ways(z, lam)


def smith_g1(wz: ArrayLike, alpha: float | NDArray[np.float64]) -> NDArray[np.float64]:
    """Smith masking ``G1 = 1 / (1 + Lambda)`` for wz > 0, else 0."""
    return parts.smith_g1(smith_lambda, wz, alpha)


def p22(x: NDArray, y: NDArray, alpha: float) -> NDArray[np.float64]:
    """Slope density ``P22 = exp(-r^2/a^2) / (pi a^2)`` [1] of slopes (x, y)."""
    return np.exp(-(x * x + y * y) / alpha**2) / (np.pi * alpha**2)


def p2(x: NDArray, alpha: float) -> NDArray[np.float64]:
    """Marginal density of one slope component, ``exp(-x^2/a^2) / (a sqrt(pi))`` [1]."""
    t = (x / alpha) ** 2
    return np.exp(-t) / (alpha * np.sqrt(np.pi))


def radial_density(r: NDArray, alpha: float) -> NDArray[np.float64]:
    """Density of the slope magnitude ``r = |grad z|``, ``2 r / a^2 exp(-r^2/a^2)`` [1]."""
    t = (r / alpha) ** 2
    return 2 * r / alpha**2 * np.exp(-t)


# ------------------------------------------------------------------ slope fit of a height map
def ml_s(q: NDArray, areal: bool) -> float:
    """Maximum-likelihood ``s = alpha^2`` of squared slopes ``q`` [1].

    ``mean(q)`` (2-D, ``q = x^2 + y^2``) or ``2 mean(q)`` (1-D marginal, ``q = x^2``).
    """
    return float(q.mean()) if areal else float(2 * q.mean())


def log_likelihood(q: NDArray, s: float, n: int, areal: bool) -> float:
    """Log-likelihood of ``n`` slopes with squares ``q`` at ``s = alpha^2``.

    2-D: ``log P22 = -ln(pi s) - q/s``; 1-D: ``log P2 = -ln(pi s)/2 - q/s``.
    """
    if areal:
        return float(-n * math.log(math.pi * s) - np.sum(q) / s)
    return float(-0.5 * n * math.log(math.pi * s) - np.sum(q) / s)


def ks_cdf(s: float, areal: bool) -> Callable[[NDArray], NDArray]:
    """CDF of the squared radial slope ``q`` (2-D) or of the slope x (1-D) at ``s``."""
    from scipy import special  # imported here: the command line starts without scipy

    if areal:
        return lambda v: -np.expm1(-v / s)
    return lambda v: 0.5 * (1 + special.erf(v / math.sqrt(s)))


def fisher_information(q: NDArray, s: float, n: int, areal: bool) -> float:
    """Observed Fisher information of ``s`` for ``n`` independent slopes."""
    return n / s**2 if areal else n / (2 * s**2)
