"""microfacet (GGX, Smith, Fresnel): BRDF and 16-element Mueller BRDF vs SCATMECH and Mitsuba."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from scipy.integrate import trapezoid

from labbrdf import models, optics
from labbrdf.integrate import reciprocity_defect
from labbrdf.microfacet import ggx
from labbrdf.models import ModelError
from labbrdf.models.microfacet import stokes_from_jones

M_COLS = [f"f_M{i}{j}" for i in range(4) for j in range(4)]
EPS = np.finfo(float).eps


def _half_ulp_10_digits(ref: np.ndarray) -> np.ndarray:
    """Half a unit in the 10th significant digit (the oracle CSVs print %.10g)."""
    ref = np.asarray(ref, dtype=float)
    mag = np.floor(np.log10(np.abs(ref), where=ref != 0, out=np.full_like(ref, -300.0)))
    return 0.5 * 10.0 ** (mag - 9)


def _load(oracles: Path, name: str) -> pd.DataFrame:
    return pd.read_csv(oracles / name)


@pytest.fixture(
    scope="module", params=["rough_conductor_inplane.csv", "rough_conductor_outofplane.csv"]
)
def rough_conductor(request, oracles: Path) -> pd.DataFrame:
    return _load(oracles, request.param)


def _configs(df: pd.DataFrame, source: str):
    sub = df[df.source == source]
    assert len(sub) > 0
    for (n, k, alpha, ti), g in sub.groupby(["n", "k", "alpha", "theta_i_deg"]):
        m = models.get(
            "microfacet", n=n, k=k, shadowing="none" if "noshadow" in source else "smith"
        )
        yield m, alpha, ti, g


def _mueller(m, alpha, ti, g) -> np.ndarray:
    return m.mueller(
        math.radians(ti),
        np.radians(g.theta_r_deg.to_numpy()),
        np.radians(g.phi_r_deg.to_numpy()),
        params={"alpha": alpha},
    ).reshape(-1, 16)


def _check_scatmech(df: pd.DataFrame, source: str) -> float:
    worst = 0.0
    for m, alpha, ti, g in _configs(df, source):
        got, ref = _mueller(m, alpha, ti, g), g[M_COLS].to_numpy()
        peak = ref[:, 0].max()
        # half a unit in the 10th significant digit, plus float64 round-off of both codes
        tol = _half_ulp_10_digits(ref) + 1e-14 * peak
        assert np.all(np.abs(got - ref) <= tol)
        worst = max(worst, float(np.max(np.abs(got - ref)) / peak))
    return worst


def test_mueller_brdf_matches_scatmech_all_16_elements(rough_conductor):
    """SCATMECH (GGX slopes + Smith table shadow) is float64; the CSV prints 10 digits."""
    assert _check_scatmech(rough_conductor, "scatmech_facet_ggx_smith") < 5e-10


def test_unshadowed_mueller_brdf_matches_scatmech_facet_model(oracles):
    d = _load(oracles, "rough_conductor_inplane.csv")
    assert _check_scatmech(d, "scatmech_facet_noshadow") < 5e-10


def test_mueller_brdf_matches_mitsuba_except_flagged_retroreflection(rough_conductor):
    """Mitsuba is float32: README section 6 states <= 9e-7 of peak f00 against SCATMECH."""
    for m, alpha, ti, g in _configs(rough_conductor, "mitsuba_roughconductor"):
        g = g[g.note.isna()]
        got, ref = _mueller(m, alpha, ti, g), g[M_COLS].to_numpy()
        assert np.max(np.abs(got - ref)) <= 1e-6 * ref[:, 0].max()


def test_flagged_mitsuba_retroreflection_rows_are_where_scatmech_differs(oracles):
    d = _load(oracles, "rough_conductor_inplane.csv")
    bad = d[d.note.notna()]
    assert len(bad) > 0
    assert np.all(bad.theta_r_deg == bad.theta_i_deg) and np.all(bad.phi_r_deg == 0)
    m = models.get("microfacet", n=1.55, k=7.71)
    r = bad.iloc[0]
    got = m.mueller(
        math.radians(r.theta_i_deg), math.radians(r.theta_r_deg), 0.0, params={"alpha": r.alpha}
    )
    # retroreflection: facet at normal incidence, M11 = +M00 (Mitsuba's wrong value differs)
    assert got[1, 1] == pytest.approx(got[0, 0], rel=1e-12)
    assert abs(r.f_M11 - got[1, 1]) > 0.1 * got[0, 0]


def test_evaluate_equals_mueller_00_and_f00_column(oracles):
    d = _load(oracles, "rough_conductor_outofplane.csv")
    for m, alpha, ti, g in _configs(d, "scatmech_facet_ggx_smith"):
        args = (
            math.radians(ti),
            np.radians(g.theta_r_deg.to_numpy()),
            np.radians(g.phi_r_deg.to_numpy()),
        )
        f = m.evaluate(*args, params={"alpha": alpha})
        np.testing.assert_allclose(
            f, m.mueller(*args, params={"alpha": alpha})[:, 0, 0], rtol=1e-14, atol=0
        )
        ref = g.f_M00.to_numpy()
        assert np.all(np.abs(f - ref) <= _half_ulp_10_digits(ref) + 1e-14 * ref.max())


def test_specular_mueller_normalised_equals_smooth_fresnel(oracles):
    """At theta_r = theta_i, phi_r = pi the facet is the mean surface: M/M00 = smooth one."""
    sm = _load(oracles, "smooth_fresnel.csv")
    sm = sm[(sm.source == "own") & (sm.material == "Al")].set_index("theta_i_deg")
    m = models.get("microfacet", n=1.55, k=7.71)
    cols = [c[2:] for c in M_COLS]
    for ti in (0, 20, 45, 70, 85):
        got = m.mueller(math.radians(ti), math.radians(ti), math.pi, params={"alpha": 0.3})
        ref = sm.loc[ti, cols].to_numpy(dtype=float).reshape(4, 4)
        np.testing.assert_allclose(got / got[0, 0], ref / ref[0, 0], rtol=0, atol=5e-10)


def test_published_specular_values_of_readme(oracles):
    """README section 5: Al alpha 0.2, f00 = 2.385, 3.517, 6.677 sr^-1 at 30, 45, 60 deg."""
    m = models.get("microfacet", n=1.55, k=7.71)
    for ti, ref in ((30, 2.385), (45, 3.517), (60, 6.677)):
        got = m.evaluate(math.radians(ti), math.radians(ti), params={"alpha": 0.2})
        assert abs(got - ref) <= 5e-4  # 3 decimals printed


def test_psi_delta_option_predicts_the_nk_brdf(oracles):
    rt = _load(oracles, "ellipsometry_roundtrip.csv")
    r = rt[(rt.material == "Al") & (rt.angle_deg == 70)].iloc[0]
    via_ellipsometer = models.get("microfacet", psi_delta=(r.psi_deg, r.delta_deg, 70.0))
    direct = models.get("microfacet", n=1.55, k=7.71)
    assert via_ellipsometer.N == pytest.approx(1.55 + 7.71j, abs=1e-12)
    args = (0.6, np.radians(np.arange(0, 90, 7.0)), np.radians([[0.0], [100.0], [180.0]]))
    np.testing.assert_allclose(
        via_ellipsometer.mueller(*args), direct.mueller(*args), rtol=1e-11, atol=1e-14
    )
    assert via_ellipsometer.options["psi_delta"] == (r.psi_deg, r.delta_deg, 70.0)


def test_ggx_distribution_is_normalised_and_matches_paper_form():
    alpha = 0.3
    t = np.linspace(0, math.pi / 2, 200001)
    d = ggx.d(np.cos(t), alpha)
    integral = trapezoid(d * np.cos(t) * np.sin(t), t) * 2 * math.pi
    assert integral == pytest.approx(1.0, abs=1e-9)  # trapezoid error ~ h^2 = 6e-11
    tm = 0.4
    paper = alpha**2 / (math.pi * math.cos(tm) ** 4 * (alpha**2 + math.tan(tm) ** 2) ** 2)
    assert ggx.d(math.cos(tm), alpha) == pytest.approx(paper, rel=1e-14)


def test_smith_g1_limits():
    assert ggx.smith_g1_closed(1.0, 0.5) == 1.0
    assert ggx.smith_g1_closed(0.0, 0.5) == 0.0
    c = math.cos(1.2)
    ref = 2 / (1 + math.sqrt(1 + 0.25 * math.tan(1.2) ** 2))
    assert ggx.smith_g1_closed(c, 0.5) == pytest.approx(ref, rel=1e-15)


def test_stokes_from_jones_reproduces_optics_mueller_reflection():
    rs, rp = optics.fresnel_cos(1.0, 1.55 + 7.71j, np.cos(np.radians([0.0, 45.0, 80.0])))[:2]
    j = np.zeros((3, 2, 2), complex)
    j[:, 0, 0], j[:, 1, 1] = rs, rp
    np.testing.assert_allclose(
        stokes_from_jones(j), optics.mueller_reflection(rs, rp), rtol=0, atol=1e-15
    )


def test_ideal_mirror_normal_incidence_mueller():
    m = models.get("microfacet", ideal_mirror=True)
    got = m.mueller(0.0, 0.0, math.pi, params={"alpha": 0.2})
    f00 = 1 / (math.pi * 0.04) / 4  # D(z) G1 G1 / (4 cos cos), F = 1
    np.testing.assert_allclose(got, f00 * np.diag([1.0, 1.0, -1.0, -1.0]), rtol=1e-14, atol=1e-15)
    # at theta_r = 0 the exit frame follows phi_r (pitfall 6). E_in = s_in = y is reflected to
    # E_out = -y; with s_out = phi_hat(pi + 0.7), p_out = z x s_out: Es = cos 0.7,
    # Ep = -sin 0.7, so S1 = cos 1.4 and S2 = -sin 1.4 for S1_in = 1
    rot = m.mueller(0.0, 0.0, math.pi + 0.7, params={"alpha": 0.2}) / f00
    c, s = math.cos(1.4), math.sin(1.4)
    np.testing.assert_allclose(rot[1:3, 1:3], [[c, -s], [-s, -c]], atol=1e-14)


def test_always_reciprocal():
    m = models.get("microfacet", n=0.23, k=3.63)
    assert m.is_reciprocal()
    d = reciprocity_defect(m, {"alpha": 0.15})
    assert d.max_rel <= 64 * EPS


def test_scale_is_linear_and_fixed_by_default():
    m = models.get("microfacet", n=1.5)
    assert m.params["scale"].vary is False and m.linear == ("scale",)
    p = m.values({"alpha": 0.3, "scale": 0.37})
    ti, tr, pr = np.broadcast_arrays(0.4, np.radians([10.0, 30, 60]), np.pi)
    comp = m.linear_components(p, ti, tr, pr, None)
    np.testing.assert_allclose(0.37 * comp["scale"], m.evaluate(ti, tr, pr, params=p), rtol=1e-15)


def test_below_horizon_is_zero():
    m = models.get("microfacet", n=1.5)
    assert m.evaluate(0.3, math.pi / 2 + 0.1) == 0.0
    assert np.all(m.mueller(0.3, math.pi / 2 + 1e-9, 1.0) == 0.0)
    assert m.evaluate(math.pi / 2 + 0.2, 0.3) == 0.0


def test_options_stored_and_json_safe():
    m = models.get("microfacet", n=1.55, k=7.71, shadowing="none")
    assert m.options == {"shadowing": "none", "n": 1.55, "k": 7.71}
    json.dumps(m.describe())


@pytest.mark.parametrize(
    ("options", "match"),
    [
        ({}, "exactly one of n="),
        ({"n": 1.5, "ideal_mirror": True}, "exactly one of n="),
        ({"k": 3.0, "ideal_mirror": True}, "'k' needs 'n'"),
        ({"n": -1.0}, "must be finite, >= 0"),
        ({"n": 1.0, "k": -0.1}, "must be finite, >= 0"),
        ({"n": 0.0, "k": 0.0}, "not both 0"),
        ({"psi_delta": (40.0, 120.0)}, "three numbers"),
        ({"n": 1.5, "shadowing": "vgroove"}, "option 'shadowing' must be one of"),
        ({"n": 1.5, "eta": 1.5}, "unknown options \\['eta'\\]"),
    ],
)
def test_bad_options_are_rejected(options, match):
    with pytest.raises(ModelError, match=match):
        models.get("microfacet", **options)


def test_impossible_psi_delta_is_rejected_by_the_inversion():
    with pytest.raises(ValueError, match="psi_deg"):
        models.get("microfacet", psi_delta=(100.0, 120.0, 70.0))


def test_alpha_not_positive_is_rejected():
    m = models.get("microfacet", n=1.5)
    with pytest.raises(ModelError, match="'alpha' must be > 0"):
        m.evaluate(0.1, 0.2, params={"alpha": 0.0})
