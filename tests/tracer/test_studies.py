"""The paper's four factor studies (Dong 2022 sec. 4) at small ray counts, and the claims."""

from __future__ import annotations

import json

import numpy as np
import pytest

from labbrdf.tracer.studies import MATERIALS, evaluate_claims, factor_studies, study_configs


@pytest.fixture(scope="module")
def studies():
    return factor_studies(rays=6000, seed=3, step=10.0)


def test_study_configs_follow_the_paper():
    cfgs = study_configs(rays=10)
    assert [s for s, _, _ in cfgs].count("incidence") == 3
    inc = [c.theta_i_deg for s, _, c in cfgs if s == "incidence"]
    assert inc == [30.0, 45.0, 60.0]
    rough = [(c.coating.alpha, c.substrate.alpha) for s, _, c in cfgs if s == "roughness"]
    assert rough == [(0.2, 0.2), (0.4, 0.4), (0.6, 0.6)]
    subs = [(c.substrate.n, c.substrate.k) for s, _, c in cfgs if s == "substrate"]
    assert subs == list(MATERIALS.values())
    # optical thickness n d = lambda/8, lambda/4, lambda/2 at 650 nm, n = 1.5
    nd = [c.coating.n * c.coating.thickness_nm for s, _, c in cfgs if s == "thickness"]
    np.testing.assert_allclose(nd, [81.25, 162.5, 325.0])
    assert all(c.coherent for s, _, c in cfgs if s == "thickness_coherent")
    assert all(c.wavelength_nm == 650.0 and c.coating.n == 1.5 for _, _, c in cfgs)


def test_factor_studies_return_one_result_per_configuration(studies):
    assert len(studies) == 15
    assert {s for s, _, _ in studies} == {
        "incidence",
        "roughness",
        "substrate",
        "thickness",
        "thickness_coherent",
    }
    for _, _, res in studies:
        assert res.rays == 6000
        led = res.ledger
        assert led["exited"] + led["absorbed"] + led["terminated"] == pytest.approx(1, abs=1e-12)


def test_incoherent_lossless_coating_thickness_changes_nothing(studies):
    # the paper's lambda/4 maximum cannot appear in incoherent ray optics
    thick = [res for s, _, res in studies if s == "thickness"]
    for other in thick[1:]:
        np.testing.assert_array_equal(thick[0].sums, other.sums)


def test_coherent_thickness_study_changes_the_reflectance(studies):
    coh = [res.albedo() for s, _, res in studies if s == "thickness_coherent"]
    assert len(set(coh)) == 3


def test_claims_are_evaluated_with_evidence(studies):
    claims = evaluate_claims(studies, min_count=5)
    assert len(claims) >= 30
    for c in claims:
        assert set(c) == {"study", "claim", "holds", "evidence"}
        assert isinstance(c["holds"], bool)
        json.dumps(c["evidence"])
    by = {(c["study"], c["claim"]): c for c in claims}
    lam4 = by[("thickness", "the S0 centre intensity is largest for d_c = lambda/4")]
    assert lam4["holds"] is False  # identical maps: no maximum at lambda/4
    sub = by[("substrate", "with larger n/k (Cu < Al < NiFe) the S0 centre intensity falls")]
    centre = [v["S0_centre"] for v in sub["evidence"].values()]
    assert list(sub["evidence"]) == ["Cu", "Al", "NiFe"]
    assert sub["holds"] == (centre[0] > centre[1] > centre[2])


def test_claims_refuse_maps_without_enough_rays(studies):
    with pytest.raises(ValueError, match="no bin has min_count=10000000 exiting rays"):
        evaluate_claims(studies[:1], min_count=10_000_000)


def test_claims_can_be_judged_on_evaluated_single_scattering_maps():
    """The evaluated estimator counts no rays: its bins are judged by S0 > 0 and their
    batch errors, so every study yields its statistics instead of 'no bin has rays'."""
    runs = factor_studies(rays=3000, seed=3, step=10.0, scattering="single")
    assert all(r.estimator == "evaluated" for _, _, r in runs)
    claims = evaluate_claims(runs)
    assert claims
    json.dumps(claims)  # JSON-safe like the counting claims
