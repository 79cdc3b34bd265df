"""Analytic power spectral densities (PSDs) of isotropic random rough surfaces.

Pure NumPy/SciPy: the model PSDs optics labs fit to measured spectra, in their 2-D
(isotropic, azimuthally symmetric) and 1-D (profile) forms, and the RMS height they
carry over a band of spatial frequencies.

Conventions (SI throughout):

* spatial frequency ``f`` in cycles per metre [1/m] (not the angular ``q = 2 pi f``);
  heights in metres [m];
* the 2-D PSD ``PSD2(fx, fy)`` [m^4] is normalised so that the height variance is its
  integral over the whole frequency plane,
  ``sigma^2 = int int PSD2(fx, fy) dfx dfy = int_0^inf 2 pi f PSD2(f) df``;
* the 1-D (profile) PSD ``PSD1(fx)`` [m^3] is two-sided:
  ``sigma^2 = int_-inf^inf PSD1(fx) dfx``; for an isotropic surface it is the 2-D PSD
  integrated over ``fy``: ``PSD1(fx) = int PSD2(fx, fy) dfy`` (Elson & Bennett 1995;
  Stover 2012, ch. 4);
* the band ``[f_min, f_max]`` of a 2-D PSD is an annulus of the plane; of a 1-D PSD it
  is ``f_min <= |fx| <= f_max`` (both signs counted).

Many papers (Stover; Church & Takacs; Duparre et al.) use the one-sided profile PSD
``2 PSD1`` over ``fx > 0`` only; multiply our ``k_correlation_1d`` by two to compare.

The models (constants in each function's docstring):

``k-correlation`` (ABC)
    ``PSD2 = A / (1 + (B f)^2)^((C+1)/2)``: flat below ``f ~ 1/B``, an inverse power law
    ``f^-(C+1)`` above it (Church, Takacs & Leonard 1989; Church & Takacs 1991;
    Duparre et al. 2002). ``C = 2`` is the exponential correlation function.
``gaussian``
    Gaussian autocovariance ``sigma^2 exp(-r^2 / l^2)`` (Stover 2012, ch. 2 and 4).
``exponential``
    exponential autocovariance ``sigma^2 exp(-r / l)`` (Stover 2012, ch. 4;
    Elson & Bennett 1979).
``fractal``
    the inverse power law ``PSD2 = K / f^n`` (Church 1988; Duparre et al. 2002):
    no finite total sigma, only band-limited ones.

References
----------
E. L. Church, "Fractal surface finish", Appl. Opt. 27 (1988) 1518-1526.
E. L. Church, P. Z. Takacs, T. A. Leonard, "The prediction of BRDFs from surface profile
measurements", Proc. SPIE 1165 (1989) 136-150.
E. L. Church, P. Z. Takacs, "The optimal estimation of finish parameters", Proc. SPIE
1530 (1991) 71-85.
J. M. Elson, J. M. Bennett, "Calculation of the power spectral density from surface
profile data", Appl. Opt. 34 (1995) 201-208; "Relation between the angular dependence of
scattering and the statistical properties of optical surfaces", J. Opt. Soc. Am. 69
(1979) 31-47.
J. C. Stover, *Optical Scattering: Measurement and Analysis*, 3rd ed., SPIE Press (2012),
ch. 2 (surface statistics) and ch. 4 (PSDs of profiles and areas).
A. Duparre, J. Ferre-Borrull, S. Gliech, G. Notni, J. Steinert, J. M. Bennett, "Surface
characterization techniques for determining the root-mean-square roughness and power
spectral densities of optical components", Appl. Opt. 41 (2002) 154-171.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import integrate, special

__all__ = [
    "PSD_MODELS",
    "PSDModel",
    "band_sigma",
    "band_slope",
    "exponential_1d",
    "exponential_2d",
    "fractal_1d",
    "fractal_2d",
    "gaussian_1d",
    "gaussian_2d",
    "get",
    "k_correlation_1d",
    "k_correlation_2d",
]

FloatArray = NDArray[np.float64]


def _f(f: ArrayLike) -> FloatArray:
    return np.abs(np.asarray(f, dtype=float))


# --------------------------------------------------------------------- K-correlation (ABC)
def k_correlation_2d(f: ArrayLike, A: float, B: float, C: float) -> FloatArray:
    """2-D K-correlation (ABC) PSD ``A / (1 + (B f)^2)^((C+1)/2)`` [m^4].

    Parameters
    ----------
    f : array_like
        Radial spatial frequency [1/m].
    A : float
        Low-frequency plateau [m^4].
    B : float
        Correlation length: the knee is at ``f = 1/B`` [m].
    C : float
        Slope exponent [-]: the PSD falls as ``f^-(C+1)`` above the knee.

    Notes
    -----
    Church, Takacs & Leonard (1989); Church & Takacs (1991); Duparre et al. (2002)
    (their 2-D form). The total height variance is finite for ``C > 1``:
    ``sigma^2 = 2 pi A / (B^2 (C - 1))``. ``C = 2`` with ``A = 2 pi sigma^2 l^2`` and
    ``B = 2 pi l`` is :func:`exponential_2d`.
    """
    return A / (1.0 + (B * _f(f)) ** 2) ** ((C + 1.0) / 2.0)


def _kc_profile_factor(C: float) -> float:
    """``int (1 + t^2)^-((C+1)/2) dt`` over the real line: ``sqrt(pi) G(C/2) / G((C+1)/2)``."""
    return math.sqrt(math.pi) * math.exp(
        special.gammaln(C / 2.0) - special.gammaln((C + 1.0) / 2.0)
    )


def k_correlation_1d(f: ArrayLike, A: float, B: float, C: float) -> FloatArray:
    """Two-sided profile form of :func:`k_correlation_2d` [m^3].

    ``PSD1(fx) = sqrt(pi) G(C/2) / G((C+1)/2) * (A / B) / (1 + (B fx)^2)^(C/2)``, with
    ``G`` the gamma function; ``A, B, C`` are the 2-D parameters (``C > 0``).

    Notes
    -----
    Derived here by integrating the 2-D form over ``fy``: with ``a^2 = 1 + (B fx)^2`` and
    ``fy = a t / B``, ``int A (a^2 + B^2 fy^2)^-((C+1)/2) dfy = A a^-C / B *
    int (1 + t^2)^-((C+1)/2) dt`` and the last integral is ``sqrt(pi) G(C/2) /
    G((C+1)/2)`` (Gradshteyn & Ryzhik 3.251.2). This is Church & Takacs's (1991) 1-D ABC
    form with exponent ``C/2``; the one-sided profile PSD of Duparre et al. (2002) is
    twice ours.
    """
    return _kc_profile_factor(C) * (A / B) / (1.0 + (B * _f(f)) ** 2) ** (C / 2.0)


def _kc_band_var(params: tuple[float, ...], f_min: float, f_max: float) -> float:
    A, B, C = params
    x1, x2 = (B * f_min) ** 2, (B * f_max) ** 2
    if abs(C - 1.0) < 1e-9:
        return math.pi * A / B**2 * (math.log1p(x2) - math.log1p(x1))
    e = (1.0 - C) / 2.0
    # (1+x)^e computed as exp(e log1p(x)); f_max = inf gives 0 for C > 1
    hi = 0.0 if (math.isinf(x2) and C > 1.0) else math.exp(e * math.log1p(x2))
    lo = math.exp(e * math.log1p(x1))
    return 2.0 * math.pi * A / (B**2 * (C - 1.0)) * (lo - hi)


# --------------------------------------------------------------------- Gaussian
def gaussian_2d(f: ArrayLike, sigma: float, corr_length: float) -> FloatArray:
    """2-D PSD of a Gaussian autocovariance ``sigma^2 exp(-r^2 / l^2)`` [m^4].

    ``PSD2(f) = pi sigma^2 l^2 exp(-(pi l f)^2)`` (Stover 2012, ch. 2 and 4, the
    Gaussian correlation function), ``sigma`` [m] the RMS height, ``l`` [m] the
    1/e correlation length. Its profile form is :func:`gaussian_1d`.
    """
    sigma2, l = sigma**2, corr_length
    return math.pi * sigma2 * l**2 * np.exp(-((math.pi * l * _f(f)) ** 2))


def gaussian_1d(f: ArrayLike, sigma: float, corr_length: float) -> FloatArray:
    """Two-sided profile PSD of :func:`gaussian_2d` [m^3].

    ``PSD1(fx) = sqrt(pi) sigma^2 l exp(-(pi l fx)^2)``: the 2-D form integrated over ``fy``.
    """
    l = corr_length
    return math.sqrt(math.pi) * sigma**2 * l * np.exp(-((math.pi * l * _f(f)) ** 2))


def _gauss_band_var(params: tuple[float, ...], f_min: float, f_max: float) -> float:
    sigma, l = params
    a = (math.pi * l) ** 2
    return sigma**2 * (math.exp(-a * f_min**2) - math.exp(-a * f_max**2))


# --------------------------------------------------------------------- exponential
def exponential_2d(f: ArrayLike, sigma: float, corr_length: float) -> FloatArray:
    """2-D PSD of an exponential autocovariance ``sigma^2 exp(-r / l)`` [m^4].

    ``PSD2(f) = 2 pi sigma^2 l^2 / (1 + (2 pi l f)^2)^(3/2)`` (Stover 2012, ch. 4;
    Elson & Bennett 1979): the K-correlation form with ``C = 2``.
    """
    l = corr_length
    return 2.0 * math.pi * sigma**2 * l**2 / (1.0 + (2.0 * math.pi * l * _f(f)) ** 2) ** 1.5


def exponential_1d(f: ArrayLike, sigma: float, corr_length: float) -> FloatArray:
    """Two-sided profile PSD of :func:`exponential_2d` [m^3].

    ``PSD1(fx) = 2 sigma^2 l / (1 + (2 pi l fx)^2)``: the Fourier transform of
    ``sigma^2 exp(-|x| / l)`` (Stover 2012, ch. 2), equal to the 2-D form integrated over ``fy``.
    """
    l = corr_length
    return 2.0 * sigma**2 * l / (1.0 + (2.0 * math.pi * l * _f(f)) ** 2)


def _exp_band_var(params: tuple[float, ...], f_min: float, f_max: float) -> float:
    sigma, l = params
    b = 2.0 * math.pi * l
    hi = 0.0 if math.isinf(f_max) else 1.0 / math.sqrt(1.0 + (b * f_max) ** 2)
    return sigma**2 * (1.0 / math.sqrt(1.0 + (b * f_min) ** 2) - hi)


# --------------------------------------------------------------------- fractal
def fractal_2d(f: ArrayLike, K: float, n: float) -> FloatArray:
    """Inverse-power-law (fractal) 2-D PSD ``K / f^n`` [m^4].

    ``K`` [m^(4-n)] the spectral strength, ``n`` [-] the slope (Church 1988; Duparre et
    al. 2002, with the fractal dimension ``D = (8 - n) / 2``
    for ``2 < n < 4``). The total sigma diverges: only band-limited values exist.
    """
    return K / _f(f) ** n


def fractal_1d(f: ArrayLike, K: float, n: float) -> FloatArray:
    """Two-sided profile form of :func:`fractal_2d` (``n > 1``) [m^3].

    ``PSD1(fx) = sqrt(pi) G((n-1)/2) / G(n/2) * K / |fx|^(n-1)``: the 2-D law integrated
    over ``fy`` (Church 1988 for the relation between profile and area exponents).
    """
    factor = math.sqrt(math.pi) * math.exp(
        special.gammaln((n - 1.0) / 2.0) - special.gammaln(n / 2.0)
    )
    return factor * K / _f(f) ** (n - 1.0)


def _fractal_band_var(params: tuple[float, ...], f_min: float, f_max: float) -> float:
    K, n = params
    if abs(n - 2.0) < 1e-9:
        return 2.0 * math.pi * K * math.log(f_max / f_min)
    return 2.0 * math.pi * K * (f_max ** (2.0 - n) - f_min ** (2.0 - n)) / (2.0 - n)


# --------------------------------------------------------------------- first guesses
def _trapz_sigma2(f: FloatArray, psd: FloatArray) -> float:
    return float(np.trapezoid(2.0 * np.pi * f * psd, f))


def _loglog_slope(f: FloatArray, psd: FloatArray) -> tuple[float, float]:
    slope, intercept = np.polyfit(np.log(f), np.log(psd), 1)
    return float(slope), float(intercept)


def _guess_kc(f: FloatArray, psd: FloatArray) -> tuple[float, ...]:
    n = len(f)
    A = float(np.median(psd[: max(3, n // 10)]))
    slope, _ = _loglog_slope(f[n // 2 :], psd[n // 2 :])
    C = float(np.clip(-slope - 1.0, 0.2, 6.0))
    f_hi, p_hi = float(f[-1]), float(psd[-1])
    B = (A / max(p_hi, 1e-300)) ** (1.0 / (C + 1.0)) / f_hi
    return A, float(max(B, 1.0 / f_hi)), C


def _guess_corr(f: FloatArray, psd: FloatArray, plateau_factor: float) -> tuple[float, ...]:
    sigma2 = max(_trapz_sigma2(f, psd), 1e-300)
    A = float(np.median(psd[: max(3, len(f) // 10)]))
    return math.sqrt(sigma2), math.sqrt(A / (plateau_factor * sigma2))


def _guess_fractal(f: FloatArray, psd: FloatArray) -> tuple[float, ...]:
    slope, intercept = _loglog_slope(f, psd)
    return math.exp(intercept), float(np.clip(-slope, 1.05, 5.95))


# --------------------------------------------------------------------- the registry
@dataclass(frozen=True)
class PSDModel:
    """One analytic PSD: its 2-D and profile forms, parameters, units, bounds and guess.

    Attributes
    ----------
    name : str
        Registry key.
    psd_2d, psd_1d : callable
        ``f(f, *params)`` -> 2-D PSD [m^4] / two-sided profile PSD [m^3].
    param_names, units : tuple of str
        Parameter names and their units.
    bounds : tuple of (float, float)
        Physical bounds of each parameter (open at 0 for the positive ones).
    guess : callable
        ``guess(f, psd2)`` -> first parameters from a 2-D (azimuthal) PSD.
    band_variance : callable
        ``band_variance(params, f_min, f_max)`` -> closed-form height variance [m^2] of
        the 2-D PSD over the annulus ``f_min <= f <= f_max``.
    description : str
        One line for tables.
    """

    name: str
    psd_2d: Callable[..., FloatArray]
    psd_1d: Callable[..., FloatArray]
    param_names: tuple[str, ...]
    units: tuple[str, ...]
    bounds: tuple[tuple[float, float], ...]
    guess: Callable[[FloatArray, FloatArray], tuple[float, ...]]
    band_variance: Callable[[tuple[float, ...], float, float], float]
    description: str

    def __call__(self, f: ArrayLike, *params: float) -> FloatArray:
        """The 2-D PSD [m^4] at ``f`` [1/m]."""
        return self.psd_2d(f, *params)

    def total_sigma(self, params: tuple[float, ...]) -> float:
        """RMS height over all frequencies [m] (``inf`` where it diverges)."""
        if self.name == "fractal" or (self.name == "k-correlation" and params[2] <= 1.0):
            return math.inf
        return math.sqrt(self.band_variance(tuple(params), 0.0, math.inf))


_POS = (1e-300, math.inf)

#: name -> :class:`PSDModel`
PSD_MODELS: dict[str, PSDModel] = {
    "k-correlation": PSDModel(
        "k-correlation",
        k_correlation_2d,
        k_correlation_1d,
        ("A", "B", "C"),
        ("m^4", "m", "1"),
        (_POS, _POS, (0.05, 8.0)),
        _guess_kc,
        _kc_band_var,
        "K-correlation (ABC): A / (1 + (B f)^2)^((C+1)/2)",
    ),
    "gaussian": PSDModel(
        "gaussian",
        gaussian_2d,
        gaussian_1d,
        ("sigma", "corr_length"),
        ("m", "m"),
        (_POS, _POS),
        lambda f, p: _guess_corr(f, p, math.pi),
        _gauss_band_var,
        "Gaussian correlation: pi sigma^2 l^2 exp(-(pi l f)^2)",
    ),
    "exponential": PSDModel(
        "exponential",
        exponential_2d,
        exponential_1d,
        ("sigma", "corr_length"),
        ("m", "m"),
        (_POS, _POS),
        lambda f, p: _guess_corr(f, p, 2.0 * math.pi),
        _exp_band_var,
        "exponential correlation: 2 pi sigma^2 l^2 / (1 + (2 pi l f)^2)^(3/2)",
    ),
    "fractal": PSDModel(
        "fractal",
        fractal_2d,
        fractal_1d,
        ("K", "n"),
        ("m^(4-n)", "1"),
        (_POS, (1.05, 5.95)),
        _guess_fractal,
        _fractal_band_var,
        "inverse power law (fractal): K / f^n",
    ),
}


def get(name: str) -> PSDModel:
    """The :class:`PSDModel` called ``name`` (a ``KeyError`` naming the known ones)."""
    try:
        return PSD_MODELS[name]
    except KeyError:
        raise KeyError(f"unknown PSD model {name!r}; known: {', '.join(PSD_MODELS)}") from None


def _check_band(f_min: float, f_max: float) -> None:
    if not (0.0 <= f_min < f_max):
        raise ValueError(f"band must satisfy 0 <= f_min < f_max, got [{f_min}, {f_max}] 1/m")


def band_sigma(
    model_name: str,
    params: ArrayLike,
    f_min: float,
    f_max: float,
    *,
    profile: bool = False,
) -> float:
    """RMS height [m] a model PSD carries over a band of spatial frequencies.

    Parameters
    ----------
    model_name : str
        A key of :data:`PSD_MODELS`.
    params : array_like
        The model's parameters, in the order of its ``param_names``.
    f_min, f_max : float
        Band [1/m]; ``f_max`` may be ``inf`` where the integral converges.
    profile : bool
        False (default): the 2-D PSD over the annulus ``f_min <= f <= f_max`` (closed
        form for every model). True: the two-sided profile PSD over ``f_min <= |fx| <=
        f_max`` (adaptive quadrature).

    Returns
    -------
    float
        ``sqrt(int 2 pi f PSD2(f) df)`` or ``sqrt(2 int PSD1(fx) dfx)`` over the band [m].
    """
    model = get(model_name)
    p = tuple(float(v) for v in np.atleast_1d(np.asarray(params, dtype=float)))
    _check_band(f_min, f_max)
    if not profile:
        if model.name == "fractal" and (f_min == 0.0 or math.isinf(f_max)):
            return math.inf
        return math.sqrt(max(model.band_variance(p, f_min, f_max), 0.0))
    var = 2.0 * _quad(lambda x: float(model.psd_1d(x, *p)), f_min, f_max)
    return math.sqrt(max(var, 0.0))


def band_slope(model_name: str, params: ArrayLike, f_min: float, f_max: float) -> float:
    """RMS surface slope [rad] (gradient magnitude) of a model 2-D PSD over a band.

    ``m^2 = int 2 pi f (2 pi f)^2 PSD2(f) df`` (Stover 2012 ch. 4; Elson & Bennett
    1979): the second moment of the PSD; computed by adaptive quadrature.
    """
    model = get(model_name)
    p = tuple(float(v) for v in np.atleast_1d(np.asarray(params, dtype=float)))
    _check_band(f_min, f_max)
    var = _quad(
        lambda x: float(2.0 * math.pi * x * (2.0 * math.pi * x) ** 2 * model.psd_2d(x, *p)),
        f_min,
        f_max,
    )
    return math.sqrt(max(var, 0.0))


def _quad(func: Callable[[float], float], a: float, b: float) -> float:
    """Adaptive quadrature over ``[a, b]``, split at decades so narrow features are seen.

    An infinite ``b`` is split at the decades up to ``1e12`` 1/m (a period of 1 pm, far
    beyond any surface) and the rest integrated with ``u = 1/f``.
    """
    tail = 0.0
    if math.isinf(b):
        top = max(1e12, 10.0 * a)
        tail, _ = integrate.quad(
            lambda u: func(1.0 / u) / u**2, 0.0, 1.0 / top, limit=400, epsabs=0.0, epsrel=1e-12
        )
        b = top
    lo_edge = max(a, 1e-2)
    edges = [a] if a < lo_edge else []
    edges += list(np.geomspace(lo_edge, b, max(2, int(math.log10(b / lo_edge)) + 2)))
    total = 0.0
    for lo, hi in zip(edges[:-1], edges[1:], strict=True):
        val, _ = integrate.quad(func, lo, hi, limit=400, epsabs=0.0, epsrel=1e-12)
        total += val
    return float(total + tail)
