"""The scattering coating: a Henyey-Greenstein medium in the coating (``Coating.medium``).

Independent checks: the HG phase function's normalisation and mean cosine by quadrature;
its sampling against the phase function (mean cosine and a histogram, z over every bin);
the unscattered fraction of a crossing against Beer-Lambert; the singly scattered light
of a slab against the closed-form single-scattering BRDF (derived below); the tracer with
a non-scattering medium against a clear coating with the same extinction; the white
furnace with a lossless medium; reciprocity; the evaluated estimator against counting.
Statistical tolerances are K = 4 standard errors.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import integrate

from labbrdf.tracer import Coating, Medium, Substrate, TraceConfig, trace
from labbrdf.tracer.agreement import agreement
from labbrdf.tracer.medium import cross_slab, hg_phase, hg_sample_cos, traverse

K = 4.0


# ------------------------------------------------------------------ the phase function


@pytest.mark.parametrize("g", [-0.6, 0.0, 3e-7, 0.3, 0.85])
def test_hg_phase_is_normalised_with_mean_cosine_g(g):
    norm = integrate.quad(lambda c: 2 * np.pi * hg_phase(c, g), -1, 1, epsabs=1e-12)[0]
    mean = integrate.quad(lambda c: 2 * np.pi * c * hg_phase(c, g), -1, 1, epsabs=1e-12)[0]
    assert norm == pytest.approx(1.0, abs=1e-9)
    assert mean == pytest.approx(g, abs=1e-9)


@pytest.mark.parametrize("g", [-0.6, 0.0, 3e-7, 0.3, 0.85])
def test_hg_sampling_follows_the_phase_function(g):
    # mean cosine g and the histogram of cos theta against the phase function integrated
    # over each bin (40 bins, the smallest expected counts included: z over all bins)
    n = 200_000
    mu = hg_sample_cos(g, np.random.default_rng(1).random(n))
    assert abs(mu.mean() - g) < K * mu.std() / np.sqrt(n)
    edges = np.linspace(-1.0, 1.0, 41)
    obs = np.histogram(mu, edges)[0]
    p = np.array(
        [
            integrate.quad(lambda c: 2 * np.pi * hg_phase(c, g), a, b, epsabs=1e-13)[0]
            for a, b in zip(edges[:-1], edges[1:], strict=True)
        ]
    )
    z = (obs - n * p) / np.sqrt(n * p * (1 - p))
    assert np.abs(z).max() < 4.5  # 40 bins: P(max |z| > 4.5) ~ 3e-4
    assert np.mean(z * z) < 1.6  # chi2 / 40 (P ~ 1e-2 beyond 1.6)


# ------------------------------------------------------------------ one crossing


def _down(theta_deg: float, n: int) -> tuple[np.ndarray, np.ndarray]:
    """``n`` rays travelling down into the slab at ``theta_deg``, azimuth 0."""
    th = np.radians(theta_deg)
    k = np.tile([[np.sin(th)], [0.0], [-np.cos(th)]], n)
    s = np.tile([[0.0], [1.0], [0.0]], n)
    return k, s


def test_unscattered_rays_follow_beer_lambert():
    # the unscattered fraction is exp(-tau / mu) (binomial), its weight the coating's own
    # absorption exp(-a / mu) exactly; without scattering the weight is exp(-(tau + a) / mu)
    n, mu, a = 100_000, np.cos(np.radians(50.0)), 0.2
    k, s = _down(50.0, n)
    c = cross_slab(Medium(0.7, 0.5, 0.4), a, k, s, np.random.default_rng(2))
    direct = c.events == 0
    p = np.exp(-0.7 / mu)
    assert abs(direct.mean() - p) < K * np.sqrt(p * (1 - p) / n)
    assert not c.up[direct].any()
    np.testing.assert_allclose(c.weight[direct], np.exp(-a / mu), rtol=1e-13)
    np.testing.assert_array_equal(c.k[:, direct], k[:, direct])
    dark = cross_slab(Medium(0.7, 0.0, 0.4), a, k, s, np.random.default_rng(2))
    np.testing.assert_allclose(dark.weight, np.exp(-(0.7 + a) / mu), rtol=1e-13)
    assert not dark.scattered.any() and not dark.up.any()


def test_scattered_rays_keep_only_their_intensity_row():
    # over a conductor (no base event): an unscattered ray keeps its Mueller matrix times
    # the attenuation, a scattered one only the intensity row; frames stay perpendicular
    # to the directions and the M00 ledger closes
    n = 5000
    k, s = _down(30.0, n)
    k0 = k.copy()
    M = np.tile(np.eye(4)[:, :, None], n)
    ab, up, based = traverse(
        Medium(1.0, 0.9, 0.3), 0.05, np.random.default_rng(4), np.arange(n), k, s, M, None
    )
    moved = np.any(k != k0, axis=0)
    assert 0.2 < moved.mean() < 0.9 and based.size == 0
    assert not M[1:, :, moved].any() and (M[0, 0, moved] >= 0).all()
    w = M[0, 0, ~moved]
    np.testing.assert_array_equal(M[:, :, ~moved], np.eye(4)[:, :, None] * w)
    assert np.abs((k * s).sum(axis=0)).max() < 1e-12
    assert ab + M[0, 0].sum() == pytest.approx(n, rel=1e-12)
    assert (up == (k[2] > 0)).all()


def _single_scattering_brdf(mu_i, mu_o, cos_scat, tau, ssa, g, a):
    """BRDF [sr^-1] of the light scattered once in a slab over a black base, no interfaces.

    The beam at depth z (in units of the thickness) is ``E exp(-(tau + a) z / mu_i)`` per
    unit area across it; a path element ``dz / mu_o`` towards the viewer scatters
    ``ssa tau p(cos) dz / mu_o`` of it into unit solid angle, attenuated by
    ``exp(-(tau + a) z / mu_o)`` on the way out. Integrating over z and dividing by the
    irradiance ``E mu_i``:
    ``f = ssa tau p (1 - exp(-(tau + a)(1/mu_i + 1/mu_o))) / ((tau + a)(mu_i + mu_o))``,
    with p per steradian (for a = 0 the classic ``ssa p / (mu_i + mu_o) (1 - exp(...))``,
    i.e. ``ssa P / (4 pi (mu_i + mu_o)) (...)`` with P normalised to 4 pi).
    """
    e = tau + a
    return (
        ssa
        * tau
        * hg_phase(cos_scat, g)
        * -np.expm1(-e * (1 / mu_i + 1 / mu_o))
        / (e * (mu_i + mu_o))
    )


def test_singly_scattered_light_matches_the_closed_form():
    # rays that leave through the top after exactly one event, binned in (theta_o,
    # phi_o), against the closed form integrated over each bin (midpoint rule on a fine
    # sub-grid: error ~1e-4 of a bin's value); every bin tested
    n, th_i, tau, ssa, g, a = 200_000, 30.0, 0.5, 0.8, 0.6, 0.1
    k, s = _down(th_i, n)
    c = cross_slab(Medium(tau, ssa, g), a, k, s, np.random.default_rng(3))
    once = c.up & (c.events == 1)
    w = np.where(once, c.weight, 0.0)
    t_edges, p_edges = np.linspace(0, 90, 10), np.linspace(0, 360, 13)
    th = np.degrees(np.arccos(np.clip(c.k[2], -1, 1)))
    ph = np.degrees(np.arctan2(c.k[1], c.k[0])) % 360
    it = np.clip(np.digitize(th, t_edges) - 1, 0, 8)
    ip = np.clip(np.digitize(ph, p_edges) - 1, 0, 11)
    flat = it * 12 + ip
    s1 = np.bincount(flat, w, 108) / n
    s2 = np.bincount(flat, w * w, 108) / n
    se = np.sqrt((s2 - s1 * s1) / n)
    mu_i, si = np.cos(np.radians(th_i)), np.sin(np.radians(th_i))
    expect = np.empty(108)
    for b in range(108):
        tt = np.radians(np.linspace(t_edges[b // 12], t_edges[b // 12 + 1], 61))
        pp = np.radians(np.linspace(p_edges[b % 12], p_edges[b % 12 + 1], 61))
        tm, pm = 0.5 * (tt[1:] + tt[:-1]), 0.5 * (pp[1:] + pp[:-1])
        T, P = np.meshgrid(tm, pm, indexing="ij")
        mu_o = np.cos(T)
        cos_scat = si * np.sin(T) * np.cos(P) - mu_i * mu_o
        f = _single_scattering_brdf(mu_i, mu_o, cos_scat, tau, ssa, g, a)
        expect[b] = (f * mu_o * np.sin(T)).sum() * (tt[1] - tt[0]) * (pp[1] - pp[0])
    z = (s1 - expect) / se
    assert np.abs(z).max() < 4.5, np.abs(z).max()  # 108 bins
    assert np.mean(z * z) < 1.5


# ------------------------------------------------------------------ in the tracer


def _diffuse(medium, **kw):
    return TraceConfig(
        substrate=Substrate.lambertian(kw.pop("albedo", 0.8)),
        coating=Coating(n=1.5, k=kw.pop("k", 0.0), thickness_nm=500.0, alpha=0.3, medium=medium),
        scattering="single",
        theta_step_deg=5.0,
        phi_step_deg=10.0,
        **kw,
    )


def test_a_medium_that_does_not_scatter_is_extinction():
    # ssa = 0: the medium is Beer-Lambert with optical thickness tau along the normal,
    # i.e. a clear coating whose k adds tau lambda / (4 pi d); no random numbers are drawn
    # in the medium, so both walks take the same rays (same arithmetic up to exp(a) exp(b)
    # against exp(a + b))
    tau, lam, d = 0.8, 650.0, 500.0
    cfg = _diffuse(Medium(tau, 0.0, 0.5), k=0.01, rays=20_000, block_rays=10_000)
    clear = cfg.replace(
        coating=Coating(n=1.5, k=0.01 + tau * lam / (4 * np.pi * d), thickness_nm=d, alpha=0.3)
    )
    a, b = trace(cfg), trace(clear)
    np.testing.assert_allclose(a.mueller, b.mueller, rtol=1e-9, atol=1e-15)
    assert (
        a.albedo()
        < 0.5
        * trace(cfg.replace(coating=Coating(n=1.5, k=0.01, thickness_nm=d, alpha=0.3))).albedo()
    )


def test_white_furnace_with_a_lossless_medium():
    # ssa = 1, lossless coating, white base, multiple scattering on the top: every ray
    # leaves with its weight (the counting walk's weights stay 1): albedo 1 to round-off
    cfg = _diffuse(
        Medium(2.0, 1.0, 0.7),
        albedo=1.0,
        rays=20_000,
        block_rays=10_000,
        max_bounces=10_000,
    ).replace(scattering="multiple", estimator="counting")
    res = trace(cfg)
    assert res.albedo() == pytest.approx(1.0, abs=1e-12)
    lossy = trace(
        cfg.replace(
            coating=Coating(n=1.5, thickness_nm=500.0, alpha=0.3, medium=Medium(2.0, 0.95, 0.7))
        )
    )
    assert lossy.albedo() + K * lossy.albedo_stderr() < 1.0


def test_brdf_with_a_medium_is_reciprocal():
    # f(a -> b) = f(b -> a) for M00 at the same relative azimuth (5-degree bins centred on
    # the angles), a forward-scattering medium over a grey base
    cfg = _diffuse(Medium(1.0, 0.9, 0.6), rays=40_000, block_rays=10_000)
    runs = {th: trace(cfg.replace(theta_i_deg=th)) for th in (20.0, 60.0)}
    for phi in (0.0, 90.0, 180.0):
        j = int(round(phi / 10.0))
        fab, sab = runs[20.0].mueller[12, j, 0, 0], runs[20.0].mueller_stderr[12, j, 0, 0]
        fba, sba = runs[60.0].mueller[4, j, 0, 0], runs[60.0].mueller_stderr[4, j, 0, 0]
        assert abs(fab - fba) < K * np.hypot(sab, sba), (phi, fab, fba)


def test_evaluated_estimator_agrees_with_counting_through_a_medium():
    cfg = _diffuse(Medium(1.0, 0.9, 0.6), theta_i_deg=40.0, rays=40_000, block_rays=10_000)
    ev = trace(cfg.replace(estimator="evaluated"))
    co = trace(cfg.replace(estimator="counting"))
    ag = agreement(ev, co, min_count=200, elements="m00")
    assert np.abs(ag.z).max() < 5.0
    assert 0.7 < ag.rms < 1.3
    assert abs(ag.albedo_z) < K


# ------------------------------------------------------------------ configuration


def test_medium_config_round_trips_and_refuses_bad_values():
    cfg = _diffuse(Medium(1.5, 0.9, -0.2))
    assert TraceConfig.from_json(cfg.to_json()) == cfg
    clear = _diffuse(None)
    assert "medium" not in clear.to_json()  # a clear coating's JSON as before the field
    for bad, what in (
        (dict(tau=-1.0), "tau"),
        (dict(tau=30.0), "tau"),
        (dict(ssa=1.5), "ssa"),
        (dict(g=1.0), "g"),
        (dict(g=float("nan")), "g"),
    ):
        with pytest.raises(ValueError, match=f"coating.medium.{what} must be"):
            Medium(**bad)
    with pytest.raises(ValueError, match="a dict of tau, ssa and g"):
        Coating(medium={"tau": 1.0, "albedo": 0.5})
    with pytest.raises(ValueError, match="coating.medium must be a Medium"):
        Coating(medium=1.0)
    with pytest.raises(ValueError, match="coherent must be False with a scattering coating"):
        TraceConfig(coating=Coating(medium=Medium()), coherent=True)
