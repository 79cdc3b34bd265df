"""Roughness statistics of measured height maps and profiles, for the microfacet tracer.

Pure NumPy/SciPy: the arrays come in already read (see :mod:`labbrdf.adapters.topography`
for instrument files). Lengths are in metres throughout; slopes are dimensionless.

Pipeline (derivations in ``docs/topography.md``). This module runs it and holds the result
(:class:`RoughnessStats`) and the jackknife; the steps live in one module each, whose public
names it also exports: :mod:`~labbrdf.roughness.levelling` (levelling, S-filter, dropout
rims), :mod:`~labbrdf.roughness.slope_fits` (slopes and the fits of their distribution),
:mod:`~labbrdf.roughness.acf` (autocorrelation, correlation lengths).

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
from scipy import ndimage

from ..jsonsafe import jsonable
from ..microfacet import DISTRIBUTIONS
from .acf import _crossing, _fit_acf, _principal, autocorrelation
from .levelling import (
    GAUSS_ALPHA,
    _as_heights,
    _eroded,
    _exponents,
    _level,
    _pixel,
    _row_blocks,
    _s_filter,
    erode_mask,
    level,
    s_filter,
)
from .levelling_sums import NormalSums
from .slope_fits import (
    KS_WARN,
    SlopeFit,
    SlopeFits,
    _fisher_u,
    _fit_core,
    _make_fits,
    _shape_stats,
    fit_slope_distribution,
    slopes,
)

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

#: Correlation length [pixels] below which the ACF is said to be pixel-scale noise.
C_MIN_PIXELS = 2.0
#: Share of the height variance the 1 % largest squared heights may carry before a note
#: (a Gaussian surface: 8.5 %).
TOP_VARIANCE_WARN = 0.5

_NAN_DEFAULT = float("nan")


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


def _fmt_len(v: float) -> str:
    for unit, f in (("mm", 1e-3), ("um", 1e-6), ("nm", 1e-9)):
        if abs(v) >= f:
            return f"{v / f:.4g} {unit}"
    return f"{v / 1e-12:.4g} pm"


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
