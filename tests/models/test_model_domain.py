"""A model fitted outside its domain says so: one mechanism (Model.domain) for every model."""

from __future__ import annotations

import numpy as np
import pytest

import labbrdf
from labbrdf import models
from labbrdf.models.base import PLANE_TOL_DEG


@pytest.fixture(scope="module")
def scan(fixtures_dir):
    """One wavelength of the OSR specular scan: points in the plane of incidence."""
    d = labbrdf.read(fixtures_dir / "specular" / "osr_specular.csv").data
    return d[d["wavelength_nm"] == d["wavelength_nm"].min()].reset_index(drop=True)


def test_every_model_states_its_domain():
    for name, cls in models.MODELS.items():
        assert cls.domain in ("hemisphere", "specular_plane"), name
    assert models.MODELS["smooth3"].domain == "specular_plane"


def test_smooth3_on_in_plane_points_is_inside(scan):
    res = labbrdf.fit("smooth3", scan)
    assert res.outside_domain == "" and res.status == "ok"
    assert not any("domain" in w for w in res.warnings)


def test_smooth3_out_of_the_plane_says_so(scan):
    moved = scan.copy()
    moved.loc[moved.index[::2], "phi_r_deg"] = 180.0 - 3 * PLANE_TOL_DEG
    res = labbrdf.fit("smooth3", moved)
    n = len(moved.index[::2])
    assert res.outside_domain.startswith(f"{n} of {len(moved)} points lie out of the plane")
    assert res.status == "outside the model's domain"
    report = res.fit_report()
    assert "success            = True, but outside the model's domain" in report
    assert "outside the model's domain: " in report
    assert labbrdf.fit_many(moved, "smooth3")["status"].tolist() == [res.status]


def test_within_the_tolerance_and_at_normal_incidence_is_in_plane():
    m = models.get("smooth3")
    ti = np.array([10.0, 20.0, 0.0])
    assert m.outside_domain(ti, [180.0 - 0.5 * PLANE_TOL_DEG, -180.0, 37.0]) is None
    assert m.outside_domain(ti, [170.0, 180.0, 180.0]).startswith("1 of 3 points")


def test_a_hemispherical_model_is_never_outside():
    m = models.get("microfacet", ideal_mirror=True)
    assert m.outside_domain(np.array([30.0, 40.0]), np.array([0.0, 90.0])) is None


@pytest.mark.shared
def test_smooth3_on_the_whole_hemisphere_bsdf_is_flagged(real_exports):
    f = real_exports / "zemax-bsdf" / "test_13_planesymmetric_brdf_zemax.bsdf"
    res = labbrdf.fit("smooth3", labbrdf.read(f))
    assert res.status == "outside the model's domain"
    assert "specular-plane model" in res.outside_domain
