"""What a model knows about itself: guesses, identifiability, reciprocity, closed forms."""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np
import pytest
from numpy.typing import NDArray

import labbrdf
from labbrdf import integrate, models
from labbrdf.fitting import FitError, fit
from labbrdf.fitting.data import FitData
from labbrdf.models.base import Model, Parameters


@pytest.mark.parametrize("name", models.names())
def test_every_model_states_its_reciprocity(name: str) -> None:
    note = models.MODELS[name].reciprocity_note
    assert note.startswith(name) and note.endswith(".")


def test_smooth3_knows_its_closed_form_and_it_matches_quadrature() -> None:
    m = models.get("smooth3")
    p = {"k1": 1.0, "k2": -0.0166, "k3": 0.4176}
    closed = m.hemispherical([0.0, 45.0, 70.0], p)
    quad = integrate.hemispherical_reflectance(m, p, [0.0, 45.0, 70.0], method="quadrature")
    assert closed is not None
    np.testing.assert_allclose(closed, quad, rtol=2e-6)  # quadrature converged to 1e-6


@pytest.mark.parametrize("name", ["five_param", "microfacet"])
def test_a_model_without_a_closed_form_says_none_and_auto_integrates(name: str) -> None:
    m = models.get(name, n=1.5, k=0.0) if name == "microfacet" else models.get(name)
    assert m.hemispherical([45.0]) is None
    with pytest.raises(ValueError, match="no closed form"):
        integrate.hemispherical_reflectance(m, None, [45.0], method="closed")


def test_smooth3_guess_recovers_noise_free_parameters() -> None:
    ti = np.radians(np.repeat([30.0, 45.0, 60.0], 21))
    tr = ti + np.radians(np.tile(np.linspace(-3, 3, 21), 3))
    truth = {"k1": 0.97, "k2": -0.012, "k3": 0.35}
    y = models.get("smooth3").evaluate(ti, tr, params=truth)
    g = models.get("smooth3").guess(ti, tr, y)
    assert g == pytest.approx(truth, rel=1e-9)


def test_the_fit_refuses_line_shape_parameters_on_the_specular_line() -> None:
    t = np.repeat([30.0, 45.0, 60.0], 3)
    y = models.get("smooth3").evaluate(np.radians(t), np.radians(t))
    fd = FitData(theta_i_deg=t, theta_r_deg=t, value=y)
    with pytest.raises(FitError, match=r"fix \['k2', 'k3'\]"):
        fit("smooth3", fd)


class _Lambert(Model):
    """A Lambertian BRDF ``rho / pi``: a whole new model in a dozen lines."""

    name = "lambert_test"
    reciprocity_note = "lambert_test is reciprocal by construction."

    def default_params(self) -> Parameters:
        p = Parameters()
        p.add("rho", 0.5, 0.0, 1.0, units="1", description="albedo")
        return p

    def _evaluate(
        self,
        p: Mapping[str, float],
        theta_i: NDArray,
        theta_r: NDArray,
        phi_r: NDArray,
        wavelength: NDArray | None,
    ) -> NDArray:
        return np.full(np.broadcast(theta_i, theta_r).shape, p["rho"] / math.pi)

    def is_reciprocal(self, params: Mapping[str, float] | None = None) -> bool:
        return True

    def hemispherical(self, theta_i_deg, params=None):  # type: ignore[no-untyped-def]
        return np.full(np.shape(theta_i_deg), self.values(params)["rho"])


def test_a_new_model_is_its_class_and_one_registry_line(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(models.MODELS, "lambert_test", _Lambert)
    m = models.get("lambert_test")
    assert integrate.hemispherical_reflectance(m, {"rho": 0.3}, [10.0]) == pytest.approx(0.3)
    quad = integrate.hemispherical_reflectance(m, {"rho": 0.3}, [10.0], method="quadrature")
    assert quad == pytest.approx(0.3, rel=1e-6)
    rng = np.random.default_rng(0)
    t_r = np.linspace(0.0, 70.0, 30)
    y = 0.3 / math.pi * (1 + 0.01 * rng.standard_normal(t_r.size))
    fd = FitData(theta_i_deg=np.full(t_r.size, 30.0), theta_r_deg=t_r, value=y)
    res = labbrdf.fit("lambert_test", fd)
    assert res.success and res.params["rho"].value == pytest.approx(0.3, rel=0.01)
