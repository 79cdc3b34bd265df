"""The layered (coating over conductor) model evaluated by the tracer."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from labbrdf import models
from labbrdf.models import ModelError

AL = {"n": 1.55, "k": 7.71}


def _points(theta_i_deg: float = 45.0, n: int = 40) -> tuple[np.ndarray, ...]:
    tr = np.radians(np.linspace(2.0, 80.0, n))
    return np.full(n, np.radians(theta_i_deg)), tr, np.full(n, np.pi)


def test_layered_is_registered_and_names_its_parameters():
    m = models.get("layered", **AL)
    assert "layered" in models.names()
    assert list(m.params) == ["n_coat", "alpha_top", "alpha_sub", "scale"]
    assert not m.params["n_coat"].vary
    coh = models.get("layered", coherent=True, floor=True, **AL)
    assert list(coh.params) == ["n_coat", "alpha_top", "thickness_nm", "scale", "kd"]
    assert coh.linear == ("scale", "kd")
    dif = models.get("layered", base="diffuse")
    assert list(dif.params) == ["n_coat", "alpha_top", "albedo", "scale"]


@pytest.mark.parametrize(
    ("options", "words"),
    [
        ({}, "needs the substrate index n="),
        ({"base": "glass", **AL}, "'base' must be one of"),
        ({"rays": 10, **AL}, "'rays' must be an integer in [1000, 1e7]"),
        ({"grid": "4x7", **AL}, "theta step must be one of"),
        ({"grid": "fine", **AL}, "'grid' must be 'auto', 'THETAxPHI'"),
        ({"coating_k": -1.0, **AL}, "'coating_k' must be >= 0"),
        ({"n": 0.0, "k": 0.0}, "not both 0"),
        ({"floor": "maybe", **AL}, "'floor' must be true or false"),
        ({"colour": 1, **AL}, "unknown options ['colour']"),
        ({"base": "diffuse", **AL}, "takes no substrate index n, k"),
        ({"base": "diffuse", "coherent": True}, "coherent=True needs base='conductor'"),
        ({"distribution": "gauss", **AL}, "'distribution' must be one of ['ggx', 'beckmann'"),
        ({"distribution": "beckmann", "base": "diffuse"}, "coated Lambertian base is written"),
        ({"distribution": "beckmann", "coherent": True, **AL}, "coherent mode's facets are GGX"),
        ({"scattering": "double", "base": "diffuse"}, "'scattering' must be 'single' or"),
        ({"scattering": "multiple", "coherent": True, **AL}, "needs the incoherent coating"),
        ({"scattering": "multiple", "distribution": "beckmann", **AL}, "distribution='ggx'"),
    ],
)
def test_bad_options_are_refused_by_name(options, words):
    with pytest.raises(ModelError) as exc:
        models.get("layered", **options)
    assert words in str(exc.value)


def test_coherent_zero_thickness_equals_the_closed_form_microfacet():
    """A 0 nm coherent film is the bare conductor: the closed-form GGX microfacet model.

    Checks the plumbing (angles, azimuth convention, interpolation of bin averages) against
    an independent closed form. A 1 x 2 degree grid against a lobe of alpha = 0.3: the
    interpolated bin averages differ from point values by ~(h / lobe)^2 / 8 < 0.1 %.
    """
    lay = models.get("layered", coherent=True, grid="1x2", **AL)
    mf = models.get("microfacet", **AL)
    ti, tr, pr = _points(40.0, 60)
    pr = np.where(np.arange(tr.size) % 2, np.pi, np.radians(150.0))
    f = lay.evaluate(ti, tr, pr, params={"alpha_top": 0.3, "thickness_nm": 0.0})
    g = mf.evaluate(ti, tr, pr, params={"alpha": 0.3})
    big = g > 0.05 * g.max()
    assert big.sum() > 30
    np.testing.assert_allclose(f[big], g[big], rtol=5e-3)
    # no Monte Carlo in the coherent mode: no variance
    assert np.all(lay.point_variance(lay.values(), ti, tr, pr, None) == 0)


def test_a_black_diffuse_base_leaves_the_closed_form_rough_dielectric():
    """Albedo 0: only the coating's first-surface reflection is left, which is the
    closed-form GGX microfacet model of the dielectric n = 1.5 (no Monte Carlo noise)."""
    lay = models.get("layered", base="diffuse", grid="1x2")
    mf = models.get("microfacet", n=1.5, k=0.0)
    ti, tr, pr = _points(30.0, 60)
    f = lay.evaluate(ti, tr, pr, params={"alpha_top": 0.3, "albedo": 0.0})
    g = mf.evaluate(ti, tr, pr, params={"alpha": 0.3})
    big = g > 0.05 * g.max()
    assert big.sum() > 30
    np.testing.assert_allclose(f[big], g[big], rtol=5e-3)
    # a white base adds light everywhere, most where the first surface reflects least
    w = lay.evaluate(ti, tr, pr, params={"alpha_top": 0.3, "albedo": 1.0})
    assert np.all(w[big] > f[big])


def test_common_random_numbers_make_the_brdf_a_deterministic_smooth_function():
    """Same seed: a 1e-6 change of alpha_top moves the BRDF by far less than the noise.

    With a different seed the difference is the Monte Carlo noise (percent level), so the
    test fails if the traces were not seeded identically.
    """
    ti, tr, pr = _points(45.0)
    kw = {"grid": "3x6", "rays": 4000, **AL}
    a = models.get("layered", seed=3, **kw)
    b = models.get("layered", seed=3, **kw)
    c = models.get("layered", seed=4, **kw)
    p = {"alpha_top": 0.25, "alpha_sub": 0.3}
    fa = a.evaluate(ti, tr, pr, params=p)
    assert np.array_equal(fa, b.evaluate(ti, tr, pr, params=p))
    near = b.evaluate(ti, tr, pr, params={**p, "alpha_top": 0.25 * (1 + 1e-6)})
    other = c.evaluate(ti, tr, pr, params=p)
    step = np.max(np.abs(near - fa) / fa)
    noise = np.max(np.abs(other - fa) / fa)
    assert step < 1e-4
    assert noise > 1e-3
    assert noise > 50 * step


def test_point_variance_is_the_tracer_error_and_falls_with_the_rays():
    """The variance at the points shrinks about as 1 / rays (batch error estimates)."""
    ti, tr, pr = _points(45.0)
    p = {"alpha_top": 0.25, "alpha_sub": 0.3}
    v1 = models.get("layered", grid="3x6", rays=2000, **AL).point_variance(p, ti, tr, pr, None)
    v4 = models.get("layered", grid="3x6", rays=8000, **AL).point_variance(p, ti, tr, pr, None)
    assert np.all(v1 > 0)
    ratio = np.median(v1) / np.median(v4)
    assert 2.0 < ratio < 8.0


def test_the_auto_grid_follows_the_data_density():
    """209 points per incidence (the Radiant file's 19 x 11): 9.9 deg apart, 3 x 6 deg bins.

    Sparser data would allow coarser bins, but "auto" stops at 3 x 6 (interpolation bias).
    """
    m = models.get("layered", coherent=True, **AL)
    n = 209
    ti = np.radians(np.full(n, 30.0))
    m.evaluate(ti, np.radians(np.linspace(0, 80, n)), np.pi)
    assert m.grid_deg == (3.0, 6.0)
    assert m.options["grid"] == "3x6"
    dense = models.get("layered", coherent=True, **AL)
    dense.evaluate(np.radians(np.full(2000, 30.0)), np.radians(np.linspace(0, 80, 2000)), np.pi)
    assert dense.grid_deg == (1.0, 3.0)


def test_hemispherical_is_the_traced_albedo_plus_the_floor():
    """Bare limit (0 nm coherent film): the albedo is below 1 and the floor adds kd."""
    m = models.get("layered", coherent=True, floor=True, grid="3x6", **AL)
    p = {"alpha_top": 0.3, "thickness_nm": 0.0, "kd": 0.0}
    r0 = m.hemispherical([30.0], p)
    r1 = m.hemispherical([30.0], {**p, "kd": 0.1})
    assert r0 is not None and r1 is not None
    assert 0.7 < r0[0] < 1.0
    assert r1[0] - r0[0] == pytest.approx(0.1, abs=1e-12)


def test_a_nearly_smooth_coating_keeps_its_energy():
    """alpha_top 0.02 (the lowest the model accepts) over a Lambertian base, 3 x 6 grid:
    the model's albedo (closed form) agrees with the counting walk's within 4 standard
    errors, and so does the evaluated walk's (the exit operator had made it 6 % low,
    z -50; the exit is now sampled there)."""
    from labbrdf.tracer import Coating, Substrate, TraceConfig, trace

    lay = models.get("layered", base="diffuse", grid="3x6", rays=20_000, seed=1)
    p = {"alpha_top": 0.02, "albedo": 0.8}
    got = lay.hemispherical([45.0], p)
    assert got is not None
    ev = trace(lay._config(lay.values(p), 45.0, 550.0))
    cfg = TraceConfig(
        theta_i_deg=45.0,
        substrate=Substrate.lambertian(0.8),
        coating=Coating(n=1.5, alpha=0.02, thickness_nm=1000.0),
        scattering="single",
        estimator="counting",
        rays=100_000,
        seed=7,
        theta_step_deg=3.0,
        phi_step_deg=6.0,
    )
    ct = trace(cfg)
    assert abs(got[0] - ct.albedo()) < 4 * ct.albedo_stderr()
    se = np.hypot(ev.albedo_stderr(), ct.albedo_stderr())
    assert abs(ev.albedo() - ct.albedo()) < 4 * se


def test_multiple_scattering_over_a_white_base_returns_all_the_light(monkeypatch):
    """Lossless coating, white base, alpha_top 0.3: the model's albedo is 1 (to 4e-3 with
    the tables' walks) where single scattering's is 0.69; the option round-trips; the
    tables' seed is the model's (seed replicates), and another seed moves the value by its
    Monte Carlo error only."""
    from labbrdf.tracer import coated_lambert_table as tb

    monkeypatch.setattr(tb, "ALPHA_RANGE", (0.28, 0.36))  # four nodes: cheap walks
    tb.clear_memory()
    p = {"alpha_top": 0.3, "albedo": 1.0}
    try:
        lay = models.get("layered", base="diffuse", scattering="multiple", grid="3x6")
        got = lay.hemispherical([20.0, 60.0], p)
        other = lay.reseeded(1).hemispherical([20.0], p)
    finally:
        tb.clear_memory()
    single = models.get("layered", base="diffuse", grid="3x6").hemispherical([20.0], p)
    assert got is not None and single is not None and other is not None
    np.testing.assert_allclose(got, 1.0, atol=4e-3)
    assert other[0] != got[0] and abs(other[0] - got[0]) < 4e-3
    assert single[0] < 0.7
    assert lay.options["scattering"] == "multiple" and lay.fd_rel_step is None
    assert lay.stochastic and lay.default_replicates == 3


def test_points_near_the_normal_evaluate_without_a_warning():
    """The exit operator is averaged over the internal cells near the pole, so points
    near the normal need no caveat (the bias it had there is checked against counting in
    tests/tracer/test_operator_pole.py)."""
    ti, tr, pr = _points(0.0, 10)  # theta_r from 2 deg
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        lay = models.get("layered", grid="3x6", rays=1000, **AL)
        val = lay.evaluate(ti, tr, pr, params={"alpha_top": 0.2, "alpha_sub": 0.2})
        dif = models.get("layered", base="diffuse", grid="3x6")
        dif.evaluate(ti, tr, pr, params={"alpha_top": 0.2, "albedo": 0.5})
    assert np.all(np.isfinite(val)) and np.all(val > 0)
    assert not dif.stochastic


def test_a_beckmann_coating_traces_both_interfaces_through_their_slope_tables():
    """``distribution='beckmann'`` puts the Beckmann table on the top and on the conductor.

    The model's map is the tracer's own run of the configuration that ``labbrdf trace
    --distribution beckmann`` builds (same seed, same arithmetic: equal arrays); a model that
    left either interface GGX traces another surface and differs by far more than the noise.
    """
    from labbrdf.microfacet import TabulatedNDF, beckmann
    from labbrdf.tracer import Coating, Substrate, TraceConfig, trace

    kw = {"grid": "3x6", "rays": 2000, **AL}
    m = models.get("layered", distribution="beckmann", **kw)
    assert m.options["distribution"] == "beckmann"
    assert "distribution" not in models.get("layered", **kw).options
    p = {"n_coat": 1.5, "alpha_top": 0.2, "alpha_sub": 0.3, "scale": 1.0}
    got, _ = m.trace_maps(p, 45.0, 550.0)
    cfg = TraceConfig(
        wavelength_nm=550.0,
        theta_i_deg=45.0,
        substrate=Substrate(n=1.55, k=7.71, alpha=0.3, ndf=TabulatedNDF.of(beckmann, 0.3)),
        coating=Coating(n=1.5, thickness_nm=1000.0, alpha=0.2, ndf=TabulatedNDF.of(beckmann, 0.2)),
        rays=2000,
        seed=0,
        scattering="single",
        estimator="evaluated",
        theta_step_deg=3.0,
        phi_step_deg=6.0,
    )
    want = np.asarray(trace(cfg).mueller[..., 0, 0], float)
    assert np.array_equal(got, want)
    ggx, _ = models.get("layered", **kw).trace_maps(p, 45.0, 550.0)
    assert np.max(np.abs(ggx - got)) > 0.05 * np.max(got)
