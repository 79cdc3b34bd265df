"""ci="auto": the Wald answer first, the profile only where it can change an interval."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pytest

from labbrdf.films import FilmModel, Layer, Stack
from labbrdf.fitting import FitData, FitError, fit
from labbrdf.fitting.film import fit_film
from labbrdf.fitting.intervals import END_SHIFT_MAX, RISE_HIGH, RISE_LOW
from labbrdf.models import Model, Parameters
from labbrdf.nk.dispersion import Cauchy

from .test_film_fit import _psi_delta


class Line(Model):
    """f = a + c theta_r: chi-square exactly quadratic in (a, c)."""

    name = "test-auto-line"

    def default_params(self) -> Parameters:
        p = Parameters()
        p.add("a", 0.5, -10.0, 10.0)
        p.add("c", 0.0, -10.0, 10.0)
        return p

    def _evaluate(self, p: Mapping[str, float], theta_i, theta_r, phi_r, wavelength):
        return p["a"] + p["c"] * theta_r


class Decay(Model):
    """f = a exp(-b theta_r): chi-square far from quadratic in b when the data are noisy."""

    name = "test-auto-decay"

    def default_params(self) -> Parameters:
        p = Parameters()
        p.add("a", 1.0, 0.0, 5.0)
        p.add("b", 1.0, 0.0, 50.0)
        return p

    def _evaluate(self, p: Mapping[str, float], theta_i, theta_r, phi_r, wavelength):
        return p["a"] * np.exp(-p["b"] * theta_r)


def _data(f, sigma: float, seed: int = 0, n: int = 12) -> FitData:
    tr = np.linspace(5.0, 60.0, n)
    y = f(np.radians(tr)) + sigma * np.random.default_rng(seed).standard_normal(n)
    return FitData(np.full_like(tr, 30.0), tr, y, np.full(n, sigma))


def test_the_band_moves_an_interval_end_by_at_most_the_stated_fraction() -> None:
    # a profile rising as r delta (x/x_w)^2 crosses delta at x_w / sqrt(r)
    assert 1 / np.sqrt(RISE_HIGH) == pytest.approx(1 - END_SHIFT_MAX)
    assert 1 / np.sqrt(RISE_LOW) == pytest.approx(1 + END_SHIFT_MAX)


def test_a_quadratic_chi2_keeps_every_wald_interval() -> None:
    fd = _data(lambda x: 0.2 + 0.5 * x, 0.01)
    seen = []
    res = fit(Line(), fd, ci="auto", on_wald=seen.append)
    wald = fit(Line(), fd, ci="wald")
    assert res.ci_methods == {"a": "wald", "c": "wald"} and res.ci_reasons == {}
    assert not seen  # nothing to profile: no second answer announced
    for k in ("a", "c"):
        assert res.params[k].ci95 == wald.params[k].ci95
    assert "(profile)" not in res.fit_report()


def test_a_curved_chi2_is_profiled_with_the_answer_of_ci_profile() -> None:
    fd = _data(lambda x: np.exp(-3.0 * x), 0.08)
    seen = []
    auto = fit(Decay(), fd, ci="auto", on_wald=seen.append)
    prof = fit(Decay(), fd, ci="profile")
    assert auto.ci_methods["b"] == "profile", auto.ci_reasons
    assert "chi2 not quadratic over its Wald interval" in auto.ci_reasons["b"]
    for k, how in auto.ci_methods.items():  # the same arithmetic on the same fit
        if how == "profile":
            assert auto.params[k].ci95 == prof.params[k].ci95
    # the Wald answer came first, with its own (symmetric) intervals, and is not changed
    (first,) = seen
    assert first.ci_methods["b"] == "wald"
    lo, hi = first.params["b"].ci95
    assert (lo + hi) / 2 == pytest.approx(first.params["b"].value)
    assert first.params["b"].ci95 != auto.params["b"].ci95
    assert "b: profile interval, chi2 not quadratic" in auto.fit_report()
    summ = auto.summary()["params"]["b"]
    assert summ["ci_method"] == "profile" and summ["ci_reason"] == auto.ci_reasons["b"]


def test_a_parameter_at_its_bound_is_profiled() -> None:
    fd = _data(lambda x: 0.2 + 0.0 * x, 0.01)
    model = Line()
    res = fit(model, fd, ci="auto", params={"c": {"value": 0.1, "min": 0.0, "max": 1.0}})
    assert res.ci_reasons.get("c") == "its Wald interval reaches a bound", res.ci_reasons
    assert res.ci_methods["c"] == "profile"


@pytest.mark.parametrize("bad", ["Wald", "both", ""])
def test_an_unknown_ci_is_refused(bad: str) -> None:
    with pytest.raises(FitError, match="ci must be one of 'auto', 'wald', 'profile'"):
        fit(Line(), _data(lambda x: x, 0.01), ci=bad)


def test_auto_is_not_combined_with_the_energy_constraint() -> None:
    with pytest.raises(FitError, match="ci='auto' is not combined with energy_constraint"):
        fit(Line(), _data(lambda x: x, 0.01), ci="auto", energy_constraint=lambda v, th: 0 * th)


# ----------------------------------------------------------------------------- films

TRUE = Stack([Layer(Cauchy(A=1.46, B=0.004), 105.0, "film")], "si")
BOX = {"film.thickness_nm": (0.0, 300.0), "film.A": (1.3, 1.8), "film.B": (0.0, 0.02)}


def test_a_well_determined_film_gets_the_wald_answer_alone() -> None:
    data = _psi_delta(TRUE, np.random.default_rng(3))
    fit_ = fit_film(FilmModel(TRUE, BOX), data)  # the default: auto
    s = fit_.summary()
    assert s["ci_method"] == "auto"
    assert {p["ci_method"] for p in s["layers"][0]["parameters"].values() if p["vary"]} == {"wald"}
    assert "intervals: Wald (no profile needed)" in fit_.fit_report()


def test_a_film_parameter_at_its_bound_is_profiled_as_with_ci_profile() -> None:
    clear = Stack([Layer(Cauchy(A=1.46, B=0.0), 105.0, "film")], "si")
    data = _psi_delta(clear, np.random.default_rng(4))
    box = {"film.thickness_nm": (50.0, 150.0), "film.B": (0.0, 0.02)}
    seen = []
    auto = fit_film(FilmModel(clear, box), data, on_wald=seen.append)
    assert auto.result.ci_methods == {"film.thickness_nm": "wald", "film.B": "profile"}
    assert "reaches a bound" in auto.result.ci_reasons["film.B"]
    assert seen and seen[0].result.ci_methods["film.B"] == "wald"
    prof = fit_film(FilmModel(clear, box), data, ci="profile")
    assert auto.result.params["film.B"].ci95 == prof.result.params["film.B"].ci95
    b = auto.summary()["layers"][0]["parameters"]["B"]
    assert b["ci_method"] == "profile" and "bound" in b["ci_reason"]
    assert "95 % profile [" in auto.fit_report()
    assert "profile for film.B (its Wald interval reaches a bound)" in auto.fit_report()


class Bent(Model):
    """f = a + (c + 10 a^2) theta_r: linear in (a, v = c + 10 a^2), a curved valley in (a, c).

    The profile over a (c free) is exactly quadratic in a, so its interval is Wald's; the
    straight quadratic path leaves the valley by 10 delta^2 in v, which only the
    Gauss-Newton step of c brings back.
    """

    name = "test-auto-bent"

    def default_params(self) -> Parameters:
        p = Parameters()
        p.add("a", 0.0, -5.0, 5.0)
        p.add("c", 0.0, -500.0, 500.0)
        return p

    def _evaluate(self, p: Mapping[str, float], theta_i, theta_r, phi_r, wavelength):
        return p["a"] + (p["c"] + 10.0 * p["a"] ** 2) * theta_r


def test_a_curved_valley_with_a_quadratic_profile_keeps_its_wald_interval() -> None:
    fd = _data(lambda x: 0.0 + 1.0 * x, 0.2, n=20)
    res = fit(Bent(), fd, ci="auto")
    assert res.ci_methods["a"] == "wald", res.ci_reasons
    prof = fit(Bent(), fd, ci="profile")
    half = res.params["a"].ci95[1] - res.params["a"].value
    for w, p in zip(res.params["a"].ci95, prof.params["a"].ci95, strict=True):
        assert abs(w - p) <= END_SHIFT_MAX * half
