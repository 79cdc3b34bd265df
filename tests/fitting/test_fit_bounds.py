"""A value fixed or started outside a parameter's declared bounds is refused, for every model.

The bounds are the model's (:meth:`labbrdf.models.Model.default_params`); the fitting core
(:func:`labbrdf.fitting.parameters.setup_params`, which :func:`labbrdf.fitting.fit` and
:func:`labbrdf.fitting.fit_many` call before any evaluation) refuses a fixed or start value
outside them, NaN or infinite, naming the parameter and the allowed range.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from labbrdf import models
from labbrdf.fitting import FitError, fit, fit_many
from labbrdf.fitting.parameters import setup_params

#: every registry model, in each of its option sets that changes the parameters
CONFIGS = [
    ("smooth3", {}),
    ("five_param", {}),
    ("five_param", {"shadowing": "mb"}),
    ("microfacet", {"n": 1.55, "k": 7.71}),
    ("microfacet", {"n": 1.55, "k": 7.71, "diffuse": True}),
    ("layered", {"n": 1.55, "k": 7.71}),
    ("layered", {"n": 1.55, "k": 7.71, "coherent": True}),
    ("layered", {"base": "diffuse"}),
    ("layered", {"n": 1.55, "k": 7.71, "floor": True}),
    ("abg", {}),
    ("abg", {"diffuse": True}),
    ("harvey_shack", {}),
    ("harvey_shack", {"diffuse": True}),
    ("rayleigh_rice", {"n": 1.2, "k": 7.0}),
    ("rayleigh_rice", {"n": 1.2, "k": 7.0, "free_index": True}),
    ("rayleigh_rice", {"n": 1.2, "k": 7.0, "psd": "gaussian"}),
]


def _cases() -> list[tuple[str, dict, str, float, str]]:
    """(model, options, parameter, bad value, what) for every parameter of every model."""
    out = []
    for name, opts in CONFIGS:
        for pname, p in models.get(name, **opts).params.items():
            width = p.max - p.min if math.isfinite(p.max - p.min) else 1.0
            if math.isfinite(p.min):
                out.append((name, opts, pname, p.min - 1e-6 * width, "below"))
            if math.isfinite(p.max):
                out.append((name, opts, pname, p.max + 1e-6 * width, "above"))
            out += [(name, opts, pname, v, "not finite") for v in (math.nan, math.inf, -math.inf)]
    return out


CASES = _cases()
IDS = [f"{m}{sorted(o)}-{p}-{what}-{v:g}" for m, o, p, v, what in CASES]


def test_every_registry_model_is_covered():
    assert {name for name, _ in CONFIGS} == set(models.names())


@pytest.mark.parametrize(("name", "opts", "param", "value", "what"), CASES, ids=IDS)
def test_a_value_outside_the_bounds_is_refused_by_the_model(name, opts, param, value, what):
    model = models.get(name, **opts)
    p = model.params[param]
    with pytest.raises(models.ModelError) as exc:
        model.check_value(param, value)
    msg = str(exc.value)
    assert f"model {name!r}" in msg and param in msg
    assert f"{p.min:g} <= {param} <= {p.max:g}" in msg


@pytest.mark.parametrize(("name", "opts", "param", "value", "what"), CASES, ids=IDS)
def test_a_fixed_or_start_value_outside_the_bounds_is_refused_by_the_fitting_core(
    name, opts, param, value, what
):
    model = models.get(name, **opts)
    p = model.params[param]
    allowed = f"{p.min:g} <= {param} <= {p.max:g}"
    with pytest.raises(FitError, match="^fix: ") as exc:
        setup_params(model, None, {param: value})
    assert allowed in str(exc.value)
    with pytest.raises(FitError, match="^params: ") as exc:
        setup_params(model, {param: {"value": value, "vary": True}}, None)
    assert allowed in str(exc.value)


@pytest.mark.parametrize(("name", "opts"), CONFIGS, ids=[f"{n}{sorted(o)}" for n, o in CONFIGS])
def test_values_on_the_bounds_are_accepted(name, opts):
    model = models.get(name, **opts)
    for pname, p in model.params.items():
        for v in (p.min, p.max):
            if math.isfinite(v):
                assert setup_params(model, None, {pname: v})[pname].value == v


def _brdf_rows(n: int = 12) -> pd.DataFrame:
    th = np.linspace(5.0, 60.0, n)
    return pd.DataFrame(
        {
            "sample": "s",
            "instrument": "synthetic",
            "source": "s.csv",
            "quantity": "brdf",
            "value": np.exp(-(((th - 30.0) / 10.0) ** 2)) + 0.01,
            "sigma": np.nan,
            "unit": "sr-1",
            "wavelength_nm": 633.0,
            "theta_i_deg": 30.0,
            "theta_r_deg": th,
            "phi_r_deg": 180.0,
        }
    )


def test_fit_refuses_layered_alpha_top_below_its_bounds_before_tracing(monkeypatch):
    """``fix={'alpha_top': -1}`` once reached the tracer (a SystemError): now a FitError."""
    model = models.get("layered", n=1.55, k=7.71)

    def traced(*a, **k):
        raise AssertionError("the model was evaluated")

    monkeypatch.setattr(model, "_evaluate", traced)
    with pytest.raises(FitError, match=r"alpha_top=-1 is outside its bounds.*0.02 <= alpha_top"):
        fit(model, _brdf_rows(), fix={"alpha_top": -1.0})
    with pytest.raises(FitError, match="alpha_top=-1 is outside its bounds"):
        fit_many(_brdf_rows(), model, fix={"alpha_top": -1.0}, executor="serial")


@pytest.mark.parametrize("seed", [-1, 2**32, 1.5, True])
def test_fit_and_fit_many_refuse_a_seed_outside_the_optimisers_range(seed):
    with pytest.raises(FitError, match=r"seed must be an integer in \[0, 4294967295\]"):
        fit("smooth3", _brdf_rows(), seed=seed)
    with pytest.raises(FitError, match=r"seed must be an integer in \[0, 4294967295\]"):
        fit_many(_brdf_rows(), "smooth3", seed=seed, executor="serial")
