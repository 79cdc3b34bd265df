"""The Lambertian base under the rough dielectric coating (``Substrate.lambertian``).

Independent checks: the closed form of a Lambertian under a smooth dielectric slab (the
interface's internal hemispherical reflectance by quadrature of a Fresnel formula written
here), the bare base's ``albedo / pi``, the energy ledger of a white base, the Lambert
distribution of the re-emitted directions (KS test), the counting estimator for the
evaluated one, and bit-identical chunking. Statistical tolerances are K = 4 standard
errors unless a comment says why otherwise.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy import integrate, stats

from labbrdf.microfacet import TabulatedNDF
from labbrdf.tracer import Coating, Substrate, TraceConfig, trace
from labbrdf.tracer.agreement import agreement
from labbrdf.tracer.walk import _base_event

K = 4.0
VARNISH = Coating(n=1.5, k=0.0, thickness_nm=500.0, alpha=0.2)


# ------------------------------------------------ smooth-interface closed form (test-only)


def _fresnel_unpolarized(n1: float, n2: float, cos_i: float) -> float:
    """(|r_s|^2 + |r_p|^2) / 2 of a lossless interface, 1 beyond the critical angle."""
    sin2_t = (n1 / n2) ** 2 * (1.0 - cos_i * cos_i)
    if sin2_t >= 1.0:
        return 1.0
    cos_t = np.sqrt(1.0 - sin2_t)
    rs = (n1 * cos_i - n2 * cos_t) / (n1 * cos_i + n2 * cos_t)
    rp = (n2 * cos_i - n1 * cos_t) / (n2 * cos_i + n1 * cos_t)
    return 0.5 * (rs * rs + rp * rp)


def _internal_diffuse_reflectance(n: float) -> float:
    """r_i = int_0^{pi/2} F_in(theta) 2 sin(theta) cos(theta) dtheta, from inside n."""
    crit = np.arcsin(1.0 / n)
    val, _ = integrate.quad(
        lambda t: _fresnel_unpolarized(n, 1.0, np.cos(t)) * np.sin(2 * t),
        0.0,
        np.pi / 2,
        points=[crit],
        epsabs=1e-13,
    )
    return val


def _slab_albedo(n: float, albedo: float, theta_i_deg: float) -> tuple[float, float]:
    """(specular F(theta_i), diffuse R_d) of a Lambertian under a smooth lossless slab."""
    f = _fresnel_unpolarized(1.0, n, np.cos(np.radians(theta_i_deg)))
    r_i = _internal_diffuse_reflectance(n)
    return f, (1.0 - f) * albedo * (1.0 - r_i) / (1.0 - albedo * r_i)


def test_internal_diffuse_reflectance_obeys_the_radiance_invariant():
    # r_i = 1 - (1 - r_e) / n^2 (the n^2 law of radiance; r_e from outside, no TIR)
    n = 1.5
    r_e, _ = integrate.quad(
        lambda t: _fresnel_unpolarized(1.0, n, np.cos(t)) * np.sin(2 * t), 0.0, np.pi / 2
    )
    assert _internal_diffuse_reflectance(n) == pytest.approx(1 - (1 - r_e) / n**2, abs=1e-10)


# alpha's bias, measured with 8e5 rays per point at theta_i 30 deg, albedo 0.8 (total minus
# closed form, SE 2.2e-4): +1.8e-4 (alpha 0.01), +4.0e-4 (0.02), +9.7e-4 (0.04),
# +2.1e-3 (0.08): linear in alpha, slope ~0.026, so 0.03 * alpha bounds it
ALPHA_SMOOTH = 0.02
ALPHA_BIAS = 0.03 * ALPHA_SMOOTH


@pytest.mark.parametrize(("theta_i", "albedo"), [(30.0, 0.8), (60.0, 0.5)])
def test_nearly_smooth_coating_over_a_base_gives_the_slab_closed_form(theta_i, albedo):
    cfg = TraceConfig(
        rays=200_000,
        block_rays=10_000,
        theta_i_deg=theta_i,
        substrate=Substrate.lambertian(albedo),
        coating=Coating(n=1.5, k=0.0, thickness_nm=500.0, alpha=ALPHA_SMOOTH),
        scattering="multiple",
        theta_step_deg=5.0,
        phi_step_deg=10.0,
    )
    res = trace(cfg)
    specular, diffuse = _slab_albedo(1.5, albedo, theta_i)
    # the diffuse albedo: the total minus the first surface's specular part F(theta_i)
    got = res.albedo() - specular
    tol = K * res.albedo_stderr() + ALPHA_BIAS
    assert abs(got - diffuse) < tol, (got, diffuse, tol)
    # the threshold kills rays below tau = 1e-4 (a grey base's long walks): negligible
    assert res.ledger["terminated"] < 1e-5


def test_white_base_under_a_lossless_coating_absorbs_nothing():
    cfg = TraceConfig(
        rays=40_000,
        block_rays=5_000,
        theta_i_deg=45.0,
        substrate=Substrate.lambertian(1.0),
        coating=VARNISH,
        scattering="multiple",
        theta_step_deg=5.0,
        phi_step_deg=10.0,
    )
    res = trace(cfg)
    led = res.ledger
    # the dielectric walk conserves M00 per ray to round-off; only max_bounces can end a ray
    assert abs(led["absorbed"]) < 1e-12
    assert led["terminated"] < 1e-3
    assert res.albedo() == pytest.approx(1.0 - led["terminated"], abs=1e-12)
    assert led["exited"] + led["absorbed"] + led["terminated"] == pytest.approx(1.0, abs=1e-12)


def test_a_grey_base_absorbs_its_share_and_the_ledger_closes():
    cfg = TraceConfig(
        rays=20_000,
        block_rays=5_000,
        substrate=Substrate.lambertian(0.5),
        coating=VARNISH,
        theta_step_deg=5.0,
        phi_step_deg=10.0,
    )
    led = trace(cfg).ledger
    assert led["absorbed"] > 0.2
    assert led["exited"] + led["absorbed"] + led["terminated"] == pytest.approx(1.0, abs=1e-12)


# ----------------------------------------------------------------------- bare base


def test_bare_base_is_albedo_over_pi_exactly_when_evaluated():
    cfg = TraceConfig(
        rays=5000, substrate=Substrate.lambertian(0.7), theta_step_deg=5.0, phi_step_deg=10.0
    )
    assert cfg.resolved_estimator == "evaluated"
    res = trace(cfg)
    m = res.mueller
    np.testing.assert_allclose(m[..., 0, 0], 0.7 / np.pi, rtol=1e-14)
    m[..., 0, 0] = 0.0
    assert not m.any()  # depolarizing: only M00
    assert not res.mueller_stderr.any()
    assert res.albedo() == pytest.approx(0.7, abs=1e-12)
    assert res.ledger["exited"] == pytest.approx(0.7, abs=1e-12)
    assert res.ledger["absorbed"] == pytest.approx(0.3, abs=1e-12)


def test_bare_base_counts_albedo_over_pi_in_every_bin():
    cfg = TraceConfig(
        rays=200_000,
        block_rays=20_000,
        substrate=Substrate.lambertian(0.6),
        estimator="counting",
        theta_step_deg=5.0,
        phi_step_deg=20.0,
    )
    res = trace(cfg)
    m, se = res.mueller[..., 0, 0], res.mueller_stderr[..., 0, 0]
    use = res.counts >= 100  # all but the polar cap and the grazing row (small cos-solid angle)
    assert use.sum() > 0.85 * use.size
    z = (m[use] - 0.6 / np.pi) / se[use]
    assert np.abs(z).max() < 5.0  # ~300 bins: |z| > 5 has p ~ 2e-4
    assert 0.8 < np.sqrt(np.mean(z * z)) < 1.2
    assert not res.mueller[..., 1:, :].any() and not res.mueller[..., :, 1:].any()
    assert res.albedo() == pytest.approx(0.6, abs=1e-12)


def test_base_event_draws_lambert_directions_and_keeps_only_the_intensity_row():
    n = 20_000
    rng = np.random.default_rng(7)
    k = np.tile(np.array([[0.0], [0.0], [-1.0]]), n)
    s = np.tile(np.array([[0.0], [1.0], [0.0]]), n)
    M = rng.normal(size=(4, 4, n))
    M[0, 0] = 1.0 + rng.random(n)
    before = M.copy()
    absorbed = _base_event(0.25, np.random.default_rng(1), np.arange(n), k, s, M)
    assert absorbed == pytest.approx(0.75 * before[0, 0].sum(), rel=1e-14)
    np.testing.assert_array_equal(M[0], 0.25 * before[0])
    assert not M[1:].any()
    np.testing.assert_allclose((k * k).sum(axis=0), 1.0, rtol=1e-14)
    np.testing.assert_allclose((k * s).sum(axis=0), 0.0, atol=1e-15)
    # Lambert: cos^2(theta) and the azimuth are uniform
    assert stats.kstest(k[2] ** 2, "uniform").pvalue > 1e-3
    phi = np.mod(np.arctan2(k[1], k[0]), 2 * np.pi) / (2 * np.pi)
    assert stats.kstest(phi, "uniform").pvalue > 1e-3


# ----------------------------------------------------------------------- estimators


def test_auto_picks_the_evaluated_estimator_where_it_applies():
    base = Substrate.lambertian(0.5)
    assert TraceConfig(substrate=base).resolved_estimator == "evaluated"
    assert TraceConfig(substrate=base, scattering="single").resolved_estimator == "evaluated"
    coated = TraceConfig(substrate=base, coating=VARNISH)
    assert coated.resolved_estimator == "counting"
    assert coated.replace(scattering="single").resolved_estimator == "evaluated"
    smooth_top = Coating(alpha=0.0)
    assert (
        TraceConfig(substrate=base, coating=smooth_top, scattering="single").resolved_estimator
        == "counting"
    )


@pytest.mark.slow
def test_evaluated_agrees_with_counting_over_a_base():
    cfg = TraceConfig(
        rays=120_000,
        block_rays=10_000,
        theta_i_deg=45.0,
        substrate=Substrate.lambertian(0.8),
        coating=VARNISH,
        scattering="single",
        theta_step_deg=5.0,
        phi_step_deg=20.0,
    )
    ev = trace(cfg)
    co = trace(cfg.replace(estimator="counting", seed=1))
    assert ev.estimator == "evaluated" and co.estimator == "counting"
    se = np.hypot(ev.albedo_stderr(), co.albedo_stderr())
    assert abs(ev.albedo() - co.albedo()) < K * se
    assert (ev.mueller_stderr[..., 0, 0] > 0).any()  # the batches give the evaluated errors
    # M00 alone (positive ray weights, Gaussian at ~200 rays), over every bin: sparse bins
    # are pooled with their neighbours, none is left out
    z = agreement(ev, co, min_count=200, elements="m00").z
    assert z.size > 100
    assert np.abs(z).max() < 5.0
    assert 0.7 < np.sqrt(np.mean(z * z)) < 1.3


# ---------------------------------------------------------------------- determinism


@pytest.mark.parametrize("scattering", ["multiple", "single"])
def test_base_runs_are_bit_identical_whatever_the_chunking(scattering):
    cfg = TraceConfig(
        rays=6000,
        block_rays=1000,
        fold_blocks=2,
        substrate=Substrate.lambertian(0.8),
        coating=VARNISH,
        scattering=scattering,
        theta_step_deg=5.0,
        phi_step_deg=10.0,
    )
    ref = trace(cfg)
    for bpu in (1, 3, 6):
        other = trace(cfg, blocks_per_unit=bpu)
        np.testing.assert_array_equal(other.mueller, ref.mueller)
        np.testing.assert_array_equal(other.mueller_stderr, ref.mueller_stderr)
        assert other.ledger == ref.ledger
    assert not np.array_equal(trace(cfg.replace(seed=1)).mueller, ref.mueller)


def test_conductor_runs_do_not_change_with_the_new_field():
    cfg = TraceConfig(rays=3000, block_rays=1000, coating=VARNISH, theta_step_deg=5.0)
    a = trace(cfg)
    b = trace(TraceConfig.from_json(cfg.to_json()))
    np.testing.assert_array_equal(a.sums, b.sums)


# ------------------------------------------------------------------ config and errors


def test_base_survives_json_and_is_described():
    cfg = TraceConfig(substrate=Substrate.lambertian(0.35), coating=VARNISH)
    d = json.loads(cfg.to_json())
    assert d["substrate"]["albedo"] == 0.35
    back = TraceConfig.from_json(cfg.to_json())
    assert back == cfg and back.substrate.kind == "lambertian"
    assert "albedo 0.35" in back.substrate.describe()
    assert Substrate().kind == "conductor" and Substrate(mirror=True).kind == "mirror"
    assert Substrate().to_dict()["albedo"] is None
    assert Substrate(n=0.0, k=0.0, albedo=0.5).kind == "lambertian"  # n, k unused


def test_base_appears_in_the_result_card():
    res = trace(TraceConfig(rays=100, substrate=Substrate.lambertian(0.4), theta_step_deg=5.0))
    assert "Lambertian base, albedo 0.4" in res._repr_html_()


@pytest.mark.parametrize("bad", [-0.1, 1.5, float("nan"), float("inf"), True, "0.5"])
def test_albedo_outside_zero_one_is_refused_naming_the_field(bad):
    with pytest.raises(ValueError, match=r"substrate\.albedo must be a finite number in \[0, 1\]"):
        Substrate.lambertian(bad)


def test_base_refuses_mirror_and_slope_table():
    with pytest.raises(ValueError, match=r"substrate\.mirror must be False with a Lambertian"):
        Substrate(albedo=0.5, mirror=True)
    table = TabulatedNDF.ggx(0.2, n=32)
    with pytest.raises(ValueError, match=r"substrate\.ndf must be None with a Lambertian"):
        Substrate(albedo=0.5, ndf=table)


def test_coherent_mode_refuses_a_base():
    with pytest.raises(ValueError, match="coherent must be False with a Lambertian base"):
        TraceConfig(substrate=Substrate.lambertian(0.5), coating=VARNISH, coherent=True)


def test_evaluated_on_a_multiple_scattering_smooth_coated_base_is_refused():
    smooth = Coating(n=VARNISH.n, alpha=0.0)
    with pytest.raises(ValueError, match="estimator must be 'counting' or 'auto'"):
        TraceConfig(substrate=Substrate.lambertian(0.5), coating=smooth, estimator="evaluated")


@pytest.mark.slow
def test_coated_base_is_reciprocal_away_from_the_specular_direction():
    # f(theta_a -> theta_b) = f(theta_b -> theta_a) for M00 at the same relative azimuth;
    # bins of 5 deg centred on the angles (their curvature error ~1e-4 of f, far below
    # the ~1 % standard errors); an absorbing coating checks Beer-Lambert's symmetry too
    cfg = TraceConfig(
        rays=100_000,
        block_rays=10_000,
        substrate=Substrate.lambertian(0.8),
        coating=Coating(n=1.5, k=0.002, thickness_nm=500.0, alpha=0.3),
        scattering="single",
        theta_step_deg=5.0,
        phi_step_deg=10.0,
    )
    runs = {th: trace(cfg.replace(theta_i_deg=th)) for th in (20.0, 40.0, 60.0)}
    for phi in (0.0, 90.0):  # backscatter side and out of plane
        j = int(round(phi / 10.0))
        for a, b in ((20.0, 60.0), (40.0, 60.0), (20.0, 40.0)):
            ia, ib = int(round(a / 5.0)), int(round(b / 5.0))
            fab, sab = runs[a].mueller[ib, j, 0, 0], runs[a].mueller_stderr[ib, j, 0, 0]
            fba, sba = runs[b].mueller[ia, j, 0, 0], runs[b].mueller_stderr[ia, j, 0, 0]
            assert abs(fab - fba) < K * np.hypot(sab, sba), (phi, a, b, fab, fba)
