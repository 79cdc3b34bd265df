"""Rayleigh parameter, criteria, Davies loss and Bennett-Porteus TIS against hand values."""

from __future__ import annotations

import math

import numpy as np
import pytest

from labbrdf.roughness import smoothness as sm
from labbrdf.roughness.synthetic import gaussian_surface
from labbrdf.roughness.topography import roughness_statistics

# (sigma [nm], wavelength [nm], theta_i [deg]) -> g computed with plain math below
CASES = [(10.0, 500.0, 0.0), (10.0, 500.0, 60.0), (2.0, 633.0, 45.0), (50.0, 1000.0, 30.0)]


def _g_by_hand(sigma: float, lam: float, theta_deg: float) -> float:
    phase = 4.0 * math.pi * sigma * math.cos(math.radians(theta_deg)) / lam
    return phase * phase


@pytest.mark.parametrize(("sigma", "lam", "theta"), CASES)
def test_rayleigh_parameter_matches_the_formula_by_hand(sigma, lam, theta):
    g = sm.rayleigh_parameter(sigma, lam, math.radians(theta))
    assert float(g) == pytest.approx(_g_by_hand(sigma, lam, theta), rel=1e-14)


def test_rayleigh_parameter_literal_values():
    # sigma = lambda / 100 at normal incidence: (4 pi / 100)^2 = 0.0157913670417...
    assert float(sm.rayleigh_parameter(5.0, 500.0)) == pytest.approx(0.01579136704174297, 1e-13)
    # at 60 deg cos^2 = 1/4
    assert float(sm.rayleigh_parameter(5.0, 500.0, math.pi / 3)) == pytest.approx(
        0.01579136704174297 / 4, rel=1e-13
    )
    # metres and nanometres give the same g
    assert float(sm.rayleigh_parameter(5e-9, 500e-9)) == pytest.approx(0.01579136704174297, 1e-13)


def test_rayleigh_parameter_broadcasts_over_wavelength_and_angle():
    lam = np.array([400.0, 500.0, 800.0])[:, None]
    th = np.radians([0.0, 30.0, 60.0])[None, :]
    g = sm.rayleigh_parameter(3.0, lam, th)
    assert g.shape == (3, 3)
    for i, L in enumerate([400.0, 500.0, 800.0]):
        for j, t in enumerate([0.0, 30.0, 60.0]):
            assert g[i, j] == pytest.approx(_g_by_hand(3.0, L, t), rel=1e-14)


def test_threshold_is_where_the_phase_spread_is_pi_over_2_or_pi_over_8():
    lam, th = 633.0, math.radians(40.0)
    for crit, phase in (("rayleigh", math.pi / 2), ("fraunhofer", math.pi / 8)):
        t = float(sm.smooth_threshold(lam, th, crit))
        assert t == pytest.approx(lam / (sm.CRITERIA[crit] * math.cos(th)), rel=1e-15)
        assert float(sm.rayleigh_parameter(t, lam, th)) == pytest.approx(phase**2, rel=1e-13)


def test_thresholds_by_hand():
    assert float(sm.smooth_threshold(800.0)) == 100.0
    assert float(sm.smooth_threshold(800.0, criterion="fraunhofer")) == 25.0
    assert float(sm.smooth_threshold(800.0, math.radians(60.0))) == pytest.approx(200.0, 1e-13)


def test_verdict_smooth_rough_undecided_with_the_uncertainty():
    lam = 800.0  # threshold 100 nm (Rayleigh), 25 nm (Fraunhofer)
    v = sm.verdict([50.0, 150.0, 95.0, 95.0, 100.0], [5.0, 5.0, 5.0, 1.0, 0.0], lam)
    assert list(v) == ["smooth", "rough", "undecided", "smooth", "rough"]
    assert str(sm.verdict(50.0, np.nan, lam, criterion="fraunhofer")) == "rough"
    assert str(sm.verdict(95.0, 5.0, lam, k=0.0)) == "smooth"


def test_specular_loss_limits():
    g = np.array([0.0, 1e-8, 1e-4, 1e-2])
    loss = sm.specular_loss(g)
    assert loss[0] == 1.0
    # exp(-g) = 1 - g + g^2/2 - ...: within g^2/2 of 1 - g
    assert np.all(np.abs(loss - (1 - g)) <= g**2 / 2 + 1e-16)
    assert float(sm.specular_loss(1.0)) == pytest.approx(1 / math.e, rel=1e-15)


def test_total_integrated_scatter_by_hand_and_small_roughness_limit():
    r0 = 0.9
    g = _g_by_hand(2.0, 633.0, 0.0)  # a good mirror: 2 nm at HeNe
    tis = float(sm.total_integrated_scatter(r0, g))
    assert tis == pytest.approx(r0 * (1 - math.exp(-g)), rel=1e-14)
    approx = float(sm.total_integrated_scatter(r0, g, small_roughness=True))
    assert approx == pytest.approx(r0 * (4 * math.pi * 2.0 / 633.0) ** 2, rel=1e-14)
    assert abs(approx - tis) <= r0 * g**2 / 2
    # energy: specular + scatter = R0
    assert float(r0 * sm.specular_loss(g)) + tis == pytest.approx(r0, rel=1e-15)
    assert float(sm.total_integrated_scatter(r0, 0.0)) == 0.0


def test_g_uncertainty_is_the_linear_propagation():
    s, u, lam, th = 10.0, 0.5, 500.0, math.radians(20.0)
    ug = float(sm.rayleigh_parameter_uncertainty(s, u, lam, th))
    h = 1e-4
    dg = (_g_by_hand(s + h, lam, 20.0) - _g_by_hand(s - h, lam, 20.0)) / (2 * h)
    assert ug == pytest.approx(dg * u, rel=1e-8)


def test_shortest_scattering_period_from_the_grating_equation():
    assert float(sm.shortest_scattering_period(500.0)) == 500.0
    d = float(sm.shortest_scattering_period(500.0, math.radians(30.0)))
    assert d == pytest.approx(500.0 / 1.5, rel=1e-15)
    # first order at that period leaves at grazing: sin(theta_s) = sin(theta_i) - lambda/d
    assert math.sin(math.radians(30.0)) - 500.0 / d == pytest.approx(-1.0, rel=1e-14)


def test_band_coverage_classifies_the_maps_band():
    # map resolves 1000..1500 nm periods
    cov, lo = sm.band_coverage([400.0, 2000.0, 1200.0], map_short=1000.0, map_long=1500.0)
    assert list(cov) == ["misses short periods", "none", "band-limited"]
    assert lo[0] == 1000.0 and np.isnan(lo[1]) and lo[2] == 1200.0


def test_verdicts_on_generated_gaussian_surfaces_follow_sigma_and_lambda():
    # two surfaces of known sigma, measured as a lab would (levelled, jackknife u)
    lam = np.array([100.0, 400.0, 1600.0])  # thresholds 12.5, 50, 200 nm (Rayleigh)
    verdicts = {}
    for sigma in (5.0, 30.0):
        s = gaussian_surface(128, 20_000.0, sigma, 1_000.0, rng=7)
        st = roughness_statistics(s.z, s.spacing)
        assert st.sigma == pytest.approx(sigma, rel=0.15)
        verdicts[sigma] = list(sm.verdict(st.sigma, st.uncertainty["sigma"], lam))
    assert verdicts[5.0] == ["smooth", "smooth", "smooth"]
    assert verdicts[30.0] == ["rough", "smooth", "smooth"]
    s = gaussian_surface(128, 20_000.0, 30.0, 1_000.0, rng=7)
    st = roughness_statistics(s.z, s.spacing)
    fr = sm.verdict(st.sigma, st.uncertainty["sigma"], lam, criterion="fraunhofer")
    assert list(fr) == ["rough", "rough", "smooth"]  # thresholds 3.1, 12.5, 50 nm


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda: sm.rayleigh_parameter(-1.0, 500.0), "sigma must be finite and >= 0"),
        (lambda: sm.rayleigh_parameter(1.0, 0.0), "wavelength must be finite and > 0"),
        (lambda: sm.rayleigh_parameter(1.0, np.nan), "wavelength must be finite"),
        (lambda: sm.rayleigh_parameter(1.0, 500.0, math.pi / 2), "theta_i must be finite"),
        (lambda: sm.rayleigh_parameter(1.0, 500.0, np.inf), "theta_i must be finite"),
        (lambda: sm.smooth_threshold(500.0, 0.0, "strict"), "criterion 'strict' unknown"),
        (lambda: sm.verdict(1.0, -0.1, 500.0), "u_sigma must be finite and >= 0"),
        (lambda: sm.verdict(1.0, np.inf, 500.0), "u_sigma must be finite"),
        (lambda: sm.verdict(1.0, 0.1, 500.0, k=-1.0), "k must be finite and >= 0"),
        (lambda: sm.specular_loss(-0.1), "g must be finite and >= 0"),
        (lambda: sm.total_integrated_scatter(-0.5, 0.1), "r0 must be finite and >= 0"),
        (lambda: sm.rayleigh_parameter_uncertainty(1.0, -1.0, 500.0), "u_sigma must be"),
        (lambda: sm.shortest_scattering_period(500.0, 2.0), "theta_i must be finite"),
        (lambda: sm.band_coverage(500.0, 0.0, 10.0), "map_short must be finite and > 0"),
        (lambda: sm.band_coverage(500.0, 10.0, 5.0), "must be below map_long"),
    ],
)
def test_bad_inputs_raise_naming_the_argument(call, match):
    with pytest.raises(ValueError, match=match):
        call()
