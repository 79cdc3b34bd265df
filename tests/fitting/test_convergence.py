"""Convergence of the fitting core: the outcome, never an optimiser's path.

Every seed reaches the same minimum (the polish finishes a local stage that stalled along a
flat valley); a local stage that stops at its round budget restarts from its best point
(built deterministically with rounds too short to converge); a flat valley of noise-free
data ends converged with the parameters flagged; a starved budget or a polish out of budget
is not a success, and the report's success check shows it.
"""

from __future__ import annotations

import json
from pathlib import Path

import nlopt
import numpy as np
import pandas as pd
import pytest

import labbrdf
from labbrdf.fitting import FitData, Objective, fit, stages
from labbrdf.fitting.data import as_fit_data
from labbrdf.fitting.stages import CHI2_TOL, EXACT_RTOL, LOCAL_ROUNDS, POLISH, _polish, _run_local
from labbrdf.report.validate import validate

ROOT = Path(__file__).resolve().parents[2]
SCANS = ROOT / "labbrdf" / "data" / "fixtures" / "specular"

#: every model fitted to the specular fixtures, with each five_param shadowing choice and
#: microfacet for a dielectric (n = 1.5) with its diffuse term
MODELS = [("smooth3", {}), ("five_param", {}), ("five_param", {"shadowing": "none"}),
          ("five_param", {"shadowing": "mb"}),
          ("microfacet", {"n": 1.5, "k": 0.0, "diffuse": True})]  # fmt: skip


def _groups() -> list[tuple[str, float, pd.DataFrame]]:
    out = []
    for path in sorted(SCANS.glob("*.csv")):
        d = labbrdf.read(path).data
        for (s, w), g in d.groupby(["sample", "wavelength_nm"], sort=True):
            out.append((str(s), float(w), g.reset_index(drop=True)))
    return out


GROUPS = _groups()


#: seeds over which the reached chi-square must agree (the outcome, not the path)
SEEDS = range(16)
#: relative agreement of the reached chi-square across seeds: far below one noise unit
#: (Delta chi-square = 1 is ~1e-2 relative here) and far above the polish's 1e-12
SEED_RTOL = 1e-6


@pytest.mark.slow
@pytest.mark.parametrize(("name", "options"), MODELS, ids=lambda v: str(v))
def test_every_seed_reaches_the_same_minimum_in_every_fixture_group(name, options):
    # nlopt's random sequence differs between releases and machines (and the BLAS kernel
    # changes the last bits of chi-square, hence the path); the seeds stand in for that:
    # whatever the path, every fit succeeds and reaches the same chi-square
    model = labbrdf.models.get(name, **options)
    failed, spread = [], {}
    for sample, wl, g in GROUPS:
        chi2 = []
        for seed in SEEDS:
            r = fit(model, g, seed=seed)
            chi2.append(r.chisqr)
            if not r.success:
                failed.append((sample, wl, seed, r.message))
        best = min(chi2)
        spread[(sample, wl)] = (max(chi2) - best) / best
    assert not failed
    assert max(spread.values()) < SEED_RTOL, spread


def _objective(model_name: str, g: pd.DataFrame) -> Objective:
    """The objective :func:`fit` builds for ``g`` (sigma weights, amplitudes profiled)."""
    model = labbrdf.models.get(model_name)
    fd = as_fit_data(g, None, None)
    return Objective(model, fd, model.params, 1.0 / np.asarray(fd.sigma) ** 2, model.linear)


def test_a_local_round_at_maxeval_restarts_from_its_best_point():
    # rounds of 2n evaluations end at maxeval by construction: BOBYQA spends its first
    # 2n + 1 on its interpolation set; a round that short never counts as converged
    g = next(g for s, w, g in GROUPS if s == "OSR" and w == 860.0)
    obj = _objective("five_param", g)
    per_round, n_rounds = 2 * obj.n, 4
    x0 = obj.to_vector(obj.base)
    x, info = _run_local(
        obj, "LN_BOBYQA", n_rounds * per_round, x0, 0, None, len(g) - 5, True, per_round
    )
    rounds = info["rounds"]
    assert [r["code"] for r in rounds] == [nlopt.MAXEVAL_REACHED] * n_rounds
    assert [r["nfev"] for r in rounds] == [per_round] * n_rounds
    assert info["nfev"] == n_rounds * per_round == obj.nfev
    assert info["code"] == nlopt.MAXEVAL_REACHED and "maxeval reached" in info["message"]
    # each round starts from the best point of the one before: chi-square never rises
    for a, b in zip(rounds, rounds[1:], strict=False):
        assert b["chisqr_start"] == a["chisqr"]
        assert b["chisqr"] <= b["chisqr_start"]
    assert obj.solve(obj.from_vector(x))[1] == rounds[-1]["chisqr"]


def test_the_evaluation_count_covers_every_stage_round_and_the_polish():
    g = next(g for s, w, g in GROUPS if s == "OSR" and w == 860.0)
    r = fit("five_param", g, seed=0)
    assert r.success
    glob, local, polish = r.stages
    assert polish["algorithm"] == POLISH and polish["code"] > 0
    assert local["nfev"] == sum(x["nfev"] for x in local["rounds"])
    assert r.nfev == glob["nfev"] + local["nfev"] + polish["nfev"]
    assert polish["chisqr"] == r.chisqr <= local["chisqr"]
    assert r.summary()["nlopt_version"].count(".") == 2


#: five_param at OSR 860 nm: where the local stage stalled for some seeds (a at its upper
#: bound, b off), chi-square 118.5826, and the minimum every seed reaches with the polish
#: (no other search in benchmarks/bench_fit.py finds lower: CRS2 with 3000 evaluations
#: reaches it too, scipy's differential evolution stops at 118.588)
STALLED = {"kb": 0.1285327, "kr": 0.1603743, "a": 10.0, "b": -0.09305686}
CHI2_MIN_OSR_860 = 118.48529348


def test_the_polish_reaches_the_minimum_from_where_the_local_stage_stalled():
    g = next(g for s, w, g in GROUPS if s == "OSR" and w == 860.0)
    obj = _objective("five_param", g)
    x0 = obj.to_vector(STALLED)
    f0 = obj.solve(obj.from_vector(x0))[1]
    assert f0 > CHI2_MIN_OSR_860 + 0.09  # the stalled point is not the minimum
    x, info = _polish(obj, x0, len(g) - 5, True)
    assert info["code"] > 0 and "stationary point" in info["message"]
    assert info["chisqr"] == pytest.approx(CHI2_MIN_OSR_860, rel=1e-9)
    assert info["gain"] == pytest.approx(f0 - info["chisqr"])
    # a first-order stationary point in the interior: the gradient of chi-square vanishes
    # on the scale where one noise unit is Delta chi-square = 1
    lo, hi = obj.bounds()
    assert np.all((x > lo + 1e-3) & (x < hi - 1e-3))
    grad = np.empty(obj.n)
    obj(x, grad)
    assert np.max(np.abs(grad)) < 1e-3


def test_a_polish_that_runs_out_of_budget_is_not_a_success(monkeypatch):
    g = next(g for s, w, g in GROUPS if s == "OSR" and w == 860.0)
    obj = _objective("five_param", g)
    monkeypatch.setattr(stages, "_POLISH_MAXEVAL_PER_DIM", 1)  # n trial points: too few
    x0 = obj.to_vector(STALLED)
    f0 = obj.solve(obj.from_vector(x0))[1]
    x, info = _polish(obj, x0, len(g) - 5, True)
    assert info["code"] == 0 and "not converged" in info["message"]
    assert info["chisqr"] <= f0 and info["nfev"] == obj.nfev
    # and the fit reports it: not a success, whatever the stages said
    real = stages.optimize.least_squares

    def starved(*args, **kwargs):
        res = real(*args, **{**kwargs, "max_nfev": 1})
        res.status, res.message = 0, "budget"
        return res

    monkeypatch.setattr(stages.optimize, "least_squares", starved)
    r = fit("five_param", g, seed=0)
    assert r.stages[-1]["algorithm"] == POLISH and r.stages[-1]["code"] == 0
    assert not r.success and "not converged" in r.message


def test_a_polish_that_fails_keeps_the_local_point_and_says_so(monkeypatch):
    g = next(g for s, w, g in GROUPS if s == "OSR" and w == 860.0)

    def broken(*args, **kwargs):
        raise ValueError("Residuals are not finite in the initial point.")

    monkeypatch.setattr(stages.optimize, "least_squares", broken)
    r = fit("five_param", g, seed=0)
    assert r.stages[-1]["code"] == -1 and r.stages[-1]["nfev"] == 0
    assert r.chisqr == r.stages[-2]["chisqr"]
    assert "polish failed (Residuals are not finite" in r.message


def test_a_starved_budget_is_not_a_success():
    # 6 = 2n evaluations for kr, a, b: BOBYQA stops inside its interpolation set, and the
    # polish only finishes a local stage that converged
    g = next(g for s, w, g in GROUPS if s == "OSR" and w == 860.0)
    r = fit("five_param", g, seed=3, maxeval=[30, 6])
    assert not r.success
    assert "maxeval reached" in r.message
    assert [s["algorithm"] for s in r.stages] == ["GN_CRS2_LM", "LN_BOBYQA"]


def test_a_flat_valley_is_reported_as_converged_with_flags():
    # five_param on noise-free data at ONE angle of incidence: k_b, a, b trade off along a
    # valley where chi-square falls by round-off only; the optimiser must stop there, with
    # a model that reproduces the data and every parameter flagged
    m = labbrdf.models.get("five_param")
    ti = np.full(41, 45.0)
    tr = 45.0 + np.linspace(-2, 2, 41)
    truth = {"kb": 0.2, "kr": 0.3, "a": 2.0, "b": -0.01, "kd": 0.0}
    y = m.evaluate(np.radians(ti), np.radians(tr), params=truth)
    r = fit(m, FitData(ti, tr, y), seed=0)
    assert r.success, r.message
    assert r.rmse < EXACT_RTOL * np.sqrt(np.mean(y**2))
    assert r.flags and all("not_identifiable" in f for f in r.flags.values())
    assert len(r.stages[1]["rounds"]) <= LOCAL_ROUNDS


def test_chi2_tolerance_is_far_below_the_interval_scale():
    # the stopping rule may not move any parameter beyond its uncertainty: the 95 %
    # intervals are set by Delta chi-square = t^2 >= 3.84
    assert CHI2_TOL <= 1e-4 * 3.84


@pytest.mark.slow
def test_report_success_check_fails_on_a_starved_budget(tmp_path):
    out = tmp_path / "r"
    code = validate(
        out,
        quick=True,
        progress=False,
        shared_dir=False,
        sections_to_run=["ingest", "fits"],
        fit_options={"maxeval": [30, 6]},
    )
    res = json.loads((out / "results.json").read_text())
    checks = {c["id"]: c for c in res["checks"]}
    assert code == 1
    assert checks["fits.five_param.success"]["status"] == "fail"
    assert "maxeval reached" in checks["fits.five_param.success"]["reason"]
