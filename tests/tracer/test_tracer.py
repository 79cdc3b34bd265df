"""Tracer: sampling, analytic limits, invariants, ledger, determinism, I/O and errors.

Statistical tolerances are K standard errors, the errors estimated from the sample
(per-ray or per-block spread) or binomial; K = 4 unless a comment says why otherwise.
"""

from __future__ import annotations

import functools
import json

import numpy as np
import pytest

from labbrdf import optics
from labbrdf.microfacet import ggx
from labbrdf.tracer import (
    Coating,
    Grid,
    Substrate,
    TraceConfig,
    TraceResult,
    trace,
    trace_block,
    trace_summary,
    work_units,
)

K = 4.0
AL = Substrate(n=1.55, k=7.71, alpha=0.2)


def _fresnel_m(n2: complex, theta: float) -> np.ndarray:
    rs, rp, _, _ = optics.fresnel(1.0, n2, theta)
    return optics.mueller_reflection(rs, rp)


# ---------------------------------------------------------------------------- sampling


@pytest.mark.parametrize("alpha", [0.1, 0.4, 1.0])
def test_ggx_d_is_normalised_over_projected_hemisphere(alpha):
    # integral D(m) cos(theta_m) dOmega = 1, by Gauss-Legendre in t = tan(theta)/alpha
    x, w = np.polynomial.legendre.leggauss(400)
    u = 0.5 * (x + 1)  # u in (0, 1) -> theta = arctan(alpha sqrt(u/(1-u))) covers [0, pi/2)
    theta = np.arctan(alpha * np.sqrt(u / (1 - u)))
    dtheta_du = alpha / (2 * np.sqrt(u) * (1 - u) ** 1.5) * np.cos(theta) ** 2
    integrand = ggx.d(np.cos(theta), alpha) * np.cos(theta) * np.sin(theta) * 2 * np.pi
    assert np.sum(0.5 * w * integrand * dtheta_du) == pytest.approx(1.0, rel=1e-10)


def test_smith_g1_matches_closed_form_and_lambda_symmetry():
    alpha = 0.37
    theta = np.radians([0.0, 10.0, 45.0, 80.0, 89.0])
    wz = np.cos(theta)
    g1 = 2 / (1 + np.sqrt(1 + alpha**2 * np.tan(theta) ** 2))
    np.testing.assert_allclose(ggx.smith_g1(wz, alpha), g1, rtol=1e-14)
    np.testing.assert_allclose(ggx.smith_lambda(-wz, alpha), -1 - ggx.smith_lambda(wz, alpha))
    assert ggx.smith_g1(-0.5, alpha) == 0.0


@pytest.mark.parametrize("alpha", [0.1, 0.2, 0.4])
@pytest.mark.parametrize("sampler", ["ggx_cos", "vndf"])
def test_mirror_albedo_at_normal_incidence_is_one_over_one_plus_alpha2(alpha, sampler):
    # oracles README sec. 4: F = 1, G = 1, theta_i = 0 -> A = 1 / (1 + alpha^2) exactly
    rng = np.random.default_rng(11)
    n = 400_000
    u1, u2 = rng.random(n), rng.random(n)
    wi = np.tile(np.array([[0.0], [0.0], [1.0]]), (1, n))
    m = (
        ggx.sample_cos(alpha, u1, u2)
        if sampler == "ggx_cos"
        else ggx.sample_visible(wi, alpha, u1, u2)
    )
    wo_z = -wi[2] + 2 * m[2] * (wi * m).sum(axis=0)
    p = 1 / (1 + alpha**2)
    assert np.mean(wo_z > 0) == pytest.approx(p, abs=K * np.sqrt(p * (1 - p) / n))


@pytest.mark.parametrize("theta_deg", [30.0, 75.0, 120.0, 170.0])
def test_vndf_moments_match_reweighted_ggx_samples(theta_deg):
    # D_wi(m) ~ max(0, wi.m) D(m): the VNDF moments equal those of D cos samples weighted by
    # max(0, wi.m) / cos(theta_m). theta_deg > 90 is a direction below the horizon (walk).
    alpha, n = 0.5, 400_000
    t = np.radians(theta_deg)
    wi1 = np.array([np.sin(t), 0.0, np.cos(t)])
    rng = np.random.default_rng(12)
    mv = ggx.sample_visible(np.repeat(wi1[:, None], n, 1), alpha, rng.random(n), rng.random(n))
    mg = ggx.sample_cos(alpha, rng.random(n), rng.random(n))
    w = np.maximum(0.0, wi1 @ mg) / mg[2]
    for f in (lambda m: m[0], lambda m: m[2], lambda m: m[0] ** 2, lambda m: m[1] ** 2):
        a, b = f(mv), f(mg)
        ref = np.sum(w * b) / np.sum(w)
        se_a = a.std() / np.sqrt(n)
        se_b = np.sqrt(np.sum((w * (b - ref)) ** 2)) / np.sum(w)
        assert a.mean() == pytest.approx(ref, abs=K * np.hypot(se_a, se_b))


@pytest.mark.parametrize("theta_deg", [0.0, 40.0, 80.0])
def test_projected_area_identity_links_lambda_to_d(theta_deg):
    # integral max(0, wi.m) D(m) dOmega = cos(theta_i) (1 + Lambda(wi))   (Heitz 2014)
    alpha, n = 0.6, 1_000_000
    t = np.radians(theta_deg)
    wi = np.array([np.sin(t), 0.0, np.cos(t)])
    rng = np.random.default_rng(13)
    m = ggx.sample_cos(alpha, rng.random(n), rng.random(n))
    x = np.maximum(0.0, wi @ m) / m[2]
    expected = np.cos(t) * (1 + ggx.smith_lambda(np.cos(t), alpha))
    assert x.mean() == pytest.approx(expected, abs=K * x.std() / np.sqrt(n))


# ------------------------------------------------------------------- analytic limits


@pytest.mark.parametrize("theta", [0.0, 20.0, 45.0, 70.0, 85.0])
@pytest.mark.parametrize("scattering", ["single", "multiple"])
def test_smooth_conductor_specular_bin_equals_fresnel_mueller(theta, scattering):
    cfg = TraceConfig(
        rays=500, theta_i_deg=theta, substrate=Substrate(alpha=0.0), scattering=scattering
    )
    res = trace(cfg)
    i, j = np.unravel_index(np.argmax(res.counts), res.counts.shape)
    assert res.counts[i, j] == cfg.rays
    assert res.theta_r_deg[i] == theta
    assert res.phi_r_deg[j] == 180.0
    power = res.sums[i, j] / cfg.rays  # reflected power fraction, all rays in one bin
    np.testing.assert_allclose(power, _fresnel_m(1.55 + 7.71j, theta), rtol=0, atol=1e-12)
    np.testing.assert_allclose(res.hemi, power, rtol=0, atol=1e-15)


def test_mirror_normal_incidence_flips_s2_and_s3():
    res = trace(TraceConfig(rays=10, theta_i_deg=0.0, substrate=Substrate(alpha=0, mirror=True)))
    np.testing.assert_allclose(res.hemi, np.diag([1.0, 1.0, -1.0, -1.0]), atol=1e-15)


@pytest.mark.parametrize("alpha", [0.2, 0.6, 1.0])
@pytest.mark.parametrize("theta", [0.0, 45.0, 80.0])
def test_white_furnace_mirror_multiple_scattering_conserves_energy(alpha, theta):
    cfg = TraceConfig(
        rays=20_000,
        theta_i_deg=theta,
        substrate=Substrate(alpha=alpha, mirror=True),
        scattering="multiple",
        tau=0.0,
        theta_step_deg=5.0,
        phi_step_deg=5.0,
    )
    res = trace(cfg)
    assert res.albedo() == pytest.approx(1.0, abs=1e-3)
    assert res.ledger["terminated"] < 1e-3
    assert res.ledger["absorbed"] == pytest.approx(0.0, abs=1e-12)


@pytest.mark.parametrize("alpha", [0.2, 0.6])
def test_white_furnace_lossless_rough_coating_on_mirror(alpha):
    cfg = TraceConfig(
        rays=20_000,
        theta_i_deg=50.0,
        substrate=Substrate(alpha=alpha, mirror=True),
        coating=Coating(n=1.5, alpha=alpha),
        tau=0.0,
        max_bounces=1000,
        theta_step_deg=5.0,
        phi_step_deg=5.0,
    )
    res = trace(cfg)
    assert res.albedo() == pytest.approx(1.0, abs=1e-3)


def test_single_scattering_energy_below_multiple_scattering():
    # the random walk adds the inter-reflections the single-scattering model terminates
    kw = {"rays": 40_000, "theta_i_deg": 60.0, "theta_step_deg": 5.0, "phi_step_deg": 5.0}
    sub = Substrate(alpha=0.6, mirror=True)
    single = trace(
        TraceConfig(
            substrate=sub, scattering="single", block_rays=2000, estimator="counting", **kw
        )
    )
    assert single.albedo() < 1 - K * single.albedo_stderr()
    assert single.ledger["terminated"] == pytest.approx(1 - single.albedo(), abs=1e-12)


# ------------------------------------------------------------------------------ ledger


@pytest.mark.parametrize(
    "cfg",
    [
        TraceConfig(rays=5000, substrate=AL, scattering="single"),
        TraceConfig(rays=5000, substrate=AL, scattering="multiple"),
        TraceConfig(rays=5000, substrate=AL, coating=Coating(k=0.01, thickness_nm=2000.0)),
        TraceConfig(rays=5000, coating=Coating(), termination="roulette", tau=0.05),
        TraceConfig(
            rays=5000, coating=Coating(), scattering="single", tau=0.05, estimator="counting"
        ),
        TraceConfig(rays=5000, coating=Coating(), max_bounces=2),
    ],
    ids=["single", "multiple", "absorbing-coat", "roulette", "coat-single", "max-bounces"],
)
def test_energy_ledger_closes_per_ray(cfg):
    led = trace(cfg).ledger
    total = led["exited"] + led["absorbed"] + led["terminated"]
    assert total == pytest.approx(1.0, abs=1e-12)


def test_roulette_is_unbiased_against_no_termination():
    kw = {
        "rays": 60_000,
        "coating": Coating(),
        "substrate": Substrate(n=2.43, k=4.0, alpha=0.4),
        "block_rays": 2000,
        "theta_step_deg": 10.0,
        "phi_step_deg": 10.0,
    }
    ref = trace(TraceConfig(tau=0.0, **kw))
    rr = trace(TraceConfig(termination="roulette", tau=0.2, seed=5, **kw))
    assert rr.ledger["terminated"] != 0.0  # roulette did act
    se = np.hypot(ref.albedo_stderr(), rr.albedo_stderr())
    assert rr.albedo() == pytest.approx(ref.albedo(), abs=K * se)


def test_absorbing_coating_loses_energy_with_thickness_lossless_does_not():
    base = {"rays": 4000, "theta_step_deg": 10.0, "phi_step_deg": 10.0}
    thin = trace(TraceConfig(coating=Coating(thickness_nm=100.0), **base))
    thick = trace(TraceConfig(coating=Coating(thickness_nm=400.0), **base))
    np.testing.assert_array_equal(thin.sums, thick.sums)  # lossless: thickness is irrelevant
    lossy = [
        trace(TraceConfig(coating=Coating(k=0.01, thickness_nm=d), **base)).albedo()
        for d in (100.0, 400.0, 1600.0)
    ]
    assert lossy[0] > lossy[1] > lossy[2]


# ------------------------------------------------------------------------- determinism


def test_same_seed_same_result_whatever_the_chunking():
    cfg = TraceConfig(
        rays=9000, block_rays=1000, fold_blocks=2, coating=Coating(), theta_step_deg=2.0
    )
    a = trace(cfg, blocks_per_unit=1)
    b = trace(cfg, blocks_per_unit=4)
    c = trace(cfg, blocks_per_unit=9)
    for other in (b, c):
        np.testing.assert_array_equal(a.sums, other.sums)
        np.testing.assert_array_equal(a.hemi, other.hemi)
        assert a.ledger == other.ledger
    d = trace(cfg.replace(seed=1))
    assert not np.array_equal(a.sums, d.sums)


def test_fold_group_size_changes_only_the_rounding():
    cfg = TraceConfig(rays=9000, block_rays=1000, fold_blocks=1, theta_step_deg=3.0)
    a, b = trace(cfg), trace(cfg.replace(fold_blocks=3))
    # same rays, sums added in another grouping: equal to float64 round-off of ~9 terms
    np.testing.assert_allclose(a.sums, b.sums, rtol=1e-13, atol=1e-13 * np.abs(a.sums).max())
    np.testing.assert_array_equal(a.counts, b.counts)


def test_same_result_on_two_worker_processes():
    parallel = pytest.importorskip("labbrdf.parallel")
    cfg = TraceConfig(
        rays=6000, block_rays=1000, fold_blocks=1, theta_step_deg=3.0, phi_step_deg=3.0
    )
    serial = trace(cfg)
    pmap = functools.partial(parallel.imap, scheduler="processes", workers=2)
    par = trace(cfg, map=pmap, blocks_per_unit=2)
    np.testing.assert_array_equal(serial.sums, par.sums)
    assert serial.ledger == par.ledger


def test_out_of_order_map_is_rejected():
    cfg = TraceConfig(
        rays=2000, block_rays=1000, fold_blocks=1, theta_step_deg=10.0, phi_step_deg=10.0
    )

    def backwards(func, items):
        return reversed([func(x) for x in items])

    with pytest.raises(RuntimeError, match="map returned fold group 1, expected 0"):
        trace(cfg, map=backwards)


# ------------------------------------------------------------------------- reciprocity


@pytest.mark.parametrize(
    ("substrate", "coating", "scattering", "rays"),
    [
        (AL, None, "single", 1_500_000),
        (Substrate(alpha=0.4), Coating(alpha=0.4), "multiple", 300_000),
    ],
    ids=["rough-Al-single", "coated-multiple"],
)
def test_s0_reciprocity_between_swapped_directions(substrate, coating, scattering, rays):
    # f(theta_a -> theta_b, dphi) = f(theta_b -> theta_a, dphi); 3-degree bins, so the
    # curvature bias of bin averages (~(h/w)^2/6 < 0.3 %) stays below the MC error.
    kw = {
        "rays": rays,
        "substrate": substrate,
        "coating": coating,
        "scattering": scattering,
        "theta_step_deg": 3.0,
        "phi_step_deg": 3.0,
        "estimator": "counting",
    }
    ra = trace(TraceConfig(theta_i_deg=30.0, **kw))
    rb = trace(TraceConfig(theta_i_deg=54.0, seed=1, **kw))
    ia, ib = 18, 10  # theta_r = 54 and 30 deg
    for jphi in (60, 50):  # phi_r = 180 and 150 deg
        fa, fb = ra.mueller[ia, jphi, 0, 0], rb.mueller[ib, jphi, 0, 0]
        se = np.hypot(ra.mueller_stderr[ia, jphi, 0, 0], rb.mueller_stderr[ib, jphi, 0, 0])
        assert fa == pytest.approx(fb, abs=K * se)


# -------------------------------------------------------------------------- result, I/O


def test_grid_edges_centres_and_solid_angles():
    g = Grid()
    assert (g.n_theta, g.n_phi) == (91, 360)
    assert g.theta_edges_deg[[0, 1, -2, -1]].tolist() == [0.0, 0.5, 89.5, 90.0]
    assert g.phi_edges_deg[[0, -1]].tolist() == [-0.5, 359.5]
    assert g.solid_angle_sr.sum() == pytest.approx(2 * np.pi, rel=1e-12)
    assert g.cos_solid_angle_sr.sum() == pytest.approx(np.pi, rel=1e-12)


def test_save_load_round_trip_and_npz_keys(tmp_path):
    cfg = TraceConfig(rays=3000, block_rays=1000, coating=Coating(), theta_step_deg=2.0)
    res = trace(cfg)
    path = res.save(tmp_path / "run.npz")
    with np.load(path) as z:
        assert z["mueller"].shape == (46, 360, 4, 4)
        for key in ("theta_r_deg", "phi_r_deg", "theta_r_edges_deg", "phi_r_edges_deg"):
            assert key in z
        assert json.loads(str(z["config"]))["rays"] == 3000
        assert set(json.loads(str(z["ledger"]))) >= {"exited", "absorbed", "terminated"}
    back = TraceResult.load(path)
    assert back.config == cfg
    np.testing.assert_array_equal(back.mueller, res.mueller)
    assert back.albedo([1, 1, 0, 0]) == res.albedo([1, 1, 0, 0])


def test_s0_and_dop_maps_follow_from_the_mueller_matrix():
    res = trace(TraceConfig(rays=20_000, theta_step_deg=5.0, phi_step_deg=5.0))
    m = res.mueller
    s_in = np.array([1.0, 0.0, 0.6, 0.8])
    st = m @ s_in
    np.testing.assert_allclose(res.s0(s_in), st[..., 0])
    ok = res.counts > 0
    dop = np.sqrt((st[..., 1:] ** 2).sum(-1))[ok] / st[..., 0][ok]
    np.testing.assert_allclose(res.dop(s_in)[ok], dop)
    assert np.all(np.isnan(res.dop()[~ok]))
    assert res.albedo() == pytest.approx((m[..., 0, 0] * res.grid.cos_solid_angle_sr).sum())


def test_trace_summary_has_the_cli_keys():
    res = trace(TraceConfig(rays=2000, theta_step_deg=10.0, phi_step_deg=10.0))
    summ = trace_summary(res)
    assert {"albedo", "energy", "rays", "seconds"} <= set(summ)
    assert set(summ["energy"]) == {"exited", "absorbed", "terminated"}
    json.dumps(summ)


def test_config_json_round_trip():
    cfg = TraceConfig(coating=Coating(k=0.01), substrate=Substrate(alpha=0.3), seed=3)
    assert TraceConfig.from_json(cfg.to_json()) == cfg
    # 100000 rays = 4 blocks = 1 fold group of 4; units hold whole groups
    assert work_units(cfg.replace(rays=100_000), 2) == [(cfg.replace(rays=100_000), (0,))]
    one = cfg.replace(rays=100_000, fold_blocks=1)
    assert work_units(one, 2)[0][1] == (0, 1)


# ------------------------------------------------------------------------------ errors


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"wavelength_nm": 0.0}, "wavelength_nm must be a finite number > 0"),
        ({"theta_i_deg": 90.0}, r"theta_i_deg must be in \[0, 90\)"),
        ({"rays": 0}, "rays must be a positive integer"),
        ({"seed": -1}, "seed must be a non-negative integer"),
        ({"scattering": "double"}, "scattering must be one of"),
        ({"termination": "none"}, "termination must be one of"),
        ({"tau": 1.5}, r"tau must be in \[0, 1\)"),
        ({"max_bounces": 0}, "max_bounces must be an integer >= 1"),
        ({"theta_step_deg": 7.0}, "theta_step_deg must be a positive divisor of 90"),
        ({"phi_step_deg": 0.0}, "phi_step_deg must be a positive divisor of 360"),
        ({"coherent": True}, "coherent must be False when there is no coating"),
        ({"block_rays": 0}, "block_rays must be an integer >= 1"),
        ({"substrate": "Al"}, "substrate must be a Substrate"),
        (
            {"coherent": True, "coating": Coating(), "substrate": Substrate(mirror=True)},
            "coherent must be False with an ideal-mirror substrate",
        ),
    ],
)
def test_bad_config_raises_naming_the_field(kwargs, match):
    with pytest.raises(ValueError, match=match):
        TraceConfig(**kwargs)


@pytest.mark.parametrize(
    ("factory", "match"),
    [
        (lambda: Substrate(k=-1.0), "substrate.k must be a finite number >= 0"),
        (lambda: Substrate(alpha=-0.1), r"substrate.alpha must be in \[0, 10\]"),
        (lambda: Substrate(n=0.0, k=0.0), "substrate n \\+ ik must be non-zero"),
        (lambda: Coating(n=0.0), "coating.n must be a finite number > 0"),
        (lambda: Coating(thickness_nm=-5.0), "coating.thickness_nm must be"),
        (lambda: Coating(alpha=float("inf")), "coating.alpha must be in"),
        (lambda: TraceConfig.from_dict({"rays": 10, "colour": 1}), "unknown TraceConfig keys"),
    ],
)
def test_bad_layers_raise_naming_the_field(factory, match):
    with pytest.raises(ValueError, match=match):
        factory()


def test_bad_calls_raise():
    cfg = TraceConfig(rays=100, theta_step_deg=10.0, phi_step_deg=10.0)
    with pytest.raises(TypeError, match="config must be a TraceConfig"):
        trace({"rays": 100})
    with pytest.raises(ValueError, match="blocks_per_unit must be a positive integer"):
        trace(cfg, blocks_per_unit=0)
    with pytest.raises(ValueError, match=r"block must be in \[0, 1\)"):
        trace_block(cfg, 1)
    res = trace(cfg)
    with pytest.raises(ValueError, match="stokes_in must be 4 finite numbers"):
        res.s0([1.0, 0.0])
    with pytest.raises(ValueError, match="stokes_in must have S0 > 0 and DOP <= 1"):
        res.dop([1.0, 2.0, 0.0, 0.0])


def test_loading_a_foreign_file_raises(tmp_path):
    p = tmp_path / "other.npz"
    np.savez(p, a=np.zeros(3))
    with pytest.raises(ValueError, match="not a labbrdf TraceResult"):
        TraceResult.load(p)


# ------------------------------------------------------- structure-aware Mueller kernels


def test_structure_aware_kernels_equal_generic_mueller_products():
    from labbrdf.tracer.interfaces import apply_fresnel, fresnel_abcs, rotate_frame

    rng = np.random.default_rng(21)
    n = 7
    M = rng.normal(size=(4, 4, n))
    cos_i = rng.uniform(0.05, 1.0, n)
    # reflection and transmission numbers vs the optics core's 4x4 matrices
    refl, trans, cos_t = fresnel_abcs(1.0, 1.5, cos_i)
    rs, rp, ts, tp, ct = optics.fresnel_cos(1.0, 1.5, cos_i)
    fac = optics.transmission_factor(1.0, 1.5, cos_i, ct)
    for (a, b, c, s), ref in (
        (refl, optics.mueller_reflection(rs, rp)),
        (trans, optics.mueller_transmission(ts, tp, fac)),
    ):
        out = M.copy()
        apply_fresnel(out, a, b, c, s)
        np.testing.assert_allclose(np.moveaxis(out, 2, 0), ref @ np.moveaxis(M, 2, 0), atol=1e-14)
    # frame rotation vs mueller_rotation with the angle from s_old to s_new about k
    k = np.tile([[0.0], [0.0], [-1.0]], (1, n))
    s_old = np.tile([[1.0], [0.0], [0.0]], (1, n))
    ang = rng.uniform(-180, 180, n)
    p_old = np.tile([[0.0], [-1.0], [0.0]], (1, n))  # k x s_old
    a = np.radians(ang)
    s_new = np.cos(a) * s_old + np.sin(a) * p_old
    out = M.copy()
    rotate_frame(out, k, s_old, s_new)
    ref = optics.mueller_rotation(ang) @ np.moveaxis(M, 2, 0)
    np.testing.assert_allclose(np.moveaxis(out, 2, 0), ref, atol=1e-14)


def test_stderr_needs_two_blocks():
    res = trace(TraceConfig(rays=100, theta_step_deg=10.0, phi_step_deg=10.0))
    assert np.isnan(res.albedo_stderr())
    assert np.all(np.isnan(res.hemi_stderr()))


@pytest.mark.parametrize(("alpha", "theta"), [(0.4, 30.0), (1.0, 70.0)])
def test_first_order_of_height_walk_is_height_correlated_smith(alpha, theta):
    # Heitz et al. 2016: with uniform heights, a ray reflected once escapes with probability
    # G2/G1(wi) = (1 + Lambda_i) / (1 + Lambda_i + Lambda_o), the height-correlated Smith
    # term. With max_bounces=1 the walk's albedo on a mirror is E_vndf[that * (wo_z > 0)].
    cfg = TraceConfig(
        rays=200_000,
        block_rays=5000,
        theta_i_deg=theta,
        substrate=Substrate(alpha=alpha, mirror=True),
        max_bounces=1,
        tau=0.0,
        theta_step_deg=10.0,
        phi_step_deg=10.0,
    )
    res = trace(cfg)
    n = 1_000_000
    t = np.radians(theta)
    wi = np.repeat(np.array([[np.sin(t)], [0.0], [np.cos(t)]]), n, 1)
    rng = np.random.default_rng(31)
    m = ggx.sample_visible(wi, alpha, rng.random(n), rng.random(n))
    wo_z = -wi[2] + 2 * m[2] * (wi * m).sum(axis=0)
    lam_i = ggx.smith_lambda(np.cos(t), alpha)
    up = wo_z > 0
    x = np.where(
        up, (1 + lam_i) / (1 + lam_i + ggx.smith_lambda(np.where(up, wo_z, 1.0), alpha)), 0
    )
    se = np.hypot(res.albedo_stderr(), x.std() / np.sqrt(n))
    assert res.albedo() == pytest.approx(x.mean(), abs=K * se)
    if alpha == 1.0:  # rough and grazing: distinct from the separable form G1(wo)
        sep = np.where(up, ggx.smith_g1(np.where(up, wo_z, 1.0), alpha), 0.0).mean()
        assert abs(sep - x.mean()) > 10 * se


def test_package_level_trace_is_the_tracer():
    import labbrdf

    assert labbrdf.trace is trace
    assert labbrdf.TraceConfig is TraceConfig
