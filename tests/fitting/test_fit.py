"""Tests of labbrdf.fitting: the 2013 paper reproduced, uncertainties, flags, bad input, batches.

Synthetic data are made here from the published Tables 1-2 of Zou, Bai, Wu (2013),
doi:10.3788/AOS201333.0612008 (theta_i 30/45/60 deg, theta_r = theta_i +- 2 deg in 0.2 deg
steps, phi_r = 180 deg), with the fixtures' noise model (fixtures/README.md: sigma =
sqrt((0.005 R)^2 + (1e-4 sr-1)^2), seeded).
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping

import numpy as np
import pandas as pd
import pytest
from numpy.typing import NDArray
from scipy import integrate, optimize, special, stats

from labbrdf.dataset import Measurement, make_frame
from labbrdf.fitting import FitData, FitError, fit, fit_many, parse_method
from labbrdf.fitting.objective import _bounded_lsq
from labbrdf.fitting.result import _fmt_ci, _fmt_unc
from labbrdf.models import Model, ModelError, Parameters, get
from labbrdf.models.smooth3 import guess_smooth3

#: Zou 2013 Table 1 (OSR) and Table 2 (mirror): wavelength [nm] -> (k1, k2 [rad], k3 [rad])
ZOU2013 = {
    "OSR": {
        360: (0.7443, -0.01156, 0.4161),
        500: (0.9740, -0.01506, 0.4177),
        550: (1.0150, -0.01660, 0.4176),
        860: (1.0310, -0.01968, 0.4155),
    },
    "mirror": {
        360: (0.4972, 0.1379, 0.3704),
        500: (0.5580, 0.1659, 0.3693),
        550: (0.5494, 0.1682, 0.3693),
        860: (0.3909, 0.1594, 0.3710),
    },
}
GROUPS = [(s, wl) for s in ZOU2013 for wl in ZOU2013[s]]
NAMES = ("k1", "k2", "k3")
REL_NOISE, ABS_NOISE = 0.005, 1e-4  # fixtures/README.md, specular scans


def scan_angles() -> tuple[NDArray, NDArray]:
    ti = np.repeat([30.0, 45.0, 60.0], 21)
    tr = ti + np.tile(np.round(np.arange(-2.0, 2.0001, 0.2), 10), 3)
    return ti, tr


def smooth3_truth(k: tuple[float, float, float]) -> tuple[NDArray, NDArray, NDArray]:
    ti, tr = scan_angles()
    y = get("smooth3").evaluate(
        np.radians(ti), np.radians(tr), params=dict(zip(NAMES, k, strict=True))
    )
    return ti, tr, y


def noisy(k: tuple[float, float, float], seed: int, rel: float = REL_NOISE) -> FitData:
    ti, tr, y = smooth3_truth(k)
    sigma = np.hypot(rel * y, ABS_NOISE)
    rng = np.random.default_rng([2013, seed])
    return FitData(ti, tr, y + sigma * rng.standard_normal(y.size), sigma)


def frame(fd: FitData, sample: str = "OSR", wl: float = 550.0, **kw) -> pd.DataFrame:
    sig = np.asarray(fd.sigma)
    return make_frame(
        sample=sample,
        instrument="synthetic",
        source="test",
        quantity="brdf",
        value=fd.value,
        unit="sr-1",
        wavelength_nm=wl,
        sigma=sig,
        theta_i_deg=fd.theta_i_deg,
        theta_r_deg=fd.theta_r_deg,
        phi_r_deg=180.0,
        **kw,
    )


class Line(Model):
    """f = a + c * theta_r [sr^-1]: linear in both parameters (an exact OLS problem)."""

    name = "test-line"
    linear = ("a", "c")

    def default_params(self) -> Parameters:
        p = Parameters()
        p.add("a", 0.5, -10.0, 10.0)
        p.add("c", 0.0, -10.0, 10.0)
        return p

    def _evaluate(self, p: Mapping[str, float], theta_i, theta_r, phi_r, wavelength):
        return p["a"] + p["c"] * theta_r

    def linear_components(self, p, theta_i, theta_r, phi_r, wavelength):
        return {"a": np.ones_like(theta_r), "c": np.asarray(theta_r, float)}


class Degenerate(Model):
    """f = (a + b) * theta_r + 0 * z: a and b are not separately identifiable, z has no effect."""

    name = "test-degenerate"

    def default_params(self) -> Parameters:
        p = Parameters()
        p.add("a", 0.3, -5.0, 5.0)
        p.add("b", 0.2, -5.0, 5.0)
        p.add("z", 1.0, 0.0, 2.0)
        return p

    def _evaluate(self, p, theta_i, theta_r, phi_r, wavelength):
        return (p["a"] + p["b"]) * theta_r + 0.0 * p["z"]


class NoBasis(Degenerate):
    """Declares a linear parameter but gives no linear components."""

    name = "test-nobasis"
    linear = ("a",)


class NaNModel(Line):
    name = "test-nan"
    linear = ()

    def _evaluate(self, p, theta_i, theta_r, phi_r, wavelength):
        return np.full_like(theta_r, np.nan)


def line_data(seed: int = 0, sigma: float | None = 0.01) -> tuple[FitData, NDArray]:
    tr = np.linspace(10.0, 50.0, 30)
    x = np.radians(tr)
    rng = np.random.default_rng(seed)
    y = 0.2 + 0.5 * x + 0.01 * rng.standard_normal(x.size)
    return FitData(np.full_like(tr, 30.0), tr, y, sigma), x


# --------------------------------------------------------------------------- the 2013 paper


@pytest.mark.parametrize(("sample", "wl"), GROUPS)
def test_noise_free_fit_recovers_published_parameters(sample: str, wl: int) -> None:
    k = ZOU2013[sample][wl]
    ti, tr, y = smooth3_truth(k)
    res = fit("smooth3", FitData(ti, tr, y))
    assert res.success
    for name, true in zip(NAMES, k, strict=True):
        assert res.values[name] == pytest.approx(true, rel=1e-4)


@pytest.mark.parametrize(("sample", "wl"), GROUPS)
def test_smooth3_guess_is_exact_on_noise_free_data(sample: str, wl: int) -> None:
    # eq. (7) is log-quadratic in ti - tr, so the parabola through log R is exact up to
    # round-off (float64 log of values ~0.1-1: ~1e-15, amplified by the polyfit conditioning)
    k = ZOU2013[sample][wl]
    ti, tr, y = smooth3_truth(k)
    g = guess_smooth3(np.radians(ti), np.radians(tr), y)
    assert [g[n] for n in NAMES] == pytest.approx(k, rel=1e-6)


@pytest.mark.slow
@pytest.mark.parametrize(
    ("sample", "rel", "ci"),
    [
        ("OSR", REL_NOISE, "wald"),
        ("mirror", REL_NOISE, "wald"),
        ("OSR", 0.01, "profile"),
        ("mirror", 0.01, "profile"),
    ],
)
def test_95_percent_intervals_cover_truth_in_90_percent_of_replicates(
    sample: str, rel: float, ci: str
) -> None:
    # Wald intervals at the fixtures' noise (0.5 %); at 1 % the mirror's k1-k2-k3 correlations
    # (> 0.99) make the Wald interval of k1 undercover (43/50 seen), the profile one does not
    k = ZOU2013[sample][550]
    n_rep = 50
    hits = dict.fromkeys(NAMES, 0)
    for seed in range(n_rep):
        res = fit("smooth3", noisy(k, seed, rel=rel), ci=ci)
        assert res.success and res.ci_method == ci
        for name, true in zip(NAMES, k, strict=True):
            lo, hi = res.params[name].ci95
            hits[name] += lo <= true <= hi
    # nominal 95%; 90% is ~1.6 binomial sigma (sqrt(.95*.05/50) = 3.1%) below it
    assert all(h >= 0.9 * n_rep for h in hits.values()), hits


@pytest.mark.parametrize("use_sigma", [True, False])
def test_profile_interval_equals_wald_interval_for_a_linear_model(use_sigma: bool) -> None:
    # chi2 is exactly quadratic: its profile crosses chi2_min + t^2 (x redchi) at +- t stderr
    fd, _ = line_data(sigma=0.01 if use_sigma else None)
    wald = fit(Line(), fd)
    prof = fit(Line(), fd, ci="profile")
    assert "(profile)" in prof.fit_report()
    for name in ("a", "c"):
        se = wald.params[name].stderr
        # Brent's xtol is 1e-3 stderr; the finite-difference stderr is exact to ~1e-8
        assert prof.params[name].ci95 == pytest.approx(wald.params[name].ci95, abs=2e-3 * se)


@pytest.mark.parametrize("sample", ["OSR", "mirror"])
def test_pm2deg_scans_report_k2_k3_as_poorly_determined(sample: str) -> None:
    res = fit("smooth3", noisy(ZOU2013[sample][550], seed=1))
    for name in ("k2", "k3"):
        assert set(res.flags[name]) & {"poorly_determined", "not_identifiable"}, res.flags
        assert res.params[name].stderr > 0.05 * abs(res.params[name].value)
        lo, hi = res.params[name].ci95
        assert lo < res.params[name].value < hi
    report = res.fit_report()
    assert "95% [" in report and "k3:" in report
    # k3 is printed with the digits its stderr supports, not the paper's four
    k3 = res.params["k3"]
    assert _fmt_unc(k3.value, k3.stderr) in report
    assert f"{k3.value:.4f}" not in report


def test_osr_amplitude_is_well_determined() -> None:
    res = fit("smooth3", noisy(ZOU2013["OSR"][550], seed=1))
    assert "k1" not in res.flags
    assert res.params["k1"].stderr < 0.01 * res.params["k1"].value


def test_format_with_uncertainty_keeps_two_significant_digits() -> None:
    assert _fmt_unc(0.41613, 0.0312) == "0.416 +/- 0.031"
    assert _fmt_unc(1.01502, 0.0018) == "1.0150 +/- 0.0018"
    assert _fmt_unc(1.0, None) == "1 +/- (not estimated)"
    assert _fmt_ci((0.355, 0.477), 0.0312) == "[0.355, 0.477]"
    assert _fmt_ci((0.355, 0.477), float("inf")) == ""


def test_three_vs_five_parameter_fits_at_45_deg() -> None:
    fd = noisy(ZOU2013["OSR"][550], seed=1)
    fd = fd.take(np.asarray(fd.theta_i_deg) == 45.0)
    r3 = fit("smooth3", fd)
    r5 = fit("five_param", fd)
    assert r3.success and r5.success
    assert r5.G == "ts" and r5.summary()["G"] == "ts"
    # both describe the 45 deg lobe to the noise level (0.5 % relative, 21 points: the
    # rms of 21 - p normal deviates lies within +-30 % of 0.5 % at > 3 sigma)
    for r in (r3, r5):
        assert 0.5 * 0.6 < r.rmse_pct < 0.5 * 1.3
    # a single +-2 deg scan cannot separate the five parameters: the result says so
    assert "not_identifiable" in r5.flags["a"] and "not_identifiable" in r5.flags["b"]


@pytest.mark.parametrize(("sample", "wl"), GROUPS)
def test_default_method_reaches_the_long_global_search_optimum(sample: str, wl: int) -> None:
    fd = noisy(ZOU2013[sample][wl], seed=7)
    quick = fit("smooth3", fd)
    slow = fit("smooth3", fd, maxeval=(4000, None), guess=False)
    # same basin: chi2 agrees far below the Delta chi2 ~ 4 that sets a 95% interval
    assert quick.chisqr <= slow.chisqr + 1e-4


def test_profiled_and_full_three_parameter_search_agree() -> None:
    fd = noisy(ZOU2013["mirror"][360], seed=3)
    a = fit("smooth3", fd)
    b = fit("smooth3", fd, profile=False, maxeval=(3000, None))
    assert a.profiled == ["k1"] and b.profiled == []
    assert b.chisqr == pytest.approx(a.chisqr, rel=1e-7)
    for name in NAMES:
        assert b.values[name] == pytest.approx(a.values[name], rel=1e-4)
    assert b.params["k3"].stderr == pytest.approx(a.params["k3"].stderr, rel=1e-3)


# --------------------------------------------------------------------------- uncertainties


@pytest.mark.parametrize("use_sigma", [True, False])
@pytest.mark.parametrize("profile", [True, False])
def test_stderr_equals_the_ols_formula_for_a_linear_model(use_sigma: bool, profile: bool) -> None:
    fd, x = line_data(sigma=0.01 if use_sigma else None)
    # weighting=None: 1/sigma^2 with sigmas, uniform (OLS) without
    res = fit(Line(), fd, profile=profile, weighting=None)
    X = np.column_stack([np.ones_like(x), x])
    y = np.asarray(fd.value)
    beta, *_ = np.linalg.lstsq(X, y, rcond=None)
    sse = float(np.sum((y - X @ beta) ** 2))
    cov = np.linalg.inv(X.T @ X)
    cov *= 0.01**2 if use_sigma else sse / (x.size - 2)
    # a linear model: central differences are exact up to float64 round-off (~1e-10 rel)
    assert [res.values["a"], res.values["c"]] == pytest.approx(beta, rel=1e-7)
    assert res.params["a"].stderr == pytest.approx(math.sqrt(cov[0, 0]), rel=1e-6)
    assert res.params["c"].stderr == pytest.approx(math.sqrt(cov[1, 1]), rel=1e-6)
    rho = cov[0, 1] / math.sqrt(cov[0, 0] * cov[1, 1])
    assert res.params["a"].correl["c"] == pytest.approx(rho, rel=1e-6)
    assert res.weighted is use_sigma
    assert res.redchi == pytest.approx(res.chisqr / (x.size - 2), rel=1e-12)


def test_ci95_is_student_t_times_stderr() -> None:
    fd, _ = line_data()
    res = fit(Line(), fd)
    p = res.params["c"]
    t = stats.t.ppf(0.975, res.nfree)
    assert p.ci95 == pytest.approx((p.value - t * p.stderr, p.value + t * p.stderr), rel=1e-12)


def test_degenerate_parameters_are_flagged_not_identifiable() -> None:
    fd, _ = line_data()
    res = fit(Degenerate(), fd)
    assert res.success
    for name in ("a", "b", "z"):
        assert "not_identifiable" in res.flags[name]
    assert any("do not depend" in r for r in res.flag_reasons["z"])
    assert any("singular" in r for r in res.flag_reasons["a"])
    assert res.params["z"].stderr is None and res.params["a"].stderr is None
    json.dumps(res.summary(), allow_nan=False)


def test_parameter_at_bound_is_flagged() -> None:
    ti, tr, y = smooth3_truth(ZOU2013["OSR"][550])
    res = fit("smooth3", FitData(ti, tr, y), params={"k1": {"max": 0.5}})
    assert res.values["k1"] == 0.5
    assert "at_bound" in res.flags["k1"]
    assert "at its max" in res.flag_reasons["k1"][0]
    assert res.summary()["params"]["k1"]["at_bound"] is True


def test_params_accept_parameter_objects_and_values() -> None:
    fd = noisy(ZOU2013["OSR"][550], seed=2)
    p = get("smooth3").params.copy()
    p["k2"].vary = False
    p["k2"].value = 0.01
    res = fit("smooth3", fd, params={"k2": p["k2"], "k3": 0.5})
    assert res.values["k2"] == 0.01 and res.var_names == ["k1", "k3"]
    assert res.init_values["k3"] == 0.5  # a value given by the caller is not replaced by the guess
    assert res.summary()["params"]["k2"]["vary"] is False


def test_fixed_parameter_is_held_and_not_counted() -> None:
    fd = noisy(ZOU2013["OSR"][550], seed=2)
    res = fit("smooth3", fd, fix={"k2": 0.0})
    assert res.values["k2"] == 0.0 and not res.params["k2"].vary
    assert res.nvarys == 2 and res.var_names == ["k1", "k3"]
    assert "(fixed)" in res.fit_report()


# --------------------------------------------------------------------------- results


def test_summary_is_json_safe_and_round_trips() -> None:
    res = fit("smooth3", noisy(ZOU2013["mirror"][500], seed=4))
    s = json.loads(json.dumps(res.summary(), allow_nan=False))
    assert s["model"] == "smooth3" and s["seed"] == 0 and s["method"] == "GN_CRS2_LM+LN_BOBYQA"
    assert s["params"]["k3"]["value"] == res.values["k3"]
    assert s["params"]["k3"]["ci95"] == list(res.params["k3"].ci95)
    assert s["G"] is None and s["options"] == {}


def test_rmse_definitions_follow_the_residuals() -> None:
    fd = noisy(ZOU2013["OSR"][360], seed=5)
    res = fit("smooth3", fd)
    f = get("smooth3").evaluate(
        np.radians(fd.theta_i_deg), np.radians(fd.theta_r_deg), params=res.values
    )
    y = np.asarray(fd.value)
    assert res.best_fit == pytest.approx(f, rel=1e-13)
    assert res.rmse == pytest.approx(np.sqrt(np.mean((y - f) ** 2)), rel=1e-10)
    assert res.rmse_pct == pytest.approx(100 * np.sqrt(np.mean(((y - f) / y) ** 2)), rel=1e-10)
    # with 0.5 % relative noise the paper-sense RMSE is ~0.5 % (63 points: +-9 % at 1 sigma)
    assert 0.5 * 0.7 < res.rmse_pct < 0.5 * 1.3


def test_fit_report_and_html_have_lmfit_blocks() -> None:
    res = fit("smooth3", noisy(ZOU2013["OSR"][500], seed=6))
    text = res.fit_report()
    for block in ("[[Model]]", "[[Fit Statistics]]", "[[Variables]]", "[[Correlations]]"):
        assert block in text
    assert "RMSE (paper, %)" in text and str(res) == text
    h = res._repr_html_()
    assert h.count("<table>") == 2 and "k3" in h and "95% interval" in h


def test_fit_never_returns_nan_parameters_as_success() -> None:
    fd, _ = line_data()
    res = fit(NaNModel(), fd, method="LN_BOBYQA")
    assert not res.success
    assert "non-finite" in res.message


def test_seeded_fits_are_reproducible() -> None:
    fd = noisy(ZOU2013["mirror"][860], seed=8)
    a = fit("smooth3", fd, seed=3, guess=False)
    b = fit("smooth3", fd, seed=3, guess=False)
    assert a.values == b.values and a.nfev == b.nfev


@pytest.mark.parametrize(
    "method",
    [
        "GN_DIRECT_L+LN_NELDERMEAD",
        "LN_BOBYQA",
        "GN_ISRES+LN_COBYLA",
        "GN_CRS2_LM+LD_LBFGS",
        "G_MLSL_LDS",
        "LN_AUGLAG",
        "nlopt_gn_esch+ln_sbplx",
    ],
)
def test_any_nlopt_algorithm_name_is_accepted(method: str) -> None:
    fd = noisy(ZOU2013["OSR"][550], seed=9)
    ref = fit("smooth3", fd)
    res = fit("smooth3", fd, method=method)
    assert res.method == "+".join(parse_method(method))
    # every one finds the optimum's basin; its chi2 lies within 1 of the best (1-sigma level)
    assert res.chisqr <= ref.chisqr + 1.0


def test_the_package_level_fit_is_callable_after_import() -> None:
    import labbrdf.fitting  # noqa: F401  (the subpackage no longer shadows labbrdf.fit)

    fd, _ = line_data()
    assert labbrdf.fit(Line(), fd).success


# --------------------------------------------------------------------------- energy


def smooth3_rho(vals: Mapping[str, float], theta_i_deg: NDArray) -> NDArray:
    """Closed form of docs/models.md 1.2 (complex erf), independent of labbrdf.integrate."""
    k1, k2, k3 = vals["k1"], vals["k2"], vals["k3"]
    ti = np.radians(np.asarray(theta_i_deg, float))
    c = ti - k2
    u0, u1 = -c / k3, (np.pi / 2 - c) / k3
    z = (
        k3
        * np.exp(1j * c)
        * np.exp(-(k3**2) / 4)
        * np.sqrt(np.pi)
        / 2
        * (special.erf(u1 - 0.5j * k3) - special.erf(u0 - 0.5j * k3))
    )
    return np.pi * k1 / (4 * np.cos(ti)) * z.imag


def test_closed_form_rho_matches_quadrature() -> None:
    vals = dict(zip(NAMES, ZOU2013["OSR"][550], strict=True))
    m = get("smooth3")
    for th in (0.0, 46.0, 60.0):

        def f(tr: float, th: float = th) -> float:
            return (
                2 * np.pi * m.evaluate(np.radians(th), tr, params=vals) * np.cos(tr) * np.sin(tr)
            )

        ref, _ = integrate.quad(f, 0, np.pi / 2)
        assert smooth3_rho(vals, np.array([th]))[0] == pytest.approx(ref, rel=1e-9)


@pytest.mark.parametrize("method", ["GN_CRS2_LM+LN_BOBYQA", "GN_ISRES+LN_COBYLA"])
def test_energy_constraint_keeps_rho_at_most_one(method: str) -> None:
    # k1 = 2.2 with the OSR shape gives rho(60 deg) = 2.2/1.083 > 1 (docs/models.md 1.4)
    k = (2.2, -0.0166, 0.4176)
    ti, tr, y = smooth3_truth(k)
    fd = FitData(ti, tr, y)
    free = fit("smooth3", fd)
    assert smooth3_rho(free.values, np.array([60.0]))[0] > 1.5
    profile = method.startswith("GN_CRS2")
    res = fit(
        "smooth3",
        fd,
        method=method,
        energy_constraint=smooth3_rho,
        profile=profile,
        maxeval=None if profile else (3000, 2000),
    )
    assert res.success, res.message
    rho = smooth3_rho(res.values, np.linspace(30, 60, 31))
    assert rho.max() <= 1 + 1e-6
    assert res.energy["active"] and res.energy["max_rho"] == pytest.approx(1.0, abs=1e-6)


def test_energy_constraint_uses_labbrdf_integrate_when_available() -> None:
    integrate = pytest.importorskip("labbrdf.integrate")
    vals = dict(zip(NAMES, ZOU2013["OSR"][550], strict=True))
    rho = integrate.hemispherical_reflectance(get("smooth3"), vals, np.array([30.0, 60.0]))
    assert np.asarray(rho) == pytest.approx(smooth3_rho(vals, np.array([30.0, 60.0])), rel=1e-6)
    ti, tr, y = smooth3_truth((2.2, -0.0166, 0.4176))
    res = fit("smooth3", FitData(ti, tr, y), energy_constraint=True)
    assert res.energy["max_rho"] <= 1 + 1e-6


# --------------------------------------------------------------------------- data input


def test_measurement_and_dataframe_input_give_the_fitdata_result() -> None:
    fd = noisy(ZOU2013["OSR"][550], seed=10)
    df = frame(fd)
    a = fit("smooth3", fd)
    b = fit("smooth3", Measurement(df))
    c = fit("smooth3", df)
    assert a.values == b.values == c.values
    assert b.weighted and b.quantity == "brdf" and b.unit == "sr-1"


def test_other_quantities_in_the_table_are_not_fitted() -> None:
    fd = noisy(ZOU2013["OSR"][550], seed=10)
    psi = make_frame(
        sample="OSR",
        instrument="x",
        source="t",
        quantity="psi",
        value=40.0,
        unit="deg",
        wavelength_nm=550.0,
        theta_i_deg=60.0,
    )
    res = fit("smooth3", pd.concat([frame(fd), psi], ignore_index=True))
    assert res.ndata == len(fd)


def test_nan_rows_are_dropped_and_counted_with_omit() -> None:
    fd = noisy(ZOU2013["OSR"][550], seed=11)
    y = np.asarray(fd.value).copy()
    y[[3, 17]] = [np.nan, np.inf]
    bad = FitData(fd.theta_i_deg, fd.theta_r_deg, y, fd.sigma)
    with pytest.raises(FitError, match=r"2 point\(s\) with NaN or infinite values .*\[3, 17\]"):
        fit("smooth3", bad)
    res = fit("smooth3", bad, nan_policy="omit")
    assert res.ndropped == 2 and res.ndata == len(fd) - 2
    assert "2 point(s) with NaN/inf values dropped" in res.warnings[0]
    assert "2 dropped" in res.fit_report()


def test_partial_sigma_is_refused_unless_ignored() -> None:
    fd = noisy(ZOU2013["OSR"][550], seed=12)
    sig = np.asarray(fd.sigma).copy()
    sig[:5] = np.nan
    part = FitData(fd.theta_i_deg, fd.theta_r_deg, fd.value, sig)
    with pytest.raises(FitError, match="sigma is given for 58 of 63 points"):
        fit("smooth3", part)
    assert not fit("smooth3", part, use_sigma=False).weighted


def test_nonpositive_sigma_is_refused() -> None:
    fd = noisy(ZOU2013["OSR"][550], seed=12)
    zero = FitData(fd.theta_i_deg, fd.theta_r_deg, fd.value, np.zeros(len(fd)))
    with pytest.raises(FitError, match="finite sigma > 0"):
        fit("smooth3", zero)


def test_mixed_quantities_are_refused_unless_one_is_chosen() -> None:
    fd = noisy(ZOU2013["OSR"][550], seed=13)
    a = frame(fd)
    b = frame(fd).assign(quantity="specular_intensity", unit="1")
    both = pd.concat([a, b], ignore_index=True)
    with pytest.raises(FitError, match=r"data mix quantities/units .*quantity=\.\.\."):
        fit("smooth3", both)
    res = fit("smooth3", both, quantity="specular_intensity")
    assert res.quantity == "specular_intensity" and res.unit == "1" and res.ndata == len(fd)


def test_unfittable_quantity_is_refused() -> None:
    fd = noisy(ZOU2013["OSR"][550], seed=13)
    with pytest.raises(FitError, match="quantity='psi' cannot be fitted"):
        fit("smooth3", frame(fd), quantity="psi")
    psi = make_frame(
        sample="S",
        instrument="x",
        source="t",
        quantity="psi",
        value=[40.0] * 5,
        unit="deg",
        wavelength_nm=550.0,
        theta_i_deg=60.0,
    )
    with pytest.raises(FitError, match=r"no rows with quantity in \['brdf'"):
        fit("smooth3", psi)


def test_several_wavelengths_in_one_fit_are_refused() -> None:
    fd = noisy(ZOU2013["OSR"][550], seed=14)
    df = pd.concat([frame(fd, wl=500.0), frame(fd, wl=550.0)], ignore_index=True)
    with pytest.raises(FitError, match="2 different 'wavelength_nm' values.*fit_many"):
        fit("smooth3", df)


def test_bad_data_types_and_shapes_are_refused() -> None:
    with pytest.raises(FitError, match="expected a Measurement, DataFrame or FitData"):
        fit("smooth3", [1, 2, 3])
    with pytest.raises(FitError, match=r"'theta_r_deg' has shape \(2,\), expected \(3,\)"):
        FitData([30, 30, 30], [29, 30], [1, 2, 3])
    with pytest.raises(FitError, match="no data points"):
        FitData([], [], [])
    with pytest.raises(FitError, match=r"'value' must be 1-D, got shape \(2, 2\)"):
        FitData(30.0, 30.0, [[1.0, 2.0], [3.0, 4.0]])
    with pytest.raises(FitError, match="'phi_r_deg' is required"):
        FitData([30.0], [30.0], [1.0], phi_r_deg=None)
    with pytest.raises(FitError, match="missing column"):
        fit("smooth3", pd.DataFrame({"value": [1.0]}))


def test_fewer_points_than_free_parameters_is_refused() -> None:
    fd = FitData([30.0, 30.0, 30.0], [29.0, 30.0, 31.0], [0.3, 0.31, 0.3])
    with pytest.raises(FitError, match=r"3 point\(s\) for 3 free parameter\(s\)"):
        fit("smooth3", fd)


def test_all_points_on_the_specular_line_are_refused_for_smooth3() -> None:
    ti = np.array([20.0, 30.0, 45.0, 60.0])
    y = get("smooth3").evaluate(np.radians(ti), np.radians(ti))
    fd = FitData(ti, ti, y)
    with pytest.raises(FitError, match="specular line .* fix \\['k2', 'k3'\\]"):
        fit("smooth3", fd)
    with pytest.raises(FitError, match="specular line"):
        fit("smooth3", fd, fix={"k2": 0.0})
    res = fit("smooth3", fd, fix={"k2": 0.0, "k3": 0.4})
    assert res.values["k1"] == pytest.approx(1.0, rel=1e-12)  # the defaults made the data


def test_unknown_method_lists_valid_names() -> None:
    fd = noisy(ZOU2013["OSR"][550], seed=15)
    with pytest.raises(
        FitError,
        match=r"unknown nlopt algorithm 'GN_FOO' .* valid names are "
        r"\[.*'GN_CRS2_LM'.*'LN_BOBYQA'",
    ):
        fit("smooth3", fd, method="GN_FOO+LN_BOBYQA")
    with pytest.raises(FitError, match="method must be a string"):
        parse_method("")


def test_unknown_model_and_parameter_names_are_refused() -> None:
    fd = noisy(ZOU2013["OSR"][550], seed=15)
    with pytest.raises(ModelError, match="unknown model 'smooth4'"):
        fit("smooth4", fd)
    with pytest.raises(FitError, match="fix: model 'smooth3' has no parameter 'k4'"):
        fit("smooth3", fd, fix={"k4": 0.0})
    with pytest.raises(FitError, match="params: model 'smooth3' has no parameter 'kk'"):
        fit("smooth3", fd, params={"kk": 1.0})
    with pytest.raises(FitError, match=r"fix: model 'smooth3': k2=nan: expected a finite number"):
        fit("smooth3", fd, fix={"k2": float("nan")})
    with pytest.raises(FitError, match="model: expected a Model or a model name"):
        fit(3, fd)


def test_bad_settings_are_refused() -> None:
    fd = noisy(ZOU2013["OSR"][550], seed=16)
    with pytest.raises(
        FitError, match="ci must be one of 'auto', 'wald', 'profile', got 'bootstrap'"
    ):
        fit("smooth3", fd, ci="bootstrap")
    with pytest.raises(FitError, match="ci='profile' is not combined with energy_constraint"):
        fit("smooth3", fd, ci="profile", energy_constraint=True)
    with pytest.raises(FitError, match="nan_policy must be 'raise' or 'omit'"):
        fit("smooth3", fd, nan_policy="drop")
    with pytest.raises(FitError, match=r"maxeval: 1 budgets for 2 stage\(s\)"):
        fit("smooth3", fd, maxeval=[100])
    with pytest.raises(FitError, match="global algorithm GN_CRS2_LM needs finite bounds"):
        fit("smooth3", fd, params={"k2": {"min": -math.inf}})
    with pytest.raises(FitError, match="every parameter is fixed"):
        fit("smooth3", fd, fix={"k1": 1.0, "k2": 0.0, "k3": 0.4})
    with pytest.raises(FitError, match="'k3': a log-scale search needs min > 0, got 0.0"):
        fit("smooth3", fd, params={"k3": {"min": 0.0}})
    with pytest.raises(FitError, match="min 0.5 must be < max 0.5"):
        fit("smooth3", fd, params={"k2": {"min": 0.5, "max": 0.5}})
    with pytest.raises(FitError, match="params: model 'smooth3': k3=nan: expected a finite"):
        fit("smooth3", fd, params={"k3": float("nan")})
    with pytest.raises(FitError, match="declares linear parameters but gives no linear"):
        fit(NoBasis(), line_data()[0])
    assert fit(NoBasis(), line_data()[0], profile=False).profiled == []
    with pytest.raises(FitError, match="profile=True but model 'test-degenerate'"):
        fit(Degenerate(), line_data()[0], profile=True)
    with pytest.raises(FitError, match="energy_constraint with LN_BOBYQA: this algorithm"):
        fit(
            Line(),
            line_data()[0],
            profile=False,
            method="LN_BOBYQA",
            energy_constraint=lambda v, t: np.zeros_like(t),
        )


# --------------------------------------------------------------------------- batches


def dataset(rows_per_group_drop: dict[tuple[str, int], int] | None = None) -> pd.DataFrame:
    frames = []
    for i, (sample, wl) in enumerate(GROUPS):
        fd = noisy(ZOU2013[sample][wl], seed=100 + i)
        frames.append(frame(fd, sample=sample, wl=float(wl)))
    return pd.concat(frames, ignore_index=True)


def test_fit_many_gives_one_row_per_group_equal_to_single_fits() -> None:
    df = dataset()
    table = fit_many(df, "smooth3", scheduler="serial", progress=False)
    assert list(table["sample"]) == ["OSR"] * 4 + ["mirror"] * 4 or len(table) == 8
    assert len(table) == 8
    for col in (
        "k1",
        "k1_stderr",
        "k1_ci95_lo",
        "k1_ci95_hi",
        "k3_flags",
        "rmse",
        "rmse_pct",
        "nfev",
        "success",
        "message",
    ):
        assert col in table.columns
    row = table[(table["sample"] == "mirror") & (table["wavelength_nm"] == 860.0)].iloc[0]
    single = fit("smooth3", df[(df["sample"] == "mirror") & (df["wavelength_nm"] == 860.0)])
    assert row["k3"] == single.values["k3"] and row["k3_stderr"] == single.params["k3"].stderr
    assert table["success"].all()
    table2, results = fit_many(
        df, "smooth3", scheduler="serial", progress=False, return_results=True
    )
    pd.testing.assert_frame_equal(
        table.drop(columns="elapsed_s"), table2.drop(columns="elapsed_s")
    )
    assert [k for k, _ in results] == table[["sample", "wavelength_nm"]].to_dict("records")
    assert results[-1][1].values == single.values


@pytest.mark.slow
def test_fit_many_result_does_not_depend_on_scheduler_or_workers() -> None:
    df = Measurement(dataset())
    serial = fit_many(df, "smooth3", scheduler="serial", progress=False)
    pool = fit_many(df, "smooth3", scheduler="processes", workers=2, progress=False, chunks=3)
    cols = [c for c in serial.columns if c != "elapsed_s"]
    pd.testing.assert_frame_equal(serial[cols], pool[cols])


def test_fit_many_reports_a_group_that_cannot_be_fitted() -> None:
    df = dataset()
    keep = ~((df["sample"] == "OSR") & (df["wavelength_nm"] == 360.0)) | (df.index % 30 == 0)
    table = fit_many(
        df[keep], "smooth3", scheduler="serial", progress=False, by=["sample", "wavelength_nm"]
    )
    bad = table[(table["sample"] == "OSR") & (table["wavelength_nm"] == 360.0)].iloc[0]
    assert not bad["success"] and "free parameter" in bad["message"]
    assert np.isnan(bad["k1"])
    assert table["success"].sum() == 7


def test_fit_many_refuses_bad_arguments() -> None:
    df = dataset()
    with pytest.raises(FitError, match=r"by: unknown column\(s\) \['lamp'\]"):
        fit_many(df, "smooth3", by=["lamp"], scheduler="serial")
    with pytest.raises(FitError, match="unknown nlopt algorithm"):
        fit_many(df, "smooth3", method="XX", scheduler="serial")
    with pytest.raises(FitError, match="fix: model 'smooth3' has no parameter 'q'"):
        fit_many(df, "smooth3", fix={"q": 1.0}, scheduler="serial")
    with pytest.raises(FitError, match="expected a Measurement or DataFrame"):
        fit_many([1], "smooth3", scheduler="serial")


def test_bounded_lsq_matches_scipy_lsq_linear() -> None:
    rng = np.random.default_rng(42)
    for _ in range(50):
        k = int(rng.integers(1, 4))
        A = rng.standard_normal((20, k))
        b = rng.standard_normal(20)
        lo = np.where(rng.random(k) < 0.5, 0.0, -np.inf)
        hi = np.where(rng.random(k) < 0.5, 0.3, np.inf)
        p = _bounded_lsq(A.T @ A, A.T @ b, lo, hi)
        ref = optimize.lsq_linear(A, b, bounds=(lo, hi), method="bvls").x
        assert np.all(p >= lo) and np.all(p <= hi)
        # a strictly convex QP has one minimiser; bvls is exact to ~1e-12
        assert p == pytest.approx(ref, abs=1e-9)
