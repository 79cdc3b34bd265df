"""Pieces every distribution module shares: Smith G1 from Lambda, the slope-fit root finder.

Physics layer: numpy (scipy's ``brentq`` imported where it is used). A distribution module
(:mod:`~labbrdf.microfacet.ggx`, :mod:`~labbrdf.microfacet.beckmann`, or a new one) writes
its own formulas (D, Lambda, the slope densities and their likelihood) and calls these for
what does not depend on them:

- :func:`tan2`: ``tan^2 theta`` of a direction from its cosine, safe at the pole;
- :func:`both_ways`: Lambda below the horizon, ``Lambda(w) = -1 - Lambda(-w)`` [2]_;
- :func:`smith_g1`: ``G1 = 1 / (1 + Lambda)`` above the horizon, 0 below ([1]_, sec. 5,
  the form the tracer uses);
- :func:`score_root`: the root of an increasing score equation in ``s = alpha^2``,
  bracketed by factors of 4 and polished by Brent's method (a maximum-likelihood slope
  fit without a closed form);
- :func:`sum_log`: ``sum(ln(s + q))`` with one temporary (log-likelihoods of the
  Student-t family of slope densities, GGX among them).

References
----------
.. [1] Heitz E., "Understanding the masking-shadowing function in microfacet-based BRDFs",
   JCGT 3(2) (2014), sec. 5.
.. [2] Heitz E., Hanika J., d'Eon E., Dachsbacher C., "Multiple-scattering microfacet BSDFs
   with the Smith model", ACM TOG 35(4) (2016).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["both_ways", "score_root", "smith_g1", "sum_log", "tan2"]


def tan2(wz: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The cosines as an array and ``tan^2 theta = (1 - wz^2) / wz^2`` [1] of each.

    ``wz^2`` is kept above 1e-300, so that a horizontal direction gives a huge finite
    ``tan^2`` rather than a division by zero.
    """
    z = np.asarray(wz, dtype=float)
    z2 = np.maximum(z * z, 1e-300)
    return z, np.maximum(1.0 - z2, 0.0) / z2


def both_ways(z: NDArray[np.float64], lam: NDArray[np.float64]) -> NDArray[np.float64]:
    """Lambda for upward (``z >= 0``) and downward directions from its upward value ``lam``.

    ``Lambda(w) = -1 - Lambda(-w)`` below the horizon [2]_, so that the height sampling of
    the multiple-scattering walk works in both directions.
    """
    return np.where(z >= 0, lam, -1.0 - lam)


def smith_g1(
    smith_lambda: Callable[[ArrayLike, float | NDArray[np.float64]], NDArray[np.float64]],
    wz: ArrayLike,
    alpha: float | NDArray[np.float64],
) -> NDArray[np.float64]:
    """Smith masking ``G1 = 1 / (1 + Lambda(|wz|))`` for wz > 0, else 0 [1].

    Parameters
    ----------
    smith_lambda : callable
        The distribution's ``smith_lambda(wz, alpha)``.
    wz : array_like
        Cosine of the direction to the macroscopic normal [1].
    alpha : float or ndarray
        Roughness [1].
    """
    z = np.asarray(wz, dtype=float)
    lam = smith_lambda(np.abs(z), alpha)
    return np.where(z > 0, 1.0 / (1.0 + lam), 0.0)


def score_root(g: Callable[[float], float], s0: float, lo_lim: float, hi_lim: float) -> float:
    """The root of an increasing function ``g`` of ``s = alpha^2`` within [lo_lim, hi_lim].

    The root is bracketed by stepping a factor 4 up or down from ``s0`` (clipped to the
    limits first), then polished by Brent's method to a relative 1e-13 inside the bracket.

    Parameters
    ----------
    g : callable
        The score function, increasing in s (e.g. ``mean(s / (s + q)) - 1/2`` for GGX).
    s0 : float
        Where to start, e.g. the mean of the squared slopes [1].
    lo_lim, hi_lim : float
        Limits of the search [1], ``0 < lo_lim < hi_lim``.

    Returns
    -------
    float
        The root [1].
    """
    from scipy import optimize  # imported here: the command line starts without scipy

    s0 = min(max(s0, lo_lim), hi_lim)
    lo = hi = s0
    if g(s0) < 0:
        while g(hi) < 0 and hi < hi_lim:
            lo, hi = hi, min(hi * 4.0, hi_lim)
    else:
        while g(lo) > 0 and lo > lo_lim:
            lo, hi = max(lo / 4.0, lo_lim), lo
    return float(optimize.brentq(g, lo, hi, xtol=1e-300, rtol=1e-13))


def sum_log(q: NDArray, s: float) -> float:
    """``sum(ln(s + q))`` with one temporary."""
    t = q + s
    np.log(t, out=t)
    return float(np.sum(t))
