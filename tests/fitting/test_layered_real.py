"""The layered model on a real export: a brown vinyl (Radiant IS-SA .bsdf)."""

from __future__ import annotations

import pytest

from labbrdf import adapters, fit, models

VINYL = "zemax-bsdf/test_13_planesymmetric_brdf_zemax.bsdf"


@pytest.mark.slow
def test_vinyl_prefers_a_coating_over_a_diffuse_base_to_facets_plus_lambert(real_exports):
    """Incidences 15, 45, 75 deg; both models have two searched parameters.

    A vinyl is a clear layer over a scattering body: the layered model with a Lambertian
    base must fit better than GGX facets of n = 1.5 plus a Lambertian floor (measured:
    AIC -922.8 against -899.2), with its parameters inside, not at, their bounds and the
    base's albedo where the data's floor puts it: 0.035-0.06 sr^-1 under a 1.5-index
    layer is an albedo of about pi n^2 x floor = 0.25-0.42, and the lobe at 75 deg, about
    15 deg wide, needs a rough top (alpha_top 0.15-0.6).
    """
    df = adapters.read(real_exports / VINYL).data
    df = df[df["theta_i_deg"].isin([15.0, 45.0, 75.0]) & (df["value"] != 0)]
    lay = fit(models.get("layered", base="diffuse"), df, weighting="relative")
    mf = fit(models.get("microfacet", n=1.5, k=0.0, diffuse=True), df, weighting="relative")
    assert lay.success and mf.success
    assert lay.nvarys == mf.nvarys == 2
    assert lay.aic < mf.aic - 10  # "essentially no support" for the other (Burnham-Anderson)
    assert not lay.flags
    assert 0.15 < lay.params["albedo"].value < 0.5
    assert 0.15 < lay.params["alpha_top"].value < 0.6
