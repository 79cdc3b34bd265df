"""Analytic PSD models: normalisation, band sigma, and the profile form against the 2-D one.

SI values are tiny (PSDs ~1e-27): every ``pytest.approx`` has ``abs=0``, or its default
absolute tolerance of 1e-12 would pass anything.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate

from labbrdf.roughness import psd_models as pm

# parameters with a knee near 1e5 1/m (10 um), sigma ~ 1 nm
CASES = {
    "k-correlation": (2.0e-28, 3.0e-5, 2.4),
    "gaussian": (1.2e-9, 4.0e-6),
    "exponential": (0.8e-9, 2.5e-6),
    "fractal": (3.0e-24, 2.6),
}
TOTAL_SIGMA2 = {
    "k-correlation": lambda A, B, C: 2 * math.pi * A / (B**2 * (C - 1)),
    "gaussian": lambda s, l: s**2,
    "exponential": lambda s, l: s**2,
}


def _quad_annulus(model, params, f1, f2):
    def g(f):
        return 2 * math.pi * f * float(model.psd_2d(f, *params))

    pts = np.geomspace(max(f1, 1.0), f2, 30) if math.isfinite(f2) else None
    if pts is None:
        return integrate.quad(g, f1, math.inf, limit=500, epsrel=1e-12, epsabs=0)[0]
    edges = np.unique(np.r_[f1, pts, f2])
    return sum(
        integrate.quad(g, a, b, limit=200, epsrel=1e-13, epsabs=0)[0]
        for a, b in zip(edges[:-1], edges[1:], strict=True)
    )


KNEE = {"k-correlation": 3.0e-5, "gaussian": math.pi * 4.0e-6, "exponential": 2 * math.pi * 2.5e-6}


@pytest.mark.parametrize("name", ["k-correlation", "gaussian", "exponential"])
def test_plane_integral_is_closed_form_sigma2(name):
    """The 2-D PSD over the whole (fx, fy) plane, in Cartesian coordinates mapped by tan."""
    model = pm.PSD_MODELS[name]
    params = CASES[name]
    B = KNEE[name]

    def g(a, b):
        fx, fy = math.tan(a) / B, math.tan(b) / B
        return float(model.psd_2d(math.hypot(fx, fy), *params)) / (
            B * math.cos(a) ** 2 * B * math.cos(b) ** 2
        )

    plane = 4 * integrate.dblquad(g, 0, math.pi / 2, 0, math.pi / 2, epsrel=1e-10, epsabs=0)[0]
    expected = TOTAL_SIGMA2[name](*params)
    assert plane == pytest.approx(expected, rel=1e-8, abs=0)
    assert model.total_sigma(params) == pytest.approx(math.sqrt(expected), rel=1e-12, abs=0)


@pytest.mark.parametrize("name", list(CASES))
@pytest.mark.parametrize("band", [(1e3, 1e5), (2e4, 3e6), (1e5, 1e8)])
def test_band_sigma_matches_quadrature(name, band):
    model = pm.PSD_MODELS[name]
    params = CASES[name]
    var = _quad_annulus(model, params, *band)
    assert pm.band_sigma(name, params, *band) == pytest.approx(math.sqrt(var), rel=1e-8, abs=0)


@pytest.mark.parametrize("name", ["k-correlation", "gaussian", "exponential"])
def test_band_to_infinity_is_total(name):
    params = CASES[name]
    assert pm.band_sigma(name, params, 0.0, math.inf) == pytest.approx(
        math.sqrt(TOTAL_SIGMA2[name](*params)), rel=1e-12
    )


def test_k_correlation_c_equal_one_is_logarithmic():
    params = (1e-28, 2e-5, 1.0)
    var = _quad_annulus(pm.PSD_MODELS["k-correlation"], params, 1e3, 1e7)
    assert pm.band_sigma("k-correlation", params, 1e3, 1e7) == pytest.approx(
        math.sqrt(var), rel=1e-8, abs=0
    )


def test_exponential_is_k_correlation_with_c_two():
    s, l = CASES["exponential"]
    f = np.geomspace(1e2, 1e9, 50)
    kc = pm.k_correlation_2d(f, 2 * math.pi * s**2 * l**2, 2 * math.pi * l, 2.0)
    np.testing.assert_allclose(pm.exponential_2d(f, s, l), kc, rtol=1e-13)
    np.testing.assert_allclose(
        pm.exponential_1d(f, s, l),
        pm.k_correlation_1d(f, 2 * math.pi * s**2 * l**2, 2 * math.pi * l, 2.0),
        rtol=1e-12,
    )


@pytest.mark.parametrize("name", list(CASES))
@pytest.mark.parametrize("fx", [3e3, 1e5, 7e5])
def test_profile_psd_is_plane_psd_integrated_over_fy(name, fx):
    model = pm.PSD_MODELS[name]
    params = CASES[name]

    def g(fy):
        return float(model.psd_2d(math.hypot(fx, fy), *params))

    edges = np.r_[0.0, np.geomspace(fx / 100, fx * 1e4, 40)]
    val = 2 * sum(
        integrate.quad(g, a, b, epsrel=1e-13, epsabs=0, limit=200)[0]
        for a, b in zip(edges[:-1], edges[1:], strict=True)
    )
    # the tail beyond fx * 1e4 with u = 1 / fy (the fractal tail carries ~1e-7 of it)
    val += (
        2 * integrate.quad(lambda u: g(1 / u) / u**2, 0, 1 / edges[-1], epsrel=1e-12, epsabs=0)[0]
    )
    assert float(model.psd_1d(fx, *params)) == pytest.approx(val, rel=1e-8, abs=0)


@pytest.mark.parametrize("name", ["k-correlation", "gaussian", "exponential"])
def test_profile_band_to_infinity_is_total(name):
    params = CASES[name]
    assert pm.band_sigma(name, params, 0.0, math.inf, profile=True) == pytest.approx(
        math.sqrt(TOTAL_SIGMA2[name](*params)), rel=1e-8
    )


def test_gaussian_slope_is_analytic():
    # Gaussian autocovariance sigma^2 exp(-r^2/l^2): gradient variance 4 sigma^2 / l^2
    s, l = CASES["gaussian"]
    assert pm.band_slope("gaussian", (s, l), 0.0, math.inf) == pytest.approx(
        2 * s / l, rel=1e-8, abs=0
    )


def test_bad_band_and_unknown_model():
    with pytest.raises(ValueError, match="f_min < f_max"):
        pm.band_sigma("gaussian", CASES["gaussian"], 1e5, 1e3)
    with pytest.raises(KeyError, match="known: k-correlation"):
        pm.get("abc")
    assert pm.band_sigma("fractal", CASES["fractal"], 0.0, 1e5) == math.inf


@pytest.mark.parametrize("name", list(CASES))
def test_guess_recovers_order_of_magnitude(name):
    model = pm.PSD_MODELS[name]
    params = CASES[name]
    f = np.geomspace(1e3, 3e6, 60)
    guess = model.guess(f, model.psd_2d(f, *params))
    assert len(guess) == len(model.param_names) == len(model.units) == len(model.bounds)
    for g, p in zip(guess, params, strict=True):
        assert 0.1 < g / p < 10
