"""The film fit's local stage: trust-region least squares in place of BOBYQA's rounds."""

from __future__ import annotations

import nlopt
import numpy as np
import pandas as pd
import pytest

from labbrdf.films import FilmModel, Layer, Stack
from labbrdf.fitting import stages
from labbrdf.fitting.film import _FilmFitModel, fit_film
from labbrdf.nk.dispersion import Cauchy

TRUE = Stack([Layer(Cauchy(A=1.46, B=0.004), 105.0, "film")], "si")
BOX = {"film.thickness_nm": (50.0, 200.0), "film.A": (1.3, 1.8), "film.B": (0.0, 0.02)}
START = Stack([Layer(Cauchy(A=1.5, B=0.006), 120.0, "film")], "si")


@pytest.fixture(scope="module")
def data() -> pd.DataFrame:
    """psi/Delta of TRUE at 60 wavelengths x 3 angles with an ellipsometer's noise."""
    rng = np.random.default_rng(7)
    W, T = np.meshgrid(np.linspace(300, 1000, 60), [55.0, 65.0, 75.0], indexing="ij")
    w, t = W.ravel(), T.ravel()
    psi, delta = TRUE.psi_delta(w, t)
    parts = [
        pd.DataFrame(
            {
                "sample": "s",
                "instrument": "sim",
                "source": "s.dat",
                "quantity": q,
                "value": v + rng.normal(0, s, v.size),
                "sigma": s,
                "unit": "deg",
                "wavelength_nm": w,
                "theta_i_deg": t,
                "theta_r_deg": t,
                "phi_r_deg": 180.0,
            }
        )  # fmt: skip
        for q, v, s in (("psi", psi, 0.01), ("delta", np.mod(delta, 360.0), 0.03))
    ]
    return pd.concat(parts, ignore_index=True)


def test_least_squares_reaches_bobyqas_minimum_in_fewer_evaluations(data, monkeypatch):
    new = fit_film(FilmModel(START, BOX), data, ci="wald")
    monkeypatch.setattr(_FilmFitModel, "least_squares_local", False)
    old = fit_film(FilmModel(START, BOX), data, ci="wald")
    assert [s["algorithm"] for s in new.result.stages] == ["GN_CRS2_LM", stages.LEAST_SQUARES]
    assert [s["algorithm"] for s in old.result.stages] == ["GN_CRS2_LM", "LN_BOBYQA",
                                                           stages.POLISH]  # fmt: skip
    assert new.result.success and new.result.stages[-1]["code"] == nlopt.SUCCESS
    assert new.result.nfev < old.result.nfev
    # both stop on a chi-square change of 1e-12 relative (the polish's tolerance): the
    # same minimum to far below its 95 % interval
    assert new.mse == pytest.approx(old.mse, rel=1e-9)
    for k in BOX:
        p, q = new.result.params[k], old.result.params[k]
        assert abs(p.value - q.value) < 1e-3 * p.stderr, k


def test_an_explicitly_named_other_local_algorithm_runs_as_nlopts(data):
    f = fit_film(FilmModel(START, BOX), data, ci="wald", method="LN_SBPLX", maxeval=60)
    assert [s["algorithm"] for s in f.result.stages][0] == "LN_SBPLX"
    assert stages.LEAST_SQUARES not in [s["algorithm"] for s in f.result.stages]


def test_a_least_squares_stage_stopped_by_its_budget_is_not_converged(data):
    f = fit_film(FilmModel(START, BOX), data, ci="wald", method="LN_BOBYQA", maxeval=2)
    last = f.result.stages[-1]
    assert last["algorithm"] == stages.LEAST_SQUARES
    assert last["code"] == nlopt.MAXEVAL_REACHED
    assert not f.result.success
    assert "budget" in f.result.message


def test_the_report_names_the_stages_that_ran(data):
    f = fit_film(FilmModel(START, BOX), data, ci="wald")
    assert f.summary()["search"] == ["GN_CRS2_LM", stages.LEAST_SQUARES]
    assert f"GN_CRS2_LM then {stages.LEAST_SQUARES}, seed 0" in f.fit_report()
