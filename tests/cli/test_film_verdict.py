"""`labbrdf film`: the verdict of a wrong model, the substrate named, n, k at --at wavelengths.

A fit whose Woollam MSE exceeds ``MSE_WRONG_MODEL`` (20) says in words that its parameters
are not meaningful and what to try; a fit that describes its data says nothing of the kind.
The standard errors of n, k are checked against the closed form of a Cauchy layer,
``var n = var A + var B / lambda^4 + 2 cov(A, B) / lambda^2`` (lambda in um).
"""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

from labbrdf.cli import main
from labbrdf.dataset import Measurement, write
from labbrdf.films import FilmModel, Layer, Stack
from labbrdf.fitting.film import fit_film
from labbrdf.fitting.film_verdict import MSE_WRONG_MODEL
from labbrdf.nk.dispersion import Cauchy

TRUE = Stack([Layer(Cauchy(A=1.46, B=0.004), 105.0, "film")], "si")
LAYER = "film:cauchy:0..300:A=1.3..1.8:B=0..0.02:C=0"  # C fixed: the closed form below


@pytest.fixture(scope="module")
def film_file(tmp_path_factory):
    """psi/Delta of 105 nm of Cauchy on Si at 60 and 70 deg, noise at the stated sigmas."""
    wl = np.linspace(300, 1000, 40)
    w, t = (a.ravel() for a in np.meshgrid(wl, [60.0, 70.0], indexing="ij"))
    psi, delta = TRUE.psi_delta(w, t)
    rng = np.random.default_rng(1)
    parts = [
        pd.DataFrame(
            {
                "sample": "wafer",
                "instrument": "sim",
                "source": "film.parquet",
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
        for q, v, s in (("psi", psi, 0.02), ("delta", delta, 0.05))
    ]
    df = pd.concat(parts, ignore_index=True)
    df["quantity"] = df["quantity"].astype("category")
    p = tmp_path_factory.mktemp("verdict") / "film.parquet"
    write(Measurement(df, {}), p)
    return p


def test_a_wrong_substrate_gets_the_verdict_and_is_named(film_file, capsys):
    # the film is on Si; fitted on fused silica the model misses by far more than 20 sigma
    argv = ["film", str(film_file), "--substrate", "sio2", "--layer", LAYER, "--ci", "wald"]
    assert main(argv) == 0
    out = capsys.readouterr().out
    assert "substrate: sio2 (reference table, Malitson 1965)" in out
    verdict = out.strip().splitlines()[-1]
    assert verdict.startswith("VERDICT: MSE ") and "not meaningful" in verdict
    assert "--substrate BARE.dat" in verdict and "more layers" in verdict
    assert "sio2 (reference table" in verdict  # the substrate that was used


def test_the_right_model_gets_no_verdict(film_file, capsys):
    assert main(["film", str(film_file), "--layer", LAYER, "--ci", "wald", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["mse"] < 2 and doc["verdict"] is None
    assert doc["substrate"]["name"] == "si (reference table, Green 2008)"


def test_the_verdict_thresholds_are_the_woollam_mse():
    from labbrdf.fitting.film_verdict import MSE_INCOMPLETE, wrong_model_verdict

    assert wrong_model_verdict(MSE_INCOMPLETE, "si") is None
    incomplete = wrong_model_verdict(MSE_INCOMPLETE * 1.01, "si") or ""
    assert incomplete.startswith("MSE 20.2 > 20: the model lacks something")
    assert "not meaningful" not in incomplete and "interface" in incomplete
    assert "lacks something" in (wrong_model_verdict(MSE_WRONG_MODEL, "si") or "")
    assert "not meaningful" in (wrong_model_verdict(MSE_WRONG_MODEL * 1.01, "si") or "")


def test_at_prints_n_k_with_the_cauchy_closed_form_sigma(film_file, tmp_path, capsys):
    fj, nk = tmp_path / "fit.json", tmp_path / "nk.csv"
    argv = ["film", str(film_file), "--layer", LAYER, "--ci", "wald", "--at", "550,633"]
    assert main([*argv, "--fit-json", str(fj), "-o", str(nk)]) == 0
    out = capsys.readouterr().out
    assert "n, k at 550 nm (+- standard error):" in out
    doc = json.loads(fj.read_text())
    box = {"film.thickness_nm": (0.0, 300.0), "film.A": (1.3, 1.8), "film.B": (0.0, 0.02)}
    stack = Stack([Layer(Cauchy(A=1.55, B=0.01), 150.0, "film")], "si")
    from labbrdf import read

    fit = fit_film(FilmModel(stack, box), read(film_file), ci="wald")
    names = list(fit.result.var_names)
    cov = np.asarray(fit.result.covar)
    ia, ib = names.index("film.A"), names.index("film.B")
    table = pd.read_csv(nk)
    for entry in doc["nk_at"]:
        lam = entry["wavelength_nm"] / 1000.0
        var = cov[ia, ia] + cov[ib, ib] / lam**4 + 2 * cov[ia, ib] / lam**2
        got = entry["media"]["film"]
        # central differences of a function linear in A and B: exact to rounding
        assert got["n_stderr"] == pytest.approx(np.sqrt(var), rel=1e-4)
        assert got["k_stderr"] == 0.0 and entry["media"]["substrate"]["n_stderr"] == 0.0
        assert f"  film           {got['n']:.5f} +- {got['n_stderr']:.2g}" in out
    # the CSV carries the same standard errors on the fitted wavelengths
    lam = table["wavelength_nm"].to_numpy() / 1000.0
    var = cov[ia, ia] + cov[ib, ib] / lam**4 + 2 * cov[ia, ib] / lam**2
    np.testing.assert_allclose(table["film_n_stderr"], np.sqrt(var), rtol=1e-4)


@pytest.mark.parametrize(
    ("at", "match"),
    [("abc", "expected wavelengths [nm] > 0"), ("-5", "> 0"), ("5000", "outside the wavelengths")],
)
def test_bad_at_exits_2_with_a_message(film_file, capsys, at, match):
    argv = ["film", str(film_file), "--layer", LAYER, "--ci", "wald", "--at", at]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert match in err and "Traceback" not in err


@pytest.mark.shared
def test_w1_on_the_default_silicon_says_the_answer_is_not_meaningful(real_exports, capsys):
    # a Ta2O5 film on tantalum: on the default Si the fit misses by MSE ~ 1000
    f = real_exports / "woollam-wvase-ascii" / "w1_12082006.dat"
    assert main(["film", str(f), "--ci", "wald", "--at", "550"]) == 0
    out = capsys.readouterr().out
    assert "substrate: si (reference table, Green 2008)" in out
    assert "n, k at 550 nm" in out
    assert "VERDICT: MSE" in out and "the parameters above are not meaningful" in out


def test_the_report_shows_the_verdict_of_a_wrong_model(film_file):
    from types import SimpleNamespace

    from labbrdf import read
    from labbrdf.report.builder import Builder
    from labbrdf.report.context import Context
    from labbrdf.report.sections.film import _fit_shown

    box = {"film.thickness_nm": (0.0, 300.0), "film.A": (1.3, 1.8), "film.B": (0.0, 0.02)}
    stack = Stack([Layer(Cauchy(A=1.55, B=0.01), 150.0, "film")], "sio2")
    fit = fit_film(FilmModel(stack, box), read(film_file), ci="wald")
    assert fit.mse > MSE_WRONG_MODEL
    ctx = Context(Builder("t", progress=False))
    with ctx.b.section("film", "Film stacks"):
        _fit_shown(ctx, "0", "film.parquet", SimpleNamespace(text="stack"), fit)
    text = str(ctx.b.results)
    assert "parameters not meaningful" in text
    assert f"MSE {fit.mse:.4g} > 100: the model does not describe this sample" in text
