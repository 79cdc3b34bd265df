"""Levelling and filtering of height maps and profiles: form removal, S-filter, dropout rims.

Pure NumPy/SciPy; lengths in metres. The least-squares polynomial of total degree
``degree`` in (x, y) over the valid points is subtracted (ISO 25178-2 F-operator; default
1, the mean plane; 0 = mean only; 2 = the full quadric, SurfaceTopography's
``"curvature"``); :func:`s_filter` removes the wavelengths below a cut-off (ISO 16610-61);
:func:`erode_mask` drops the rims of dropouts. Used by
:func:`labbrdf.roughness.topography.roughness_statistics`, whose module docstring gives the
whole pipeline.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import ndimage

__all__ = ["GAUSS_ALPHA", "erode_mask", "level", "s_filter"]

#: ISO 16610-61 Gaussian weighting constant, sqrt(ln 2 / pi): 50 % transmission at lambda_s.
GAUSS_ALPHA = math.sqrt(math.log(2.0) / math.pi)


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
