"""The registry of microfacet distributions: complete modules, and a new one added in one line."""

from __future__ import annotations

import types

import numpy as np
import pytest
from scipy import integrate

from labbrdf.microfacet import DISTRIBUTIONS, TabulatedNDF, beckmann, get, ggx, names, registry
from labbrdf.roughness.topography import fit_slope_distribution
from labbrdf.sample import trace_config_from_inputs


@pytest.mark.parametrize("name", list(DISTRIBUTIONS))
def test_every_distribution_defines_the_required_names(name):
    dist = DISTRIBUTIONS[name]
    missing = [n for n in registry.REQUIRED if not hasattr(dist, n)]
    assert missing == []
    assert dist.NAME == name
    if dist.TRACED_IN_CLOSED_FORM:
        assert callable(dist.sample_visible)


@pytest.mark.parametrize("dist", [ggx, beckmann])
@pytest.mark.parametrize("alpha", [0.1, 0.4])
def test_d_is_normalised_over_the_projected_hemisphere(dist, alpha):
    val, _ = integrate.quad(
        lambda t: dist.d(np.cos(t), alpha) * np.cos(t) * np.sin(t) * 2 * np.pi,
        0,
        np.pi / 2,
        points=[alpha],
        limit=200,
    )
    assert val == pytest.approx(1.0, rel=1e-6)


@pytest.mark.parametrize("alpha", [0.15, 0.5])
def test_beckmann_closed_form_lambda_matches_its_slope_table(alpha):
    t = np.radians([10.0, 45.0, 70.0, 85.0])
    w = np.stack([np.sin(t), np.zeros_like(t), np.cos(t)])
    table = TabulatedNDF.of(beckmann, alpha, n=256)
    np.testing.assert_allclose(
        table.smith_lambda(w), beckmann.smith_lambda(w[2], alpha), atol=2e-3
    )
    np.testing.assert_allclose(
        beckmann.smith_lambda(-w[2], alpha), -1.0 - beckmann.smith_lambda(w[2], alpha)
    )


def test_an_unknown_name_is_refused_with_the_known_ones():
    assert names() == ("ggx", "beckmann")
    with pytest.raises(KeyError, match="ggx, beckmann"):
        get("cauchy")


def _copy_of(module: types.ModuleType, name: str) -> types.ModuleType:
    new = types.ModuleType(name)
    new.__dict__.update({k: v for k, v in vars(module).items() if not k.startswith("__")})
    new.NAME, new.LABEL = name, name.capitalize()
    return new


def test_a_distribution_added_by_one_registry_line_is_fitted_and_traced(monkeypatch):
    """A new module plus one registry entry: the slope fits and the trace setup take it."""
    new = _copy_of(beckmann, "gauss2")
    monkeypatch.setitem(DISTRIBUTIONS, "gauss2", new)
    rng = np.random.default_rng(2)
    fits = fit_slope_distribution(rng.normal(0, 0.1, 4000), rng.normal(0, 0.1, 4000))
    assert list(fits.fits) == ["ggx", "beckmann", "gauss2"]
    assert fits.gauss2.alpha == fits.beckmann.alpha
    assert fits.to_dict()["gauss2"]["alpha"] == pytest.approx(0.1 * np.sqrt(2), rel=0.05)
    cfg = trace_config_from_inputs(
        633.0, 30.0, substrate_index=complex(0.2, 3.0), alpha=0.3, distribution="gauss2"
    )
    assert cfg.substrate.ndf is not None and cfg.substrate.ndf.name == "gauss2(0.3)"
    assert cfg.substrate.ndf == TabulatedNDF.beckmann(0.3)
