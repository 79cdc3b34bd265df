"""Slopes of a height map and the maximum-likelihood fits of their distribution.

Pure NumPy/SciPy. Forward-difference slopes paired at the same corner, the shape
statistics of a sample (skewness, kurtosis, KS distance to the Gaussian), and the fit of
every distribution of :data:`labbrdf.microfacet.registry.DISTRIBUTIONS` to the slopes
(:func:`fit_slope_distribution`: ML alpha, observed-Fisher uncertainty, log-likelihood,
AIC, KS distance), each distribution's formulas taken from its module.

References
----------
Walter B. et al., "Microfacet models for refraction through rough surfaces", EGSR 2007
(GGX and Beckmann slope distributions).
Heitz E., "Understanding the masking-shadowing function in microfacet-based BRDFs",
JCGT 3(2) (2014) (slope-space densities P22, marginals).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import special

from ..jsonsafe import jsonable
from ..microfacet import DISTRIBUTIONS
from .levelling import _CHUNK

__all__ = ["KS_WARN", "SlopeFit", "SlopeFits", "fit_slope_distribution", "slopes"]

#: KS distance above which neither GGX nor Beckmann is said to describe the slopes.
KS_WARN = 0.05


def slopes(
    z: NDArray, pixel_size: tuple[float, ...], valid: NDArray | None = None
) -> tuple[NDArray, NDArray | None]:
    """Forward-difference slopes at the valid corner points.

    Parameters
    ----------
    z : ndarray
        Heights [m], 1-D or 2-D.
    pixel_size : tuple of float
        Grid spacing [m] per axis.
    valid : ndarray of bool, optional
        Valid points (default: finite ones).

    Returns
    -------
    sx, sy : ndarray
        1-D arrays of dz/dx and dz/dy [1] at the points (i, j), i < M-1, j < N-1, where
        h[i, j], h[i+1, j] and h[i, j+1] are all valid (``sy`` is None for a profile).
    """
    if valid is None:
        valid = np.isfinite(z)
    if z.ndim == 1:
        ok = valid[1:] & valid[:-1]
        return ((z[1:] - z[:-1]) / pixel_size[0])[ok], None
    ok = valid[:-1, :-1] & valid[1:, :-1] & valid[:-1, 1:]
    sx = (z[1:, :-1] - z[:-1, :-1]) / pixel_size[0]
    sy = (z[:-1, 1:] - z[:-1, :-1]) / pixel_size[1]
    return sx[ok], sy[ok]


def _ks_sorted(xs: NDArray, cdf: Any) -> float:
    """Two-sided KS distance sup|F_n - F| of sorted samples to the CDF ``cdf``.

    Walked in blocks of :data:`_CHUNK` samples, so that no array of the sample's size
    beyond ``xs`` itself is made.
    """
    n = xs.size
    d = -np.inf
    for a in range(0, n, _CHUNK):
        f = cdf(xs[a : a + _CHUNK])
        i = np.arange(a, a + f.size, dtype=float)
        d = max(d, float(np.max((i + 1) / n - f)), float(np.max(f - i / n)))
    return float(d)


def _shape_stats(x: NDArray) -> tuple[float, float, float]:
    """Skewness, kurtosis (3 for a Gaussian) and KS distance to the Gaussian.

    The moment estimators of :func:`scipy.stats.skew` and :func:`scipy.stats.kurtosis`
    (biased, ``m3 / m2^1.5`` and ``m4 / m2^2``), formed with two temporaries.
    """
    s = x.std() if x.size >= 3 else 0.0
    if s == 0:
        return float("nan"), float("nan"), float("nan")
    d = x - x.mean()
    d2 = d * d
    m2 = float(np.mean(d2))
    m3 = float(np.dot(d2, d)) / x.size
    m4 = float(np.dot(d2, d2)) / x.size
    del d2
    d /= s  # standardised: the KS distance to N(0, 1)
    d.sort()
    return m3 / m2**1.5, m4 / m2**2, _ks_sorted(d, special.ndtr)


# ------------------------------------------------------------------ slope-space fits
@dataclass(frozen=True)
class SlopeFit:
    """Maximum-likelihood fit of one slope distribution.

    Attributes
    ----------
    model : str
        ``"ggx"`` or ``"beckmann"``.
    alpha : float
        Roughness [1].
    alpha_u : float
        Standard uncertainty [1] (observed Fisher information for independent slopes; the
        block jackknife when fitted inside :func:`roughness_statistics`).
    loglik : float
        Log-likelihood at the optimum (densities in slope space).
    aic : float
        ``2 k - 2 loglik`` with k = 1.
    ks : float
        KS distance of the radial slope |s| (2-D) or of the slope (profile) [1].
    n : int
        Number of slopes.
    """

    model: str
    alpha: float
    alpha_u: float
    loglik: float
    aic: float
    ks: float
    n: int


@dataclass(frozen=True)
class SlopeFits:
    """The fits of every registered distribution to one slope sample.

    Attributes
    ----------
    fits : dict of str to SlopeFit
        One fit per name of :data:`labbrdf.microfacet.registry.DISTRIBUTIONS`, in registry order;
        also readable as attributes (``fits.ggx``, ``fits.beckmann``).
    best : str
        The name with the smallest AIC (the first of equal ones).
    warning : str or None
        Set when no distribution describes the slopes (every KS distance above
        ``ks_threshold``).
    ks_threshold : float
        :data:`KS_WARN`.
    """

    fits: dict[str, SlopeFit]
    best: str
    warning: str | None
    ks_threshold: float = KS_WARN

    def __getattr__(self, name: str) -> SlopeFit:
        fits = self.__dict__.get("fits", {})
        if name in fits:
            return fits[name]
        raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")

    def to_dict(self) -> dict[str, Any]:
        """JSON-safe dict: one entry per distribution, then best, warning, ks_threshold."""
        d: dict[str, Any] = {name: asdict(fit) for name, fit in self.fits.items()}
        d.update(best=self.best, warning=self.warning, ks_threshold=self.ks_threshold)
        return jsonable(d)


def _fit_core(x: NDArray, y: NDArray | None) -> dict[str, float]:
    """ML alphas, log-likelihoods and KS distances (no uncertainties) of every distribution.

    Keys ``"<name>_alpha"``, ``"<name>_loglik"``, ``"<name>_ks"`` and ``"<name>_s"``
    (``s = alpha^2``) for each name of :data:`labbrdf.microfacet.registry.DISTRIBUTIONS`.

    Raises
    ------
    ValueError
        All slopes are zero (a map without roughness at the pixel scale).
    """
    n = x.size
    areal = y is not None
    q = x * x
    if y is not None:
        q += y * y
    s = {name: dist.ml_s(q, areal) for name, dist in DISTRIBUTIONS.items()}
    _check_slopes(s)
    ll = {name: dist.log_likelihood(q, s[name], n, areal) for name, dist in DISTRIBUTIONS.items()}
    if areal:  # KS of the squared radial slope
        q.sort()
        sample = q
    else:  # KS of the slope itself
        del q
        sample = np.sort(x)
    out: dict[str, float] = {}
    for name, dist in DISTRIBUTIONS.items():
        out[name + "_alpha"] = math.sqrt(s[name])
        out[name + "_loglik"] = ll[name]
        out[name + "_ks"] = _ks_sorted(sample, dist.ks_cdf(s[name], areal))
        out[name + "_s"] = s[name]
    return out


def _check_slopes(s: dict[str, float]) -> None:
    if not all(v > 0 for v in s.values()):
        raise ValueError("all slopes are zero: the heights do not change between pixels")


def _fisher_u(x: NDArray, y: NDArray | None, core: dict[str, float]) -> dict[str, float]:
    """Observed-information standard uncertainties of the ML alphas (independent slopes)."""
    n = x.size
    q = x * x + (y * y if y is not None else 0.0)
    out = {}
    for name, dist in DISTRIBUTIONS.items():
        s = core[name + "_s"]
        j = dist.fisher_information(q, s, n, y is not None)
        # alpha = sqrt(s): u(alpha) = u(s) / (2 alpha)
        out[name] = (1.0 / math.sqrt(j)) / (2 * math.sqrt(s)) if j > 0 else float("nan")
    return out


def _make_fits(core: dict[str, float], u: dict[str, float], n: int) -> SlopeFits:
    fits = {}
    for m in DISTRIBUTIONS:
        ll = core[m + "_loglik"]
        fits[m] = SlopeFit(m, core[m + "_alpha"], u[m], ll, 2.0 - 2.0 * ll, core[m + "_ks"], n)
    best = next(iter(fits))
    for m in fits:  # the first of the smallest AIC
        if not fits[best].aic <= fits[m].aic:
            best = m
    warning = None
    if min(f.ks for f in fits.values()) > KS_WARN:
        each = " nor ".join(f"{DISTRIBUTIONS[m].LABEL} (KS {f.ks:.3f})" for m, f in fits.items())
        warning = (
            f"neither {each} describes the slope distribution: "
            f"{'both' if len(fits) == 2 else 'all'} KS distances exceed {KS_WARN}"
        )
    return SlopeFits(fits, best, warning)


def fit_slope_distribution(x: ArrayLike, y: ArrayLike | None = None) -> SlopeFits:
    """Fit GGX and Beckmann alphas to slopes by maximum likelihood.

    Parameters
    ----------
    x : array_like
        Slopes dz/dx [1].
    y : array_like, optional
        Slopes dz/dy [1] at the same points; without them the 1-D marginal densities are
        fitted (a profile; the alpha then assumes an isotropic surface).

    Returns
    -------
    SlopeFits
        Both fits with observed-Fisher uncertainties (valid for independent slopes),
        log-likelihood, AIC, KS distance; ``warning`` when both KS distances exceed
        :data:`KS_WARN`.

    Notes
    -----
    Slope-space densities (Walter et al. 2007; Heitz 2014, sec. 5.2):
    GGX ``P22 = 1 / (pi a^2 (1 + r^2/a^2)^2)``, Beckmann ``P22 = exp(-r^2/a^2)/(pi a^2)``,
    r^2 = x^2 + y^2. Their x marginals are ``1 / (2 a (1 + x^2/a^2)^(3/2))`` and
    ``exp(-x^2/a^2) / (sqrt(pi) a)``. With s = a^2 the score equations are
    ``mean(s/(s + r^2)) = 1/2`` (GGX 2-D), ``= 2/3`` (GGX 1-D), ``s = mean(r^2)``
    (Beckmann 2-D), ``s = 2 mean(x^2)`` (Beckmann 1-D). GGX has infinite slope variance,
    so its alpha is not a moment; the ML fit is what defines it.
    """
    xa = np.asarray(x, dtype=float).ravel()
    ya = None if y is None else np.asarray(y, dtype=float).ravel()
    ok = np.isfinite(xa) if ya is None else np.isfinite(xa) & np.isfinite(ya)
    xa = xa[ok]
    ya = None if ya is None else ya[ok]
    if xa.size < 2 or not np.any(xa != 0) and (ya is None or not np.any(ya != 0)):
        raise ValueError("need at least 2 finite, not all zero slopes")
    core = _fit_core(xa, ya)
    return _make_fits(core, _fisher_u(xa, ya, core), xa.size)
