"""Roughness statistics of measured height maps and profiles, for the microfacet tracer.

Pure NumPy/SciPy: the arrays come in already read (see :mod:`labbrdf.adapters.topography`
for instrument files). Lengths are in metres throughout; slopes are dimensionless.

Pipeline (derivations in ``docs/topography.md``):

1. *Levelling* (form removal, ISO 25178-2 F-operator): the least-squares polynomial of total
   degree ``degree`` in (x, y) over the valid points is subtracted (default 1, the mean
   plane; 0 = mean only; 2 = the full quadric, SurfaceTopography's ``"curvature"``).
2. *Heights*: sigma = RMS of the levelled heights (ISO Sq; Rq for a profile), skewness,
   kurtosis (3 for a Gaussian) and the Kolmogorov-Smirnov distance to the Gaussian.
3. *Slopes*: forward differences ``(h[i+1, j] - h[i, j]) / dx`` and
   ``(h[i, j+1] - h[i, j]) / dy``, paired at the same corner ``(i, j)`` (the
   ``(M-1) x (N-1)`` points where both exist; SurfaceTopography's default non-periodic
   stencil); RMS per axis and total ``sqrt(<sx^2 + sy^2>)``.
4. *Autocorrelation* rho(tau) of the levelled heights by a mask-normalised FFT:
   ``rho = IFFT|FFT(w z)|^2 / IFFT|FFT(w)|^2``, normalised to 1 at tau = 0, with w the
   valid-point indicator and zero padding (no wrap-around); lags up to half the map.
   Correlation lengths: the 1/e crossing along x and y, and along the principal axes of
   the inertia tensor of the central region rho > 1/e (anisotropy ratio and direction);
   a Gaussian ``exp(-tau^2/c^2)`` and an exponential ``exp(-tau/c)`` fitted to the
   axis ACFs, the one with the smaller residual is reported.
5. ``alpha = sqrt(2) sigma / c`` (Dong et al. 2022, text after eq. (15); exact RMS slope
   per axis of a Gaussian-correlated surface), and maximum-likelihood GGX and Beckmann
   alphas of the slope distribution (:func:`fit_slope_distribution`).

Uncertainties: delete-one-block jackknife. The valid area is cut into ``blocks x blocks``
tiles (``blocks`` segments of a profile); each replicate repeats the *whole* pipeline
(levelling included) with one tile marked invalid. The standard uncertainty is
``sqrt((B-1)/B sum (theta_b - theta_mean)^2)``. A map only L/c correlation lengths wide
holds about (L/c)^2 independent samples, far fewer than its pixels, and the jackknife over
tiles several c wide captures this without a model of the correlation.

References
----------
Dong Z. et al., Acta Optica Sinica 42(22), 2224001 (2022) (alpha = sqrt(2) sigma / c).
Walter B. et al., "Microfacet models for refraction through rough surfaces", EGSR 2007
(GGX and Beckmann slope distributions).
Heitz E., "Understanding the masking-shadowing function in microfacet-based BRDFs",
JCGT 3(2) (2014) (slope-space densities P22, marginals).
ISO 25178-2:2012 (Sq, Ssk, Sku, Sdq); ISO 4287 (Rq, Rdq).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import asdict, dataclass, field, replace
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import fft as sfft
from scipy import ndimage, optimize, special

from ..jsonsafe import jsonable
from ..microfacet import DISTRIBUTIONS
from .levelling_sums import NormalSums

__all__ = [
    "C_MIN_PIXELS",
    "GAUSS_ALPHA",
    "KS_WARN",
    "TOP_VARIANCE_WARN",
    "erode_mask",
    "s_filter",
    "RoughnessStats",
    "SlopeFit",
    "SlopeFits",
    "autocorrelation",
    "fit_slope_distribution",
    "level",
    "on_measured_points",
    "roughness_statistics",
    "slopes",
]

#: KS distance above which neither GGX nor Beckmann is said to describe the slopes.
KS_WARN = 0.05
#: Correlation length [pixels] below which the ACF is said to be pixel-scale noise.
C_MIN_PIXELS = 2.0
#: Share of the height variance the 1 % largest squared heights may carry before a note
#: (a Gaussian surface: 8.5 %).
TOP_VARIANCE_WARN = 0.5
#: ISO 16610-61 Gaussian weighting constant, sqrt(ln 2 / pi): 50 % transmission at lambda_s.
GAUSS_ALPHA = math.sqrt(math.log(2.0) / math.pi)

_NAN_DEFAULT = float("nan")

_INV_E = math.exp(-1.0)


# --------------------------------------------------------------------------- helpers
def _as_heights(heights: ArrayLike, mask: ArrayLike | None) -> tuple[NDArray, NDArray]:
    """Float heights and the valid-point indicator (finite and not masked)."""
    z = np.ma.getdata(heights)
    z = np.array(z, dtype=float)
    valid = np.isfinite(z)
    m = np.ma.getmaskarray(heights) if np.ma.isMaskedArray(heights) else None
    if m is not None:
        valid &= ~m
    if mask is not None:
        mk = np.asarray(mask, dtype=bool)
        if mk.shape != z.shape:
            raise ValueError(f"mask shape {mk.shape} differs from heights shape {z.shape}")
        valid &= ~mk
    if z.ndim not in (1, 2):
        raise ValueError(f"heights must be a profile (1-D) or a map (2-D), got {z.ndim}-D")
    if min(z.shape) < 8:
        raise ValueError(f"heights need at least 8 points per axis, got shape {z.shape}")
    return z, valid


def _pixel(pixel_size: float | ArrayLike, ndim: int) -> tuple[float, ...]:
    p = np.broadcast_to(np.asarray(pixel_size, dtype=float), (ndim,))
    if not np.all(np.isfinite(p)) or np.any(p <= 0):
        raise ValueError(f"pixel_size must be positive and finite [m], got {pixel_size!r}")
    return tuple(float(v) for v in p)


#: Elements per block of the passes that walk a map in row blocks (bounded temporaries).
_CHUNK = 1 << 18


def _exponents(ndim: int, degree: int) -> list[tuple[int, ...]]:
    """Monomial exponents of total degree <= degree (x first, then mixed, then y)."""
    if ndim == 1:
        return [(p,) for p in range(degree + 1)]
    return [(tot - py, py) for tot in range(degree + 1) for py in range(tot + 1)]


def _row_blocks(shape: tuple[int, ...]) -> list[tuple[int, int]]:
    """Row ranges of about :data:`_CHUNK` elements (whole rows of a map)."""
    row = int(np.prod(shape[1:])) if len(shape) > 1 else 1
    step = max(1, _CHUNK // max(row, 1))
    return [(a, min(a + step, shape[0])) for a in range(0, shape[0], step)]


def _block_design(
    shape: tuple[int, ...], r0: int, r1: int, exps: list[tuple[int, ...]], v: NDArray
) -> NDArray:
    """Monomials in coordinates scaled to [-1, 1) at the valid points of rows r0:r1."""
    x = 2.0 * np.arange(r0, r1) / shape[0] - 1.0
    if len(shape) == 1:
        xs = x[v]
        return np.column_stack([xs ** e[0] for e in exps])
    y = 2.0 * np.arange(shape[1]) / shape[1] - 1.0
    xs = np.broadcast_to(x[:, None], v.shape)[v]
    ys = np.broadcast_to(y[None, :], v.shape)[v]
    return np.column_stack([xs ** e[0] * ys ** e[1] for e in exps])


def level(heights: ArrayLike, degree: int = 1, mask: ArrayLike | None = None) -> NDArray:
    """Subtract the least-squares polynomial of total degree ``degree`` (form removal).

    Parameters
    ----------
    heights : array_like, 1-D or 2-D
        Heights [m]; NaN (or masked) points are invalid.
    degree : int
        0 = mean, 1 = mean plane (default, ISO 25178 F-operator; SurfaceTopography
        ``detrend("height")``), 2 = full quadric (``detrend("curvature")``), higher on request.
    mask : array_like of bool, optional
        True where a point is invalid.

    Returns
    -------
    ndarray
        Levelled heights [m], NaN at invalid points.
    """
    z, valid = _as_heights(heights, mask)
    return _level(z, valid, degree)


def _level(z: NDArray, valid: NDArray, degree: int) -> NDArray:
    """Levelled copy of z (NaN at invalid points); normal equations summed over row blocks.

    The polynomial is fitted in coordinates scaled to [-1, 1) after removing the mean
    height, which keeps the normal equations well conditioned for the low degrees of form
    removal; no design matrix of the whole map is ever built.
    """
    if not (isinstance(degree, int | np.integer) and degree >= 0):
        raise ValueError(f"degree must be an integer >= 0, got {degree!r}")
    exps = _exponents(z.ndim, int(degree))
    k = len(exps)
    nvalid = int(np.count_nonzero(valid))
    if nvalid <= k:
        raise ValueError(f"{nvalid} valid points cannot fix a polynomial of degree {degree}")
    zmean = float(np.mean(z, where=valid))
    ata = np.zeros((k, k))
    atz = np.zeros(k)
    blocks = _row_blocks(z.shape)
    for r0, r1 in blocks:
        v = valid[r0:r1]
        a = _block_design(z.shape, r0, r1, exps, v)
        zz = z[r0:r1][v] - zmean
        ata += a.T @ a
        atz += a.T @ zz
    coef = np.linalg.lstsq(ata, atz, rcond=None)[0]
    out = np.full(z.shape, np.nan)
    for r0, r1 in blocks:
        v = valid[r0:r1]
        a = _block_design(z.shape, r0, r1, exps, v)
        out[r0:r1][v] = z[r0:r1][v] - zmean - a @ coef
    return out


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


def autocorrelation(
    z: NDArray,
    valid: NDArray | None = None,
    max_lag: tuple[int, ...] | None = None,
    *,
    hole: tuple[slice, ...] | None = None,
) -> NDArray:
    """Normalised autocorrelation by a mask-normalised, zero-padded FFT.

    Parameters
    ----------
    z : ndarray
        Levelled heights, 1-D or 2-D (invalid points anything; they get weight 0).
    valid : ndarray of bool, optional
        Valid points (default: finite).
    max_lag : tuple of int, optional
        Largest lag per axis in pixels (default: half the extent).
    hole : tuple of slice, optional
        Declares that ``valid`` is the whole grid except this rectangle (a jackknife
        replicate of a map without dropouts): the pair counts are then exact products of
        interval overlaps instead of a second FFT.

    Returns
    -------
    ndarray
        rho(tau) for lags ``-max_lag..max_lag`` per axis (zero lag at the centre);
        NaN where no pair of valid points exists.
    """
    if valid is None:
        valid = np.isfinite(z)
    if max_lag is None:
        max_lag = tuple(n // 2 for n in z.shape)
    shape = [
        sfft.next_fast_len(n + lag, real=True) for n, lag in zip(z.shape, max_lag, strict=True)
    ]
    zc = np.zeros(z.shape)
    np.subtract(z, np.mean(z, where=valid), out=zc, where=valid)
    num = _correlate_window(zc, shape, max_lag)
    del zc
    if valid.all():
        den = _rect_pair_counts(z.shape, max_lag, None)
    elif hole is not None:
        den = _rect_pair_counts(z.shape, max_lag, hole)
    else:
        den = _correlate_window(valid.astype(float), shape, max_lag)
    good = den > 0.5
    cov = np.full(num.shape, np.nan)
    cov[good] = num[good] / np.round(den[good])
    centre = tuple(max_lag)
    return cov / cov[centre]


def _rect_pair_counts(
    shape: tuple[int, ...], max_lag: tuple[int, ...], hole: tuple[slice, ...] | None
) -> NDArray:
    """Valid pairs at lags ``-max_lag..max_lag`` of a full grid F minus a rectangle T.

    With ``1_V = 1_F - 1_T`` the count ``sum_p 1_V(p) 1_V(p + l)`` is
    ``c_FF - c_FT - c_TF + c_TT``, where ``c_PQ(l) = #{p in P : p + l in Q}`` of two
    rectangles is the product over the axes of the interval overlaps
    ``|P_k ∩ (Q_k - l_k)|``: exactly what the FFT of the indicator gives, without it.
    """

    def overlap(i: tuple[int, int], j: tuple[int, int], lags: NDArray) -> NDArray:
        return np.maximum(0, np.minimum(i[1], j[1] - lags) - np.maximum(i[0], j[0] - lags))

    lags = [np.arange(-lag, lag + 1) for lag in max_lag]
    full = [(0, n) for n in shape]
    if hole is None:
        sets = [(1.0, full, full)]
    else:
        tile = [sl.indices(n)[:2] for sl, n in zip(hole, shape, strict=True)]
        sets = [(1.0, full, full), (-1.0, full, tile), (-1.0, tile, full), (1.0, tile, tile)]
    den = np.zeros(tuple(lg.size for lg in lags))
    for sign, a, b in sets:
        term = overlap(a[0], b[0], lags[0]).astype(float)
        for k in range(1, len(shape)):
            term = np.multiply.outer(term, overlap(a[k], b[k], lags[k]))
        den += sign * term
    return den


def _correlate_window(a: NDArray, shape: list[int], max_lag: tuple[int, ...]) -> NDArray:
    """Zero-padded circular autocorrelation of ``a`` at lags ``-max_lag..max_lag``.

    ``IFFT |FFT a|^2`` with the power formed in place in the spectrum, so that the padded
    transform is held once (plus its inverse), not in several temporary copies.
    """
    axes = tuple(range(a.ndim))
    f = sfft.rfftn(a, shape, axes=axes)
    re, im = f.real, f.imag
    np.square(re, out=re)
    np.square(im, out=im)
    re += im
    im[...] = 0.0
    r = sfft.irfftn(f, shape, axes=axes, overwrite_x=True)
    del f, re, im
    idx = np.ix_(*[np.r_[s - lag : s, 0 : lag + 1] for s, lag in zip(shape, max_lag, strict=True)])
    return r[idx]


def _crossing(r: NDArray, step: float) -> float:
    """First 1/e crossing of a 1-D ACF starting at lag 0 (linear interpolation) [m]."""
    below = np.nonzero(~(r > _INV_E))[0]
    if below.size == 0 or below[0] == 0:
        return float("nan")
    i = below[0]
    r0, r1 = r[i - 1], r[i]
    if not np.isfinite(r1):
        return float("nan")
    return float((i - 1 + (r0 - _INV_E) / (r0 - r1)) * step)


def _fit_acf(r: NDArray, step: float, c0: float) -> dict[str, float]:
    """Least-squares Gaussian and exponential ACF models on lags where rho > 0.05."""
    out = {}
    if not np.isfinite(c0):
        return {"gaussian": float("nan"), "exponential": float("nan")} | {
            "rms_gaussian": float("nan"),
            "rms_exponential": float("nan"),
        }
    stop = np.nonzero(~(r > 0.05))[0]
    n = int(stop[0]) if stop.size else r.size
    n = max(n, 3)
    tau = np.arange(n) * step
    rr = r[:n]
    models = {
        "gaussian": lambda c: np.exp(-((tau / c) ** 2)),
        "exponential": lambda c: np.exp(-tau / c),
    }
    for name, f in models.items():
        res = optimize.minimize_scalar(
            lambda lc, f=f: float(np.sum((f(np.exp(lc)) - rr) ** 2)),
            bounds=(math.log(c0) - 3, math.log(c0) + 3),
            method="bounded",
            options={"xatol": 1e-10},
        )
        out[name] = float(np.exp(res.x))
        out["rms_" + name] = float(np.sqrt(res.fun / n))
    return out


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


# ------------------------------------------------------------------------ statistics
@dataclass(frozen=True)
class RoughnessStats:
    """Roughness statistics of one levelled height map or profile (lengths in metres).

    Scalars are NaN where undefined (e.g. y quantities of a profile); ``uncertainty``
    maps a field name to its standard uncertainty by the block jackknife.
    """

    kind: str  # "areal" or "profile"
    shape: tuple[int, ...]
    pixel_size: tuple[float, ...]  # [m]
    levelling: str
    n_valid: int
    sigma: float  # RMS height [m]
    slope_rms_x: float  # [1]
    slope_rms_y: float  # [1]
    slope_rms: float  # total sqrt(<sx^2 + sy^2>) (profile: along x) [1]
    c_x: float  # 1/e ACF crossing along x [m]
    c_y: float
    c_major: float  # along the principal axes of the ACF inertia tensor [m]
    c_minor: float
    c: float  # sqrt(c_major c_minor) (profile: c_x) [m]
    anisotropy_ratio: float  # c_major / c_minor [1]
    anisotropy_angle_deg: float  # direction of c_major from +x towards +y [deg]
    acf_model: str  # "gaussian" or "exponential" (smaller residual)
    c_fit_x: float  # fitted length of that model along x [m]
    c_fit_y: float
    acf_rms_gaussian: float  # RMS residual of the Gaussian ACF fit [1]
    acf_rms_exponential: float
    height_skewness: float
    height_kurtosis: float  # 3 for a Gaussian
    height_ks: float
    slope_skewness_x: float
    slope_kurtosis_x: float
    slope_ks_x: float
    slope_skewness_y: float
    slope_kurtosis_y: float
    slope_ks_y: float
    alpha_gaussian_acf: float  # Dong 2022: sqrt(2) sigma / c [1]
    alpha_gaussian_acf_x: float  # sqrt(2) sigma / c_x
    alpha_gaussian_acf_y: float
    alpha_ggx_ml: float  # maximum-likelihood GGX alpha of the slopes (= slope_fits.ggx.alpha)
    slope_fits: SlopeFits
    uncertainty: dict[str, float] = field(default_factory=dict)
    n_blocks: int = 0
    notes: tuple[str, ...] = ()
    short_cutoff: float = _NAN_DEFAULT  # S-filter cut-off lambda_s [m]; NaN = none
    bandwidth: str = ""  # the wavelengths every slope and alpha refers to
    n_eroded: int = 0  # valid points dropped by eroding the mask around dropouts
    tracer_alpha: str = "alpha_ggx_ml"  # the alpha `trace --surface` uses

    def to_dict(self) -> dict[str, Any]:
        """JSON-safe dict (NaN -> None, tuples -> lists)."""
        d = asdict(self)
        d["slope_fits"] = self.slope_fits.to_dict()
        return jsonable(d)


_NAN = float("nan")


def _principal(rho: NDArray, px: tuple[float, float]) -> tuple[float, float, float, float]:
    """c_major, c_minor, ratio and angle [deg] from the inertia tensor of rho > 1/e."""
    centre = tuple(n // 2 for n in rho.shape)
    inside = np.nan_to_num(rho, nan=0.0) > _INV_E
    lab, _ = ndimage.label(inside)
    region = lab == lab[centre]
    ii, jj = np.nonzero(region)
    tx = (ii - centre[0]) * px[0]
    ty = (jj - centre[1]) * px[1]
    wgt = rho[ii, jj]
    inertia = np.array(
        [
            [np.sum(wgt * tx * tx), np.sum(wgt * tx * ty)],
            [np.sum(wgt * tx * ty), np.sum(wgt * ty * ty)],
        ]
    )
    evals, evecs = np.linalg.eigh(inertia)
    lengths = []
    for k in (1, 0):  # major first
        e = evecs[:, k]
        step = min(px)
        nmax = int(min(rho.shape[0] // 2 * px[0], rho.shape[1] // 2 * px[1]) / step)
        t = np.arange(nmax) * step
        coords = np.stack([centre[0] + t * e[0] / px[0], centre[1] + t * e[1] / px[1]])
        prof = ndimage.map_coordinates(np.nan_to_num(rho, nan=0.0), coords, order=1)
        lengths.append(_crossing(prof, step))
    cmaj, cmin = lengths
    ev = evecs[:, 1]
    ang = math.degrees(math.atan2(ev[1], ev[0]))
    ang = (ang + 90.0) % 180.0 - 90.0
    if ang == -90.0:
        ang = 90.0
    return cmaj, cmin, cmaj / cmin if cmin > 0 else _NAN, ang


def _core(
    z: NDArray,
    valid: NDArray,
    px: tuple[float, ...],
    degree: int,
    with_slopes: bool = False,
    hole: tuple[slice, ...] | None = None,
    levelled: NDArray | None = None,
) -> dict[str, Any]:
    """All statistics of one valid set (``levelled``: its levelled z, if known); scalars, fits."""
    if np.count_nonzero(valid) < 8:
        raise ValueError("fewer than 8 valid points")
    lz = _level(z, valid, degree) if levelled is None else levelled
    h = lz[valid]
    out: dict[str, Any] = {}
    out["sigma"] = float(np.sqrt(np.mean(h * h)))
    spread = float(np.sqrt(np.var(z, where=valid)))
    if not out["sigma"] > 1e-10 * spread:
        raise ValueError(
            f"all valid heights lie on the levelling polynomial (RMS height {out['sigma']:.3g}"
            f" m of {spread:.3g} m before levelling): no roughness"
        )
    out["height_skewness"], out["height_kurtosis"], out["height_ks"] = _shape_stats(h)
    if with_slopes:
        out["_top_share"] = _top_share(h)
    del h
    sx, sy = slopes(lz, px, valid)
    if sx.size < 2:
        raise ValueError("fewer than 2 valid slopes")
    out["slope_rms_x"] = float(np.sqrt(np.mean(sx * sx)))
    sk = _shape_stats(sx)
    out["slope_skewness_x"], out["slope_kurtosis_x"], out["slope_ks_x"] = sk
    if sy is not None:
        out["slope_rms_y"] = float(np.sqrt(np.mean(sy * sy)))
        out["slope_rms"] = float(np.sqrt(np.mean(sx * sx + sy * sy)))
        sk = _shape_stats(sy)
    else:
        out["slope_rms_y"] = _NAN
        out["slope_rms"] = out["slope_rms_x"]
        sk = (_NAN, _NAN, _NAN)
    out["slope_skewness_y"], out["slope_kurtosis_y"], out["slope_ks_y"] = sk
    fc = _fit_core(sx, sy)
    out["_fit"] = fc
    out["_n_slopes"] = sx.size
    if with_slopes:
        out["_fisher"] = _fisher_u(sx, sy, fc)
    del sx, sy
    out["alpha_ggx_ml"] = fc["ggx_alpha"]
    for name in DISTRIBUTIONS:
        out[name + "_alpha"] = fc[name + "_alpha"]

    rho = autocorrelation(lz, valid, hole=hole)
    centre = tuple(n // 2 for n in rho.shape)
    if z.ndim == 1:
        rx = rho[centre[0] :]
        out["c_x"] = _crossing(rx, px[0])
        out["c_y"] = _NAN
        out["c_major"] = out["c_minor"] = out["c"] = out["c_x"]
        out["anisotropy_ratio"] = out["anisotropy_angle_deg"] = _NAN
        fx = _fit_acf(rx, px[0], out["c_x"])
        fy = None
    else:
        rx = rho[centre[0] :, centre[1]]
        ry = rho[centre[0], centre[1] :]
        out["c_x"] = _crossing(rx, px[0])
        out["c_y"] = _crossing(ry, px[1])
        cmaj, cmin, ratio, ang = _principal(rho, (px[0], px[1]))
        out["c_major"], out["c_minor"] = cmaj, cmin
        out["c"] = math.sqrt(cmaj * cmin)
        out["anisotropy_ratio"], out["anisotropy_angle_deg"] = ratio, ang
        fx = _fit_acf(rx, px[0], out["c_x"])
        fy = _fit_acf(ry, px[1], out["c_y"])
    rg = fx["rms_gaussian"] + (fy["rms_gaussian"] if fy else 0.0)
    re = fx["rms_exponential"] + (fy["rms_exponential"] if fy else 0.0)
    model = "exponential" if re < rg else "gaussian"
    out["acf_model"] = model
    out["acf_rms_gaussian"] = rg if fy is None else rg / 2
    out["acf_rms_exponential"] = re if fy is None else re / 2
    out["c_fit_x"] = fx[model]
    out["c_fit_y"] = fy[model] if fy else _NAN
    s2 = math.sqrt(2.0) * out["sigma"]
    out["alpha_gaussian_acf"] = s2 / out["c"]
    out["alpha_gaussian_acf_x"] = s2 / out["c_x"]
    out["alpha_gaussian_acf_y"] = s2 / out["c_y"] if z.ndim == 2 else _NAN
    return out


def _top_share(h: NDArray) -> tuple[float, NDArray]:
    """Share of sum(h^2) carried by the 1 % largest h^2, and the threshold h^2 [m^2]."""
    h2 = h * h
    k = max(1, h2.size // 100)
    part = np.partition(h2, h2.size - k)
    top = part[h2.size - k :]
    total = float(np.sum(h2))
    return (float(np.sum(top)) / total if total > 0 else _NAN), np.asarray(part[h2.size - k])


def _tiles(valid: NDArray, blocks: int) -> list[tuple[slice, ...]]:
    """Index slices of the jackknife tiles (equal shares per axis) holding valid points."""
    edges = [np.linspace(0, n, blocks + 1).round().astype(int) for n in valid.shape]
    cand: list[tuple[slice, ...]]
    if valid.ndim == 1:
        cand = [(slice(edges[0][a], edges[0][a + 1]),) for a in range(blocks)]
    else:
        cand = [
            (slice(edges[0][a], edges[0][a + 1]), slice(edges[1][b], edges[1][b + 1]))
            for a in range(blocks)
            for b in range(blocks)
        ]
    return [t for t in cand if valid[t].any()]


def s_filter(
    heights: ArrayLike,
    pixel_size: float | ArrayLike,
    cutoff: float,
    mask: ArrayLike | None = None,
) -> NDArray:
    """Gaussian S-filter (ISO 16610-61): remove wavelengths shorter than ``cutoff``.

    Parameters
    ----------
    heights : array_like, 1-D or 2-D
        Heights [m]; NaN (or masked) points are invalid.
    pixel_size : float or (float, float)
        Grid spacing [m].
    cutoff : float
        Short-wavelength cut-off lambda_s [m]: a sinusoid of this wavelength keeps 50 % of
        its amplitude.
    mask : array_like of bool, optional
        True where a point is invalid.

    Returns
    -------
    ndarray
        Filtered heights [m], NaN at invalid points.

    Notes
    -----
    ISO 16610-61 (areal; ISO 16610-21 for profiles) weights with
    ``s(x) = exp(-pi (x / (a lambda_s))^2) / (a lambda_s)``, a = sqrt(ln 2 / pi), whose
    transmission is ``exp(-pi (a lambda_s / lambda)^2)`` (0.5 at lambda = lambda_s). That
    is a normal kernel of standard deviation ``a lambda_s / sqrt(2 pi)``, applied here per
    axis by :func:`scipy.ndimage.gaussian_filter` to ``w z`` and to the valid-point
    indicator ``w`` and divided (normalised convolution): dropouts and the map border get
    no weight instead of the standard's end-effect corrections.
    """
    z, valid = _as_heights(heights, mask)
    return _s_filter(z, valid, _pixel(pixel_size, z.ndim), cutoff)


def _s_filter(z: NDArray, valid: NDArray, px: tuple[float, ...], cutoff: float) -> NDArray:
    if not (math.isfinite(cutoff) and cutoff > 0):
        raise ValueError(
            f"short-wavelength cut-off must be positive and finite [m], got {cutoff!r}"
        )
    sig = [GAUSS_ALPHA * cutoff / (math.sqrt(2.0 * math.pi) * p) for p in px]
    num = np.zeros(z.shape)
    np.copyto(num, z, where=valid)
    ndimage.gaussian_filter(num, sig, output=num, mode="constant", truncate=4.0)
    den = ndimage.gaussian_filter(valid.astype(float), sig, mode="constant", truncate=4.0)
    np.divide(num, den, out=num, where=valid)
    num[~valid] = np.nan
    return num


def erode_mask(valid: ArrayLike, pixels: int) -> NDArray:
    """Valid points farther than ``pixels`` (chessboard distance) from any invalid point.

    Parameters
    ----------
    valid : array_like of bool
        True at valid points.
    pixels : int
        Width of the band around each dropout to drop [pixels], >= 0.

    Returns
    -------
    ndarray of bool
        The eroded valid set (the map border is not a dropout).
    """
    v = np.asarray(valid, dtype=bool)
    if not (isinstance(pixels, int | np.integer) and pixels >= 0):
        raise ValueError(f"erode pixels must be an integer >= 0, got {pixels!r}")
    if pixels == 0 or v.all():
        return v.copy()
    bad = ndimage.binary_dilation(
        ~v, structure=np.ones((3,) * v.ndim, dtype=bool), iterations=int(pixels)
    )
    return v & ~bad


def _fmt_len(v: float) -> str:
    for unit, f in (("mm", 1e-3), ("um", 1e-6), ("nm", 1e-9)):
        if abs(v) >= f:
            return f"{v / f:.4g} {unit}"
    return f"{v / 1e-12:.4g} pm"


def _eroded(valid: NDArray, erode: int) -> tuple[NDArray, int]:
    """The valid points after :func:`erode_mask` by ``erode`` pixels, and how many it dropped."""
    if not valid.any():
        raise ValueError("heights hold no valid (finite, unmasked) point")
    if not erode:
        return valid, 0
    n_before = int(np.count_nonzero(valid))
    valid = erode_mask(valid, erode)
    n_eroded = n_before - int(np.count_nonzero(valid))
    if not valid.any():
        raise ValueError(f"eroding the mask by {erode} pixels leaves no valid point")
    return valid, n_eroded


def _jackknife(
    z: NDArray,
    valid: NDArray,
    px: tuple[float, ...],
    degree: int,
    tiles: list[tuple[slice, ...]],
    full: dict[str, Any],
    progress: Callable[[int, int], None] | None,
) -> dict[str, float]:
    """Delete-one-tile jackknife standard errors (bias included) of every finite scalar.

    One replicate per tile, each :func:`_core` with that tile masked, run one after the
    other (memory: one replicate at a time). Empty without tiles.
    """
    if not tiles:
        return {}
    scal = [
        k
        for k, v in full.items()
        if not k.startswith("_") and isinstance(v, float) and math.isfinite(v)
    ]
    no_dropouts = bool(valid.all())
    reps: dict[str, list[float]] = {k: [] for k in scal}
    exps = _exponents(z.ndim, int(degree))
    whole = NormalSums.of(z, valid, exps, ((slice(a, b),) for a, b in _row_blocks(z.shape)))
    for i, t in enumerate(tiles):
        sub = valid.copy()
        sub[t] = False
        lz = (whole - NormalSums.of(z, valid, exps, [t])).levelled(z, sub, exps)
        rep = _core(z, sub, px, degree, hole=t if no_dropouts else None, levelled=lz)
        del sub, lz
        for k in scal:
            reps[k].append(rep[k])
        if progress is not None:
            progress(i + 2, 1 + len(tiles))
    nb = len(tiles)
    unc: dict[str, float] = {}
    for k in scal:
        v = np.asarray(reps[k], dtype=float)
        if not np.all(np.isfinite(v)):
            unc[k] = _NAN
            continue
        var = (nb - 1) / nb * float(np.sum((v - v.mean()) ** 2))
        bias = (nb - 1) * (float(v.mean()) - full[k])
        unc[k] = math.sqrt(var + bias * bias)
    return unc


def _stats_notes(
    z: NDArray,
    valid: NDArray,
    px: tuple[float, ...],
    degree: int,
    full: dict[str, Any],
    fits: SlopeFits,
) -> list[str]:
    """The warnings of :func:`roughness_statistics`.

    A profile, a poor slope fit, a pixel-scale or undefined correlation length, height
    variance carried by a few points.
    """
    notes = []
    if z.ndim == 1:
        notes.append(
            "profile: alphas and the slope fits use one direction and assume an isotropic surface"
        )
    if fits.warning:
        notes.append(fits.warning)
    if not math.isfinite(full["c"]):
        notes.append("the ACF does not fall below 1/e within half the map: c undefined")
    elif full["c"] < C_MIN_PIXELS * min(px):
        notes.append(
            f"correlation length c = {full['c'] / min(px):.2g} pixels (< {C_MIN_PIXELS:g}):"
            " the ACF is that of pixel-scale noise or spikes, so sqrt(2) sigma / c ="
            f" {full['alpha_gaussian_acf']:.3g} is no slope; limit the bandwidth"
            " (short_cutoff, --short-cutoff) or drop dropout rims (erode, --erode-mask)"
        )
    share, h2_thr = full["_top_share"]
    if math.isfinite(share) and share > TOP_VARIANCE_WARN:
        big = np.zeros(z.shape, dtype=bool)
        lz = _level(z, valid, degree)
        with np.errstate(invalid="ignore"):
            np.greater_equal(lz * lz, h2_thr, out=big, where=valid)
        del lz
        n_big = int(np.count_nonzero(big))
        rim = ""
        if not valid.all():
            near = ndimage.binary_dilation(~valid, structure=np.ones((3,) * z.ndim, dtype=bool))
            rim = f", {int(np.count_nonzero(big & near))} of them next to a dropout"
        notes.append(
            f"1 % of the points ({n_big}{rim}) carry {100 * share:.3g} % of the height"
            " variance: spikes or dropout rims dominate sigma, c and the alphas; erode the"
            " mask around dropouts (erode, --erode-mask N) or check the data"
        )
    return notes


def _bandwidth(
    shape: tuple[int, ...], px: tuple[float, ...], degree: int, short_cutoff: float | None
) -> tuple[str, str]:
    """The levelling and the band of surface wavelengths the statistics describe, as text."""
    lev = {0: "mean removed", 1: "least-squares mean plane removed"}.get(
        degree, f"least-squares polynomial of total degree {degree} removed"
    )
    extent = max(n * p for n, p in zip(shape, px, strict=True))
    if short_cutoff is not None:
        lo = (
            f"short-wavelength cut-off {_fmt_len(float(short_cutoff))}"
            " (Gaussian S-filter, ISO 16610-61)"
        )
    else:
        lo = f"no S-filter: down to the pixel, {_fmt_len(min(px))}"
    return lev, f"{lo}; up to the map size {_fmt_len(extent)} ({lev})"


def roughness_statistics(
    heights: ArrayLike,
    pixel_size: float | ArrayLike,
    *,
    mask: ArrayLike | None = None,
    degree: int = 1,
    blocks: int | None = None,
    short_cutoff: float | None = None,
    erode: int = 0,
    progress: Callable[[int, int], None] | None = None,
) -> RoughnessStats:
    """Roughness statistics of an areal height map or a profile, with uncertainties.

    Parameters
    ----------
    heights : array_like, shape (M, N) or (M,)
        Heights [m]; ``heights[i, j]`` at ``(i dx, j dy)``. NaN or masked points are invalid.
    pixel_size : float or (float, float)
        Grid spacing (dx, dy) [m].
    mask : array_like of bool, optional
        True where a point is invalid (in addition to NaN / the array's own mask).
    degree : int
        Levelling polynomial (total degree; 1 = least-squares mean plane).
    blocks : int, optional
        Jackknife tiles per axis (default 5 for a map, 20 for a profile); 0 or 1 = no
        uncertainties.
    short_cutoff : float, optional
        S-filter cut-off lambda_s [m] (:func:`s_filter`, applied after levelling); default
        none: slopes then refer to the pixel, and pixel noise enters them in full.
    erode : int
        Drop the valid points within this many pixels of a dropout (:func:`erode_mask`);
        the rims of dropouts often carry spikes.
    progress : callable, optional
        Called as ``progress(done, total)`` after the full pass and after each jackknife
        replicate.

    Returns
    -------
    RoughnessStats
        ``bandwidth`` states the wavelengths the slopes and alphas refer to; ``notes``
        flag pixel-scale correlation lengths and variance carried by a few points.

    Raises
    ------
    ValueError
        Bad shapes or pixel sizes, too few valid points (e.g. a map full of NaN), a map
        without roughness (all heights on the levelling polynomial).

    Notes
    -----
    ``alpha_gaussian_acf = sqrt(2) sigma / c`` (Dong et al. 2022) is the RMS slope per axis
    of a surface with the Gaussian ACF ``sigma^2 exp(-tau^2/c^2)``; for other ACFs it is
    only a length ratio. ``alpha_ggx_ml`` is the maximum-likelihood GGX alpha of the
    measured slopes, the one the tracer uses. From a profile, alphas and slope fits
    describe the surface only if it is isotropic (one direction is measured).
    Memory: a few copies of the heights (levelled copy, slopes, the zero-padded FFT of
    the ACF at 1.5 times the size per axis); the replicates run one after the other.
    """
    z, valid = _as_heights(heights, mask)
    px = _pixel(pixel_size, z.ndim)
    valid, n_eroded = _eroded(valid, erode)
    if short_cutoff is not None:
        z = _s_filter(_level(z, valid, degree), valid, px, float(short_cutoff))
    if blocks is None:
        blocks = 5 if z.ndim == 2 else 20
    tiles = _tiles(valid, blocks) if blocks and blocks > 1 else []
    if len(tiles) < 2:
        tiles = []
    full = _core(z, valid, px, degree, with_slopes=True)
    if progress is not None:
        progress(1, 1 + len(tiles))
    unc = _jackknife(z, valid, px, degree, tiles, full, progress)
    if tiles:
        u = {name: unc.get(name + "_alpha", _NAN) for name in DISTRIBUTIONS}
    else:
        u = full["_fisher"]
    fits = _make_fits(full["_fit"], u, full["_n_slopes"])
    notes = _stats_notes(z, valid, px, degree, full, fits)
    if n_eroded:
        notes.append(f"mask eroded by {erode} pixels around dropouts: {n_eroded} points dropped")
    names = {f for f in RoughnessStats.__dataclass_fields__}
    kw = {k: v for k, v in full.items() if k in names}
    lev, band = _bandwidth(z.shape, px, degree, short_cutoff)
    return RoughnessStats(
        kind="areal" if z.ndim == 2 else "profile",
        shape=tuple(int(n) for n in z.shape),
        pixel_size=px,
        levelling=lev,
        n_valid=int(np.count_nonzero(valid)),
        slope_fits=fits,
        uncertainty=unc,
        n_blocks=len(tiles),
        notes=tuple(notes),
        short_cutoff=float(short_cutoff) if short_cutoff is not None else _NAN,
        bandwidth=band,
        n_eroded=n_eroded,
        **kw,
    )


#: SurfaceTopography's detrend mode for each levelling degree of a line scan
_DETREND_MODES = {0: "center", 1: "height", 2: "curvature"}


def on_measured_points(
    stats: RoughnessStats,
    points: tuple[ArrayLike, ArrayLike] | None,
    degree: int = 1,
) -> RoughnessStats:
    """sigma and RMS slope of a non-uniform line scan computed on its measured points.

    A stylus export with irregular x is interpolated onto a uniform grid for the
    statistics (:func:`roughness_statistics`); the grid's forward differences mix the
    slopes of neighbouring segments and lose slope (10 % on a real Dektak scan spaced
    0.1-0.2 um). Here the RMS height and RMS slope are those of the measured points
    joined by straight segments, as SurfaceTopography's ``NonuniformLineScan`` computes
    them (``rms_height_from_profile``, ``rms_slope_from_profile``) after its detrend of the
    same degree (0 ``center``, 1 ``height``, 2 ``curvature``); ``alpha_gaussian_acf``
    follows the new sigma. Correlation lengths, slope distributions and their alphas stay
    those of the grid; a note says so.

    Parameters
    ----------
    stats : RoughnessStats
        The statistics of the interpolated profile.
    points : (array_like, array_like) or None
        Measured positions and heights [m] (``HeightMap.points``).
    degree : int
        The levelling degree ``stats`` used.

    Returns
    -------
    RoughnessStats
        ``stats`` itself when there are no points, for an areal map, a levelling degree
        above 2, or statistics of S-filtered or eroded heights (which the measured points
        are not).
    """
    if points is None or stats.kind != "profile" or stats.n_eroded:
        return stats
    if math.isfinite(stats.short_cutoff) or degree not in _DETREND_MODES:
        return stats
    from SurfaceTopography import NonuniformLineScan

    x, z = (np.asarray(a, dtype=float) for a in points)
    ok = np.isfinite(z)
    line = NonuniformLineScan(x[ok], z[ok]).detrend(detrend_mode=_DETREND_MODES[degree])
    sigma = float(line.rms_height_from_profile())
    slope = float(line.rms_slope_from_profile())
    s2 = math.sqrt(2.0) * sigma
    note = (
        f"sigma and RMS slope from the {int(ok.sum())} measured points of the non-uniform "
        f"line scan (piecewise linear; the uniform grid gave {stats.sigma:.4g} m and "
        f"{stats.slope_rms_x:.4g}); correlation length, slope distributions and their alphas "
        "from the grid"
    )
    return replace(
        stats,
        sigma=sigma,
        slope_rms_x=slope,
        slope_rms=slope,
        alpha_gaussian_acf=s2 / stats.c,
        alpha_gaussian_acf_x=s2 / stats.c_x,
        notes=(*stats.notes, note),
    )
