"""FFT Gaussian random surfaces (Dong 2022 eqs. 1-5, corrected): statistics and errors.

Tolerances: a patch of size L_x x L_y holds about P = (L_x / c_x)(L_y / c_y) independent
correlation cells, so sample statistics scatter by ~1/sqrt(P) relative; we allow
K = 4 of those.
"""

from __future__ import annotations

import numpy as np
import pytest

from labbrdf.roughness.synthetic import (
    correlation_length,
    gaussian_psd,
    gaussian_surface,
    height_rms,
    slope_rms,
)

K = 4.0
CASES = [
    # shape, length, sigma, corr (isotropic and anisotropic)
    ((512, 512), (64.0, 64.0), 0.3, (1.0, 1.0)),
    ((512, 256), (100.0, 50.0), 0.5, (1.0, 2.0)),
]


def _tol(length, corr) -> float:
    patches = (length[0] / corr[0]) * (length[1] / corr[1])
    return K / np.sqrt(patches)


@pytest.mark.parametrize(("shape", "length", "sigma", "corr"), CASES)
def test_height_rms_matches_requested_sigma(shape, length, sigma, corr):
    srf = gaussian_surface(shape, length, sigma, corr, rng=1)
    assert height_rms(srf) == pytest.approx(sigma, rel=_tol(length, corr))


@pytest.mark.parametrize(("shape", "length", "sigma", "corr"), CASES)
def test_correlation_length_matches_request(shape, length, sigma, corr):
    srf = gaussian_surface(shape, length, sigma, corr, rng=2)
    cx, cy = correlation_length(srf)
    assert cx == pytest.approx(corr[0], rel=_tol(length, corr))
    assert cy == pytest.approx(corr[1], rel=_tol(length, corr))


@pytest.mark.parametrize(("shape", "length", "sigma", "corr"), CASES)
def test_slope_rms_is_sqrt2_sigma_over_corr(shape, length, sigma, corr):
    srf = gaussian_surface(shape, length, sigma, corr, rng=3)
    sx, sy = slope_rms(srf)
    assert sx == pytest.approx(np.sqrt(2) * sigma / corr[0], rel=_tol(length, corr))
    assert sy == pytest.approx(np.sqrt(2) * sigma / corr[1], rel=_tol(length, corr))


def test_ensemble_variance_is_sigma_squared():
    # 40 surfaces: the mean of the sample variances has relative error ~ sqrt(2/(40 P)).
    length, corr, sigma = (32.0, 32.0), (1.0, 1.0), 0.7
    rng = np.random.default_rng(4)
    var = [height_rms(gaussian_surface(128, length, sigma, corr, rng=rng)) ** 2 for _ in range(40)]
    patches = 40 * length[0] * length[1]
    # + 1/P per surface: removing the sample mean biases each variance by -sigma^2/P
    assert np.mean(var) == pytest.approx(sigma**2, rel=K * np.sqrt(2 / patches) + 1 / 1024)


def test_psd_is_fourier_transform_of_eq1_correlation():
    # S(k) = (2 pi)^-2 * integral C(r) exp(-i k.r) d^2r, evaluated by a Riemann sum on a
    # grid fine and wide enough for the Gaussian (error far below 1e-10).
    sigma, cx, cy = 0.4, 1.3, 0.6
    x = np.linspace(-12, 12, 1201)
    y = np.linspace(-6, 6, 1201)
    dx, dy = x[1] - x[0], y[1] - y[0]
    cxy = sigma**2 * np.exp(-(x[:, None] ** 2) / cx**2 - y[None, :] ** 2 / cy**2)
    for kx, ky in [(0.0, 0.0), (1.1, 0.0), (0.0, 2.3), (0.7, -1.9)]:
        phase = np.cos(kx * x)[:, None] * np.cos(ky * y)[None, :]  # C is even
        s_num = (cxy * phase).sum() * dx * dy / (2 * np.pi) ** 2
        assert gaussian_psd(kx, ky, sigma, cx, cy) == pytest.approx(s_num, rel=1e-10, abs=1e-16)


def test_surface_is_real_and_reproducible_with_seed():
    a = gaussian_surface(64, 16.0, 0.2, 1.0, rng=7)
    b = gaussian_surface(64, 16.0, 0.2, 1.0, rng=7)
    c = gaussian_surface(64, 16.0, 0.2, 1.0, rng=8)
    assert a.z.dtype == np.float64
    np.testing.assert_array_equal(a.z, b.z)
    assert not np.array_equal(a.z, c.z)
    assert a.x.shape == (64,) and a.y.shape == (64,) and a.spacing == (0.25, 0.25)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"shape": 4}, "shape must be integers >= 8"),
        ({"shape": (16, 7.5)}, "shape must be integers >= 8"),
        ({"length": -1.0}, "length must be positive"),
        ({"sigma": 0.0}, "sigma must be positive"),
        ({"sigma": float("nan")}, "sigma must be positive"),
        ({"corr_length": (1.0, 0.0)}, "corr_length must be positive"),
    ],
)
def test_bad_arguments_raise_naming_the_argument(kwargs, match):
    args = {"shape": 16, "length": 8.0, "sigma": 0.1, "corr_length": 1.0} | kwargs
    with pytest.raises(ValueError, match=match):
        gaussian_surface(**args)
