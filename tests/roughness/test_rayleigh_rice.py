"""Rayleigh-Rice scatter: limits, invariants and the closed-form TIS.

Each check can fail: reciprocity fails if an off-diagonal factor has the wrong sign or
incidence/scatter roles swapped, the perfect-conductor limit fails on any factor's form,
the TIS checks fail on the 16 pi^2 / lambda^4 prefactor, a cosine or the Bragg frequency.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate

from labbrdf.optics import fresnel
from labbrdf.roughness import psd_models, smoothness
from labbrdf.roughness import rayleigh_rice as rr

LAM = 633e-9
AL = 1.55 + 7.71j
GLASS = 1.5 + 0.0j


def gaussian_psd(sigma: float, ell: float):
    """Isotropic Gaussian 2-D PSD [m^4] with integral sigma^2 (SCATMECH's form)."""

    def psd(fx, fy):
        f2 = np.asarray(fx) ** 2 + np.asarray(fy) ** 2
        return math.pi * (sigma * ell) ** 2 * np.exp(-((math.pi * ell) ** 2) * f2)

    return psd


def kcorr_psd(a: float, b: float, c: float):
    def psd(fx, fy):
        f2 = np.asarray(fx) ** 2 + np.asarray(fy) ** 2
        return a / (1.0 + b * b * f2) ** (c / 2.0)

    return psd


def _random_geometry(rng, n=200):
    ti = rng.uniform(0.0, 1.5, n)
    tr = rng.uniform(0.0, 1.5, n)
    pr = rng.uniform(-math.pi, math.pi, n)
    return ti, tr, pr


@pytest.mark.parametrize("index", [AL, GLASS, 0.2 + 3.6j, 4.0 + 0.05j])
def test_reciprocity_mueller_transpose(index):
    """f_M(r -> i) = D f_M(i -> r)^T D, D = diag(1, 1, -1, 1) (S2 flips on reversal)."""
    rng = np.random.default_rng(1)
    ti, tr, pr = _random_geometry(rng)
    psd = kcorr_psd(1e-30, 2e-5, 2.5)
    m = rr.mueller_brdf(ti, tr, pr, LAM, index, psd)
    back = rr.mueller_brdf(tr, ti, -pr, LAM, index, psd)
    d = np.diag([1.0, 1.0, -1.0, 1.0])
    expect = d @ np.swapaxes(m, -1, -2) @ d
    np.testing.assert_allclose(back, expect, rtol=1e-12, atol=1e-12 * np.abs(m).max())


def test_perfect_conductor_limit():
    """N -> i infinity: q_ss = cos ps, q_pp = (si ss - cos ps)/(ci cs), q_ps = -sin ps/ci,
    q_sp = -sin ps/cs (Germer 1997's factors at eps -> -infinity; Stover ch. 5)."""
    rng = np.random.default_rng(2)
    ti, tr, pr = _random_geometry(rng)
    q = rr.jones_factors(ti, tr, pr, 1e9j)
    ps = pr - math.pi
    ci, si, cs, ss = np.cos(ti), np.sin(ti), np.cos(tr), np.sin(tr)
    want = {
        (0, 0): np.cos(ps),
        (1, 1): (si * ss - np.cos(ps)) / (ci * cs),
        (0, 1): -np.sin(ps) / ci,
        (1, 0): -np.sin(ps) / cs,
    }
    # the factors approach the limit as 1/|N| times 1/(cos ti cos ts) at most: 1e-9 * 1e3
    for (a, b), w in want.items():
        assert np.max(np.abs(q[..., a, b] - w) * ci * cs) < 1e-7, (a, b)


@pytest.mark.parametrize("index", [AL, GLASS])
def test_specular_factors_are_fresnel(index):
    """At the specular direction Q_ss = R_s, Q_pp = R_p and no cross-polarization."""
    t = np.radians(np.array([0.0, 20.0, 45.0, 70.0, 85.0]))
    q = rr.jones_factors(t, t, math.pi, index)
    rs, rp = fresnel(1.0, index, np.degrees(t))[:2]
    np.testing.assert_allclose(q[..., 0, 0], -rs, atol=1e-14)
    np.testing.assert_allclose(q[..., 1, 1], -rp, atol=1e-14)
    np.testing.assert_allclose(q[..., 0, 1], 0.0, atol=1e-14)
    np.testing.assert_allclose(q[..., 1, 0], 0.0, atol=1e-14)


def test_brdf_channels_match_mueller():
    rng = np.random.default_rng(3)
    ti, tr, pr = _random_geometry(rng, 50)
    psd = gaussian_psd(2e-9, 3e-6)
    m = rr.mueller_brdf(ti, tr, pr, LAM, AL, psd)
    np.testing.assert_allclose(rr.brdf(ti, tr, pr, LAM, AL, psd), m[..., 0, 0], rtol=1e-12)
    np.testing.assert_allclose(
        rr.brdf(ti, tr, pr, LAM, AL, psd, "s"), m[..., 0, 0] + m[..., 0, 1], rtol=1e-12
    )
    np.testing.assert_allclose(
        rr.brdf(ti, tr, pr, LAM, AL, psd, "p"), m[..., 0, 0] - m[..., 0, 1], rtol=1e-12
    )


def test_tis_perfect_conductor_normal_incidence_against_radial_integral():
    """At normal incidence on a perfect conductor, cos ts Q_unpol = (cos ts + 1/cos ts)/2,
    so TIS = (16 pi^2 / lambda^2) int_0^{1/lambda} (cos + 1/cos)/2 PSD(f) 2 pi f df with
    sin ts = lambda f: a 1-D integral (scipy quad) against the 2-D angular quadrature."""
    psd = kcorr_psd(2e-32, 3e-6, 3.0)

    def radial(f):
        c = math.sqrt(max(1.0 - (LAM * f) ** 2, 0.0))
        return 0.5 * (c + 1.0 / c) * psd(f, 0.0) * 2 * math.pi * f

    ref, _ = integrate.quad(radial, 0.0, 0.8 / LAM, limit=400, epsabs=0, epsrel=1e-12)
    ref *= 16 * math.pi**2 / LAM**2
    got = rr.tis(0.0, LAM, 1e9j, psd, theta_max=math.asin(0.8), n_theta=400, n_phi=16)
    assert got == pytest.approx(ref, rel=1e-8)


@pytest.mark.parametrize("index", [AL, GLASS])
@pytest.mark.parametrize("theta_i_deg", [0.0, 30.0, 60.0])
def test_tis_small_roughness_limit(index, theta_i_deg):
    """Long correlation length: all scatter near specular, TIS -> R_0 (4 pi sigma cos ti/lambda)^2.

    The Gaussian PSD of ell = 40 lambda scatters within sin(dt) ~ 1/(pi 40); the relative
    angular variation of Q cos ts over that cone is below 1e-3 (5 deg from specular at 60 deg
    incidence), so the tolerance is 3e-3. The same number is labbrdf.smoothness' R_0 g.
    """
    sigma, ell = 1e-9, 40 * LAM
    ti = math.radians(theta_i_deg)
    psd = gaussian_psd(sigma, ell)
    u0 = math.sin(ti)
    du = 6.0 / (math.pi * ell) * LAM
    lo, hi = max(u0 - du, 0.0), min(u0 + du, 1.0)
    got = rr.tis(
        ti,
        LAM,
        index,
        psd,
        theta_min=math.asin(lo),
        theta_max=math.asin(hi),
        n_theta=200,
        n_phi=720,
    )
    rs, rp = fresnel(1.0, index, theta_i_deg)[:2]
    r0 = 0.5 * (abs(rs) ** 2 + abs(rp) ** 2)
    want = rr.tis_small_roughness(sigma, LAM, ti, r0)
    assert got == pytest.approx(float(want), rel=3e-3)
    g = smoothness.rayleigh_parameter(sigma, LAM, ti)
    small = smoothness.total_integrated_scatter(r0, g, small_roughness=True)
    assert float(want) == pytest.approx(float(small), rel=1e-12)
    assert float(rr.specular_loss(sigma, LAM, ti)) == pytest.approx(
        float(smoothness.specular_loss(g)), rel=1e-12
    )


@pytest.mark.parametrize(
    "form, params",
    [
        ("k-correlation", (1e-31, 1e-5, 1.6)),
        ("gaussian", (2e-9, 4e-6)),
        ("exponential", (2e-9, 3e-6)),
    ],
)
def test_parseval_sigma_from_brdf(form, params):
    """sigma^2 of the band recovered from the integrated BRDF, against the PSD model's
    closed-form band sigma (labbrdf.roughness.psd_models.band_sigma): Parseval through
    the scatter. A perfect conductor at normal incidence, band sin ts < 0.1, where the
    weight (cos + 1/cos)/2 differs from 1 by < 1.3e-5: sigma_band^2 = TIS (lambda/4 pi)^2.
    """
    model = psd_models.get(form)

    def psd(fx, fy):
        return model.psd_2d(np.hypot(fx, fy), *params)

    sig = psd_models.band_sigma(form, params, 0.0, 0.1 / LAM)
    t = rr.tis(0.0, LAM, 1e9j, psd, theta_max=math.asin(0.1), n_theta=300, n_phi=16)
    assert math.sqrt(t) * LAM / (4 * math.pi) == pytest.approx(sig, rel=1e-5)


def test_bad_input():
    psd = gaussian_psd(1e-9, 1e-6)
    with pytest.raises(ValueError, match="theta_r"):
        rr.brdf(0.1, 2.0, 0.0, LAM, AL, psd)
    with pytest.raises(ValueError, match="wavelength"):
        rr.brdf(0.1, 0.2, 0.0, -1.0, AL, psd)
    with pytest.raises(ValueError, match="index"):
        rr.brdf(0.1, 0.2, 0.0, LAM, -1 + 0j, psd)
    with pytest.raises(ValueError, match="polarization"):
        rr.brdf(0.1, 0.2, 0.0, LAM, AL, psd, "x")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="psd2d"):
        rr.brdf(0.1, 0.2, 0.0, LAM, AL, lambda fx, fy: -np.ones_like(fx))
    with pytest.raises(ValueError, match="theta_min"):
        rr.tis(0.1, LAM, AL, psd, theta_min=1.0, theta_max=0.5)
