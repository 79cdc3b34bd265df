r"""FFT Gaussian random rough surfaces (Dong et al. 2022, section 2.1, eqs. 1-5, corrected).

A surface ``z = f(x, y)`` on a periodic M x N grid has the Gaussian autocorrelation of
eq. (1),

.. math:: C(x, y) = \sigma^2 \exp(-x^2/c_x^2 - y^2/c_y^2),

whose power spectral density (2-D Fourier transform, convention
``S(k) = (2 pi)^-2 \int C(r) exp(-i k.r) d^2 r``) is

.. math:: S(k_x, k_y) = \frac{\sigma^2 c_x c_y}{4\pi}
          \exp\left(-\frac{k_x^2 c_x^2 + k_y^2 c_y^2}{4}\right).

References
----------
Dong Z., Bai P., Xu W., Liu Y., Sun X., "Modeling and characteristic analysis methods for
reflection polarization on coated surfaces", Acta Optica Sinica 42(22), 2224001 (2022),
doi:10.3788/AOS202242.2224001.

Notes
-----
Departures from the paper:

* eq. (2) prints the exponent as ``k_x^2 c_x + k_y^2 c_y`` and the prefactor with the
  roughness alpha; the transform of eq. (1) gives ``k_x^2 c_x^2 + k_y^2 c_y^2`` and the
  height variance sigma^2 (checked in the tests by the sample autocorrelation).
* eqs. (3)-(5) build a Hermitian-symmetric complex Gaussian spectrum by hand. We take the
  FFT of real white noise instead, which *is* such a spectrum (complex Gaussian pairs with
  ``F(-k) = F(k)*``, real values at the self-conjugate frequencies), filter it with
  ``sqrt(S)`` and transform back: the surface is real to round-off by construction and no
  real part has to be taken.
* The filter is normalised so that the ensemble variance is exactly sigma^2 on the discrete
  grid (the discrete sum of S differs from the integral only when the grid does not resolve
  the correlation length or the patch is not much larger than it).
* A Gaussian surface has Beckmann (Gaussian) slopes with RMS slope sqrt(2) sigma / c per
  axis (the paper's ``alpha = sqrt(2) sigma / c_l``); the tracer uses the paper's GGX
  distribution with that alpha, which is a model choice of the paper, not an identity.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, cast

import numpy as np
from numpy.typing import NDArray

__all__ = [
    "Surface",
    "correlation_length",
    "gaussian_psd",
    "gaussian_surface",
    "height_rms",
    "slope_rms",
]


@dataclass(frozen=True)
class Surface:
    """A sampled periodic height map.

    Attributes
    ----------
    x, y : ndarray
        Grid coordinates, shapes (M,) and (N,) [same length unit as the heights].
    z : ndarray
        Heights, shape (M, N); ``z[i, j]`` is at ``(x[i], y[j])``.
    sigma, corr_length : float, tuple of float
        The requested RMS height and correlation lengths (c_x, c_y).
    """

    x: NDArray[np.floating[Any]]
    y: NDArray[np.floating[Any]]
    z: NDArray[np.floating[Any]]
    sigma: float
    corr_length: tuple[float, float]

    @property
    def spacing(self) -> tuple[float, float]:
        """Grid spacing (dx, dy) [length]."""
        return float(self.x[1] - self.x[0]), float(self.y[1] - self.y[0])


def _pair(value: float | tuple[float, float], name: str) -> tuple[float, float]:
    vals = np.broadcast_to(np.asarray(value, dtype=float), (2,))
    if not np.all(np.isfinite(vals)) or np.any(vals <= 0):
        raise ValueError(f"{name} must be positive and finite, got {value!r}")
    return float(vals[0]), float(vals[1])


def gaussian_psd(
    kx: NDArray[np.floating[Any]],
    ky: NDArray[np.floating[Any]],
    sigma: float,
    cx: float,
    cy: float,
) -> NDArray[np.float64]:
    """Power spectral density of the Gaussian correlation, corrected eq. (2) of Dong 2022.

    Parameters
    ----------
    kx, ky : array_like
        Spatial angular frequencies [rad / length].
    sigma : float
        RMS height [length].
    cx, cy : float
        Correlation lengths [length].

    Returns
    -------
    ndarray
        ``S = sigma^2 cx cy / (4 pi) exp(-(kx^2 cx^2 + ky^2 cy^2) / 4)`` [length^4].
    """
    kx = np.asarray(kx, dtype=float)
    ky = np.asarray(ky, dtype=float)
    return sigma**2 * cx * cy / (4 * np.pi) * np.exp(-(kx**2 * cx**2 + ky**2 * cy**2) / 4)


def gaussian_surface(
    shape: int | tuple[int, int],
    length: float | tuple[float, float],
    sigma: float,
    corr_length: float | tuple[float, float],
    rng: np.random.Generator | int | None = None,
) -> Surface:
    """Generate a real Gaussian random surface by FFT filtering (Dong 2022, eqs. 1-5).

    Parameters
    ----------
    shape : int or (int, int)
        Grid points (M, N); each at least 8.
    length : float or (float, float)
        Patch size (L_x, L_y) [length]; the surface is periodic over it.
    sigma : float
        RMS height [length].
    corr_length : float or (float, float)
        Correlation lengths (c_x, c_y) [length]; equal values give an isotropic surface.
    rng : numpy.random.Generator or int or None
        Random generator or seed.

    Returns
    -------
    Surface
        Heights with zero ensemble mean and ensemble variance sigma^2.

    Raises
    ------
    ValueError
        For non-positive sizes, lengths or sigma.
    """
    m: Any
    n: Any
    m, n = (shape, shape) if np.isscalar(shape) else tuple(cast("tuple[int, int]", shape))
    if int(m) != m or int(n) != n or m < 8 or n < 8:
        raise ValueError(f"shape must be integers >= 8, got {shape!r}")
    m, n = int(m), int(n)
    lx, ly = _pair(length, "length")
    cx, cy = _pair(corr_length, "corr_length")
    if not np.isfinite(sigma) or sigma <= 0:
        raise ValueError(f"sigma must be positive and finite, got {sigma!r}")
    gen = rng if isinstance(rng, np.random.Generator) else np.random.default_rng(rng)
    kx = 2 * np.pi * np.fft.fftfreq(m, d=lx / m)
    ky = 2 * np.pi * np.fft.fftfreq(n, d=ly / n)
    psd = gaussian_psd(kx[:, None], ky[None, :], sigma, cx, cy)
    # Var(z) = sum(H^2) / (M N) for z = ifft(fft(w) H) with unit white noise w.
    h = np.sqrt(psd * (m * n) * sigma**2 / psd.sum())
    white = gen.standard_normal((m, n))
    z = np.fft.ifft2(np.fft.fft2(white) * h).real
    x = np.arange(m) * (lx / m)
    y = np.arange(n) * (ly / n)
    return Surface(x=x, y=y, z=z, sigma=float(sigma), corr_length=(cx, cy))


def height_rms(surface: Surface) -> float:
    """Sample RMS height about the mean [length]."""
    z = surface.z
    return float(np.sqrt(np.mean((z - z.mean()) ** 2)))


def _autocorrelation(z: NDArray[np.floating[Any]]) -> NDArray[np.float64]:
    """Circular autocorrelation normalised to 1 at zero lag."""
    f = np.fft.fft2(z - z.mean())
    acf = np.fft.ifft2(f * np.conj(f)).real
    return acf / acf[0, 0]


def correlation_length(surface: Surface) -> tuple[float, float]:
    """Estimate (c_x, c_y) from the sample autocorrelation [length].

    Uses the lag ``l`` on the grid closest to the requested correlation length and
    inverts eq. (1): ``c = l / sqrt(-ln rho(l))``, with rho the normalised circular
    autocorrelation along each axis.
    """
    acf = _autocorrelation(surface.z)
    dx, dy = surface.spacing
    out = []
    for axis, (d, c) in enumerate(zip((dx, dy), surface.corr_length, strict=True)):
        lag = max(1, int(round(c / d)))
        rho = acf[lag, 0] if axis == 0 else acf[0, lag]
        out.append(float(lag * d / np.sqrt(-np.log(rho))) if 0 < rho < 1 else float("nan"))
    return out[0], out[1]


def slope_rms(surface: Surface) -> tuple[float, float]:
    """RMS slopes (dz/dx, dz/dy) by spectral differentiation [1].

    For the Gaussian correlation of eq. (1) the expected values are sqrt(2) sigma / c_x
    and sqrt(2) sigma / c_y (the paper's ``alpha = sqrt(2) sigma / c_l``).
    """
    m, n = surface.z.shape
    dx, dy = surface.spacing
    kx = 2 * np.pi * np.fft.fftfreq(m, d=dx)
    ky = 2 * np.pi * np.fft.fftfreq(n, d=dy)
    if m % 2 == 0:
        kx[m // 2] = 0.0  # Nyquist term has no odd part
    if n % 2 == 0:
        ky[n // 2] = 0.0
    f = np.fft.fft2(surface.z)
    sx = np.fft.ifft2(1j * kx[:, None] * f).real
    sy = np.fft.ifft2(1j * ky[None, :] * f).real
    return float(np.sqrt(np.mean(sx**2))), float(np.sqrt(np.mean(sy**2)))
