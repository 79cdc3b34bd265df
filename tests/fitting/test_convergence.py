"""Convergence of the fitting core that does not hang on an evaluation budget.

A local stage that stops at its round budget restarts from its best point; a flat valley
(parameters not identifiable from in-plane scans) ends as "converged in chi-square" with the
parameters flagged, not as a failed optimisation; a starved budget still fails, and the
report's success check shows it.
"""

from __future__ import annotations

import json
from pathlib import Path

import nlopt
import pandas as pd
import pytest

import labbrdf
from labbrdf.fitting import FitData, fit
from labbrdf.fitting.core import CHI2_CONVERGED, CHI2_TOL, LOCAL_ROUNDS
from labbrdf.report.validate import validate

ROOT = Path(__file__).resolve().parents[2]
SCANS = ROOT / "labbrdf" / "data" / "fixtures" / "specular"

#: every fittable model of the specular fixtures, with each five_param shadowing choice
MODELS = [("smooth3", {}), ("five_param", {}), ("five_param", {"shadowing": "none"}),
          ("five_param", {"shadowing": "mb"})]  # fmt: skip


def _groups() -> list[tuple[str, float, pd.DataFrame]]:
    out = []
    for path in sorted(SCANS.glob("*.csv")):
        d = labbrdf.read(path).data
        for (s, w), g in d.groupby(["sample", "wavelength_nm"], sort=True):
            out.append((str(s), float(w), g.reset_index(drop=True)))
    return out


GROUPS = _groups()


@pytest.mark.slow
@pytest.mark.parametrize(("name", "options"), MODELS, ids=lambda v: str(v))
def test_every_fixture_group_of_every_model_converges_for_several_seeds(name, options):
    # nlopt's random sequence differs between releases and machines; the seeds stand in
    # for that: seeds 3 and 4 reproduce the OSR 860 nm run that used to stop at maxeval
    model = labbrdf.models.get(name, **options)
    failed = []
    for sample, wl, g in GROUPS:
        for seed in range(6):
            r = fit(model, g, seed=seed)
            if not r.success:
                failed.append((sample, wl, seed, r.message))
    assert not failed


def test_a_local_round_at_maxeval_restarts_from_its_best_point():
    g = next(g for s, w, g in GROUPS if s == "OSR" and w == 860.0)
    r = fit("five_param", g, seed=3)
    rounds = r.stages[-1]["rounds"]
    assert r.success
    assert len(rounds) >= 2
    assert rounds[0]["code"] == nlopt.MAXEVAL_REACHED
    # each round starts from the best point of the one before: chi-square never rises
    chis = [x["chisqr"] for x in rounds]
    assert all(b <= a for a, b in zip(chis, chis[1:], strict=False))
    assert r.nfev == r.stages[0]["nfev"] + sum(x["nfev"] for x in rounds)
    assert r.summary()["nlopt_version"].count(".") == 2


def test_a_starved_budget_is_not_a_success():
    g = next(g for s, w, g in GROUPS if s == "OSR" and w == 860.0)
    r = fit("five_param", g, seed=3, maxeval=[30, 10])
    assert not r.success
    assert "maxeval reached" in r.message


def test_a_flat_valley_is_reported_as_converged_with_flags():
    # five_param on noise-free data at ONE angle of incidence: k_b, a, b trade off along a
    # valley where chi-square falls by round-off only; the optimiser must stop there
    m = labbrdf.models.get("five_param")
    import numpy as np

    ti = np.full(41, 45.0)
    tr = 45.0 + np.linspace(-2, 2, 41)
    truth = {"kb": 0.2, "kr": 0.3, "a": 2.0, "b": -0.01, "kd": 0.0}
    y = m.evaluate(np.radians(ti), np.radians(tr), params=truth)
    r = fit(m, FitData(ti, tr, y), seed=0)
    local = r.stages[-1]
    assert r.success, r.message
    assert local["code"] == CHI2_CONVERGED
    assert "flat valley" in r.message
    assert r.flags and all("not_identifiable" in f for f in r.flags.values())
    assert len(local["rounds"]) <= LOCAL_ROUNDS


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
        fit_options={"maxeval": [30, 10]},
    )
    res = json.loads((out / "results.json").read_text())
    checks = {c["id"]: c for c in res["checks"]}
    assert code == 1
    assert checks["fits.five_param.success"]["status"] == "fail"
    assert "maxeval reached" in checks["fits.five_param.success"]["reason"]
