"""Autocorrelation of levelled height maps and profiles, and correlation lengths from it.

Pure NumPy/SciPy; lengths in metres. rho(tau) by a mask-normalised FFT
(``rho = IFFT|FFT(w z)|^2 / IFFT|FFT(w)|^2``, w the valid-point indicator, zero padding),
the 1/e crossing along a line, the principal axes of the central region rho > 1/e, and
Gaussian and exponential models fitted to an axis ACF. Used by
:func:`labbrdf.roughness.topography.roughness_statistics` (step 4 of its pipeline).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray
from scipy import fft as sfft
from scipy import ndimage, optimize

__all__ = ["autocorrelation"]

_NAN = float("nan")

_INV_E = math.exp(-1.0)


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
