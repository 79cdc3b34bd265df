"""The layered model on a real export: a brown vinyl (Radiant IS-SA .bsdf)."""

from __future__ import annotations

import math

import pytest

from labbrdf import adapters, fit, models

VINYL = "zemax-bsdf/test_13_planesymmetric_brdf_zemax.bsdf"


@pytest.mark.slow
def test_vinyl_coating_roughness_agrees_with_the_facet_model(real_exports):
    """Incidence 45 deg, theta_r <= 70 deg (beyond, the sphere vignettes).

    Both models put GGX facets on a 1.5-index surface for the first-surface reflection;
    the rest is a broad, smooth term (the coating's diffuse base, or a Lambertian floor).
    So the coating's top roughness must agree with the facet model's alpha within their
    combined standard errors (measured: 0.2751 +- 0.0043 and 0.2756 +- 0.0032), and the
    base's albedo must sit where the data's floor puts it: 0.035-0.06 sr^-1 under a
    1.5-index layer is about pi n^2 x floor = 0.25-0.42 before the layer's losses, so
    0.15-0.5, inside its bounds.

    One incidence keeps the suite within its time on a loaded 2-core machine (the three
    incidences 15, 45, 75 deg took 12 minutes there, a third of the whole suite; measured
    then: 0.2864 +- 0.0034 against 0.2874 +- 0.0035). The three-incidence fit is timed and
    reported by ``benchmarks/bench_layered.py --incidences 15,45,75 --rays 5000``.
    """
    df = adapters.read(real_exports / VINYL).data
    keep = (df["theta_i_deg"] == 45.0) & (df["theta_r_deg"] <= 70.0)
    df = df[keep & (df["value"] != 0)]
    # a diffuse base is evaluated in closed form: no rays, no seed replicates needed
    lay = fit(models.get("layered", base="diffuse", rays=5000), df, weighting="relative")
    mf = fit(models.get("microfacet", n=1.5, k=0.0, diffuse=True), df, weighting="relative")
    assert lay.success and mf.success
    assert not lay.flags
    a, b = lay.params["alpha_top"], mf.params["alpha"]
    assert a.stderr is not None and b.stderr is not None
    assert abs(a.value - b.value) < 3 * math.hypot(a.stderr, b.stderr)
    assert 0.15 < lay.params["albedo"].value < 0.5
