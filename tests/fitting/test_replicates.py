"""Seed replicates of a stochastic model: the combination checked where it is known exactly.

The fake stochastic model is a line whose slope carries a seed-dependent Monte Carlo error
``e_s`` (``f = (a + e_s) x``): the sigma-weighted fit of seed s then returns exactly
``a_LS - e_s`` with the standard error ``sigma / sqrt(sum x^2)`` of the data alone, so the
mean of R replicates, their spread and the combined standard error are known in closed form.
"""

from __future__ import annotations

import dataclasses
import json
import math

import numpy as np
import pytest

from labbrdf import models, parallel
from labbrdf.fitting import FitData, FitError, combine_replicates, fit, fit_replicates
from labbrdf.models import Model, ModelError, Parameters

TAU = 0.05  # the Monte Carlo error's standard deviation on the slope


def _mc_error(seed: int) -> float:
    return TAU * float(np.random.default_rng(seed).standard_normal())


class _SeededLine(Model):
    """f = (a + e_seed) x, x = theta_r [rad]: a slope with a seed-fixed Monte Carlo error."""

    name = "seeded_line"
    stochastic = True

    def __init__(self, seed: int = 0) -> None:
        super().__init__(seed=seed)
        self.e = _mc_error(seed)

    def default_params(self) -> Parameters:
        p = Parameters()
        p.add("a", 1.0, 0.0, 10.0)
        return p

    def reseeded(self, seed: int) -> _SeededLine:
        return _SeededLine(seed)

    def _evaluate(self, p, theta_i, theta_r, phi_r, wavelength):
        return (p["a"] + self.e) * theta_r


class _Line(_SeededLine):
    stochastic = False


SIGMA = 0.01
AL = {"n": 1.55, "k": 7.71}


def _data() -> FitData:
    x_deg = np.linspace(5.0, 60.0, 12)
    y = 2.0 * np.radians(x_deg) + SIGMA * np.where(np.arange(12) % 2, 1.0, -1.0)
    return FitData(
        theta_i_deg=np.full(12, 30.0), theta_r_deg=x_deg, value=y, sigma=np.full(12, SIGMA)
    )


def _exact(d: FitData, seeds: list[int]) -> tuple[np.ndarray, float, float]:
    x = np.radians(np.asarray(d.theta_r_deg))
    y = np.asarray(d.value)
    a_ls = float(x @ y / (x @ x))
    est = np.array([a_ls - _mc_error(s) for s in seeds])
    se_data = SIGMA / math.sqrt(float(x @ x))
    return est, se_data, float(np.std(est, ddof=1))


@pytest.mark.parametrize(("seed0", "R"), [(0, 3), (10, 5)])
def test_replicates_mean_spread_and_stderr_match_the_exact_combination(seed0, R):
    """Mean of a_LS - e_s, s_between, and sqrt(se_data^2 + s_between^2 / R), to 1e-4."""
    d = _data()
    seeds = list(range(seed0, seed0 + R))
    est, se_data, sb = _exact(d, seeds)
    res = fit(_SeededLine(seed0), d, method="LN_BOBYQA", replicates=R)
    p = res.params["a"]
    assert [r["seed"] for r in res.replicates] == seeds
    assert [r["a"] for r in res.replicates] == pytest.approx(est, abs=1e-7)
    assert p.value == pytest.approx(est.mean(), abs=1e-7)
    assert res.seed_spread["a"] == pytest.approx(sb, rel=1e-4)
    assert p.stderr == pytest.approx(math.sqrt(se_data**2 + sb**2 / R), rel=1e-4)
    assert p.stderr > se_data  # the Monte Carlo part adds to the data's
    assert "seed replicates" in res.weighting
    lo, hi = p.ci95
    assert lo < p.value < hi


def test_one_replicate_is_the_plain_fit():
    d = _data()
    one = fit(_SeededLine(4), d, method="LN_BOBYQA", replicates=1)
    plain = fit(_SeededLine(4), d, method="LN_BOBYQA")
    assert one.replicates is None and one.seed_spread is None
    assert one.params["a"].value == plain.params["a"].value


def test_replicates_are_identical_whatever_the_executor():
    d = _data()
    serial = fit_replicates(_SeededLine(0), d, 3, method="LN_BOBYQA", executor="serial")
    pool = fit_replicates(
        _SeededLine(0),
        d,
        3,
        method="LN_BOBYQA",
        executor=parallel.Executor("processes", workers=2),
    )
    assert pool.replicates == serial.replicates
    assert pool.params["a"].value == serial.params["a"].value
    assert pool.params["a"].stderr == serial.params["a"].stderr


def test_replicates_in_the_summary_json_and_report():
    res = fit(_SeededLine(0), _data(), method="LN_BOBYQA", replicates=3)
    s = json.loads(json.dumps(res.summary()))
    assert [r["seed"] for r in s["replicates"]] == [0, 1, 2]
    assert s["seed_spread"]["a"] == pytest.approx(res.seed_spread["a"])
    rep = res.fit_report()
    assert "seed replicates" in rep and "s_between" in rep


def test_replicates_nfev_sums_the_fits():
    d = _data()
    res = fit(_SeededLine(0), d, method="LN_BOBYQA", replicates=2)
    singles = [fit(_SeededLine(s), d, method="LN_BOBYQA").nfev for s in (0, 1)]
    assert res.nfev == sum(singles)


@pytest.mark.parametrize("R", [0, -1, 1.5, True, "3"])
def test_bad_replicate_count_is_refused(R):
    with pytest.raises(FitError, match="replicates must be"):
        fit_replicates(_SeededLine(0), _data(), R)


def test_bad_replicate_count_through_fit_is_refused():
    with pytest.raises(FitError, match="replicates must be >= 2"):
        fit(_SeededLine(0), _data(), replicates=0)


def test_deterministic_model_with_replicates_is_refused():
    with pytest.raises(FitError, match="deterministic"):
        fit(_Line(0), _data(), replicates=3)
    with pytest.raises(FitError, match="deterministic"):
        fit("smooth3", _data(), replicates=2)


def test_replicates_of_a_non_model_are_refused():
    with pytest.raises(FitError, match="expected a Model or a model name"):
        fit(3, _data(), replicates=2)  # type: ignore[arg-type]


def test_replicates_with_profile_intervals_are_refused():
    with pytest.raises(FitError, match="ci='wald'"):
        fit(_SeededLine(0), _data(), replicates=2, ci="profile")


def test_combine_needs_two_results_of_the_same_parameters():
    d = _data()
    a = fit(_SeededLine(0), d, method="LN_BOBYQA")
    with pytest.raises(FitError, match="R >= 2"):
        combine_replicates([a], [0])
    b = dataclasses.replace(a, var_names=[])
    with pytest.raises(FitError, match="different parameters"):
        combine_replicates([a, b], [0, 1])


def test_deterministic_model_has_no_reseeded():
    with pytest.raises(ModelError, match="deterministic"):
        models.get("smooth3").reseeded(1)


def test_layered_is_stochastic_and_reseeded_keeps_its_options():
    m = models.get("layered", rays=4000, grid="3x6", floor=True, **AL)
    assert m.stochastic
    r = m.reseeded(7)
    assert r.options == {**m.options, "seed": 7}
    assert r.linear == m.linear and r is not m


def test_coherent_layered_is_deterministic():
    m = models.get("layered", coherent=True, **AL)
    assert not m.stochastic
    with pytest.raises(ModelError, match="deterministic"):
        m.reseeded(1)


def _table_data():
    import pandas as pd

    d = _data()
    rows = []
    for sample, shift in (("A", 0.0), ("B", 0.1)):
        rows.append(
            pd.DataFrame(
                {
                    "sample": sample,
                    "wavelength_nm": 550.0,
                    "quantity": "brdf",
                    "unit": "sr-1",
                    "theta_i_deg": d.theta_i_deg,
                    "phi_i_deg": 0.0,
                    "theta_r_deg": d.theta_r_deg,
                    "phi_r_deg": 180.0,
                    "value": np.asarray(d.value) * (1 + shift),
                    "sigma": SIGMA,
                }
            )
        )
    return pd.concat(rows, ignore_index=True)


def test_fit_many_with_replicates_matches_fit_and_has_the_spread_columns():
    from labbrdf.fitting import fit_many

    df = _table_data()
    table = fit_many(df, _SeededLine(0), method="LN_BOBYQA", replicates=3, executor="serial")
    one = fit(_SeededLine(0), df[df["sample"] == "A"], method="LN_BOBYQA", replicates=3)
    row = table.iloc[0]
    assert row["a"] == one.params["a"].value
    assert row["a_stderr"] == one.params["a"].stderr
    assert row["a_seed_spread"] == one.seed_spread["a"]
    assert row["a_replicates"].split(";") == [f"{r['a']:.10g}" for r in one.replicates]
    assert list(table["replicates"]) == [3, 3]
    pool = fit_many(
        df,
        _SeededLine(0),
        method="LN_BOBYQA",
        replicates=3,
        executor=parallel.Executor("processes", workers=2),
    )
    cols = ["a", "a_stderr", "a_seed_spread", "a_replicates"]
    assert pool[cols].equals(table[cols])


def test_fit_many_refuses_replicates_of_a_deterministic_model():
    from labbrdf.fitting import fit_many

    with pytest.raises(FitError, match="deterministic"):
        fit_many(_table_data(), _Line(0), replicates=2, executor="serial")
    with pytest.raises(FitError, match="replicates must be >= 2"):
        fit_many(_table_data(), _SeededLine(0), replicates=0, executor="serial")


def test_default_replicates_come_from_the_model():
    class _Three(_SeededLine):
        default_replicates = 3

        def reseeded(self, seed: int) -> _Three:
            m = _Three.__new__(_Three)
            _SeededLine.__init__(m, seed)
            return m

    res = fit(_Three(0), _data(), method="LN_BOBYQA")
    assert [r["seed"] for r in res.replicates] == [0, 1, 2]
    assert not any("one Monte Carlo seed" in w for w in res.warnings)


def test_one_seed_of_a_stochastic_model_warns_that_the_spread_is_missing():
    res = fit(_SeededLine(0), _data(), method="LN_BOBYQA", replicates=1)
    assert any("one Monte Carlo seed" in w for w in res.warnings)
    assert not any("one Monte Carlo seed" in w for w in fit(_Line(0), _data()).warnings)


def test_layered_defaults_to_three_replicates():
    assert models.get("layered", **AL).default_replicates == 3
    assert models.get("layered", coherent=True, **AL).default_replicates == 1
