"""Several samples in one film fit: recovery on files written by tmm, TOML and CLI forms."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

from labbrdf.cli import main
from labbrdf.dataset import Measurement, make_frame, write_csv
from labbrdf.films import FilmError, FilmModel, Layer, Stack, load_samples, named_inputs
from labbrdf.fitting.film_multi import fit_film_samples, per_sample_name
from labbrdf.nk.dispersion import Cauchy, Constant

tmm = pytest.importorskip("tmm")

WL = np.linspace(350.0, 900.0, 28)
THETA = (65.0, 75.0)
A, B = 1.46, 0.004  # shared Cauchy film
N_SUB = 3.9 + 0.02j  # a constant substrate, so that tmm needs no table of ours
THICK = {"w1": 80.0, "w2": 125.0, "w3": 170.0}  # per sample [nm]
SIG_PSI, SIG_DELTA = 0.02, 0.05  # [deg]


def _tmm_psi_delta(d_nm: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """psi, Delta [deg] of the film on the substrate from tmm (an independent code).

    tmm's ``ellips`` returns Delta = arg(-r_p/r_s); the Nebraska convention (WVASE,
    labbrdf) is arg(r_s conj(r_p)) = 180 deg - that, mod 360.
    """
    w, t, psi, delta = [], [], [], []
    for th in THETA:
        for lam in WL:
            n = A + B / (lam / 1000.0) ** 2
            e = tmm.ellips([1.0, n, N_SUB], [np.inf, d_nm, np.inf], np.radians(th), lam)
            w.append(lam)
            t.append(th)
            psi.append(np.degrees(e["psi"]))
            delta.append(np.mod(180.0 - np.degrees(e["Delta"]), 360.0))
    return np.array(w), np.array(t), np.array(psi), np.array(delta)


def _sample(name: str, d_nm: float, seed: int) -> Measurement:
    rng = np.random.default_rng(seed)
    w, t, psi, delta = _tmm_psi_delta(d_nm)
    frames = [
        make_frame(
            sample=name,
            instrument="tmm",
            source=f"{name}.csv",
            quantity=q,
            value=v + rng.normal(0.0, s, v.size),
            unit="deg",
            wavelength_nm=w,
            sigma=s,
            theta_i_deg=t,
            theta_r_deg=t,
            phi_r_deg=180.0,
        )  # fmt: skip
        for q, v, s in (("psi", psi, SIG_PSI), ("delta", delta, SIG_DELTA))
    ]
    return Measurement(pd.concat(frames, ignore_index=True), {})


@pytest.fixture(scope="module")
def samples():
    return {s: _sample(s, d, seed) for seed, (s, d) in enumerate(THICK.items())}


def _model() -> FilmModel:
    start = Stack([Layer(Cauchy(A=1.5, B=0.006), 100.0, "film")], Constant(n=3.9, k=0.02))
    box = {"film.thickness_nm": (20.0, 250.0), "film.A": (1.3, 1.7), "film.B": (0.0, 0.02)}
    return FilmModel(start, box)


@pytest.fixture(scope="module")
def multi(samples):
    return fit_film_samples(_model(), samples, per_sample=["film.thickness"], seed=1)


def test_shared_index_and_per_sample_thickness_recovered_within_their_intervals(multi):
    res = multi.result
    assert res.success
    assert 0.7 < res.redchi < 1.3  # honest sigmas: the model and the right order found
    truth = {"film.A": A, "film.B": B}
    truth |= {per_sample_name("film.thickness_nm", s): d for s, d in THICK.items()}
    assert sorted(res.var_names) == sorted(truth)
    for k, v in truth.items():
        lo, hi = res.params[k].ci95
        assert lo <= v <= hi, f"{k}: {v} outside [{lo}, {hi}]"
    for st in multi.sample_stats().values():  # each sample fitted to within its sigmas
        assert 0.5 < st["chi2_per_point"] < 1.5
    for s, d in THICK.items():
        assert multi.stacks[s].layers[0].thickness_nm == pytest.approx(d, abs=1.0)
        assert multi.stacks[s].layers[0].material.A == res.params["film.A"].value


def test_summary_names_each_sample_and_report_shows_them(multi):
    s = multi.summary()
    json.dumps(s, allow_nan=False)
    assert list(s["samples"]) == list(THICK)
    assert set(s["shared"]) == {"film.A", "film.B"}
    p = s["samples"]["w2"]["parameters"]["film.thickness_nm"]
    assert p["ci95"][0] <= THICK["w2"] <= p["ci95"][1]
    assert "film.thickness_nm[w3]" in s["correlations"]
    text = str(multi)
    assert "sample w2 (w2.csv)" in text and "film.A = " in text
    assert s["verdict"] is None and "VERDICT" not in text


def test_a_wrong_model_ends_with_the_verdict(samples):
    """Glass instead of the substrate measured: MSE far above 20, the report says so."""
    fm = _model()
    wrong = FilmModel(Stack(fm.stack.layers, Constant(n=1.5, k=0.0)), fm.free)
    f = fit_film_samples(wrong, samples, per_sample=["film.thickness_nm"], maxeval=(300, 300))
    assert f.mse > 20
    assert "VERDICT: MSE" in str(f) and f.summary()["verdict"] == f.verdict


def test_model_file_samples_table_and_cli(tmp_path, samples, capsys):
    for s, m in samples.items():
        write_csv(m, tmp_path / f"{s}.csv")
    model = tmp_path / "multi.toml"
    model.write_text(
        '[substrate]\nmaterial = "constant"\nn = 3.9\nk = 0.02\n\n'
        '[[layer]]\nname = "film"\nmaterial = "cauchy"\nthickness_nm = [20, 250]\n'
        "A = [1.3, 1.7]\nB = [0, 0.02]\n\n"
        '[samples]\nper_sample = ["film.thickness_nm"]\n\n'
        '[samples.files]\nw1 = "w1.csv"\nw2 = ["w2.csv"]\nw3 = "w3.csv"\n'
    )
    spec = load_samples(model)
    assert spec.files["w2"] == (tmp_path / "w2.csv",)
    assert tmp_path / "w3.csv" in named_inputs(model, "model")  # never an output
    py = fit_film_samples(model, seed=1)
    assert py.result.params["film.A"].ci95[0] <= A <= py.result.params["film.A"].ci95[1]
    assert main(["film", "--model", str(model), "--json", "--seed", "1", "--ci", "wald"]) == 0
    out = json.loads(capsys.readouterr().out)
    got = out["samples"]["w3"]["parameters"]["film.thickness_nm"]["value"]
    assert got == pytest.approx(py.stacks["w3"].layers[0].thickness_nm, rel=1e-6)
    files = [str(tmp_path / f"{s}.csv") for s in THICK]
    args = ["film", *files, "--model", str(model)]
    assert main(args) == 2  # files in [samples] and on the command line
    assert "give no FILE as well" in capsys.readouterr().err
    plain = tmp_path / "plain.toml"
    plain.write_text(model.read_text().split("[samples]")[0])
    args = ["film", *files, "--model", str(plain), "--per-sample", "film.thickness_nm"]
    assert main([*args, "--ci", "wald", "--seed", "1"]) == 0
    assert "sample w1 (" in capsys.readouterr().out


def test_errors_name_what_is_wrong(tmp_path, samples, capsys):
    with pytest.raises(FilmError, match="'film.C' is not a free parameter"):
        fit_film_samples(_model(), samples, per_sample=["film.C"])
    with pytest.raises(FilmError, match="at least two"):
        fit_film_samples(_model(), {"w1": samples["w1"]}, per_sample=["film.thickness_nm"])
    bad = tmp_path / "bad.toml"
    bad.write_text('[substrate]\nmaterial = "si"\n\n[samples]\nper_sample = []\nfile = "a.csv"\n')
    with pytest.raises(FilmError, match=r"bad.toml, line 6: unknown key 'file'"):
        load_samples(bad)
    bad.write_text('[substrate]\nmaterial = "si"\n\n[samples.files]\nw1 = 3\n')
    with pytest.raises(FilmError, match=r"bad.toml, line 5: sample 'w1': expected a file"):
        load_samples(bad)
    write_csv(samples["w1"], tmp_path / "w1.csv")
    one = ["film", str(tmp_path / "w1.csv"), "--per-sample", "film.thickness_nm"]
    assert main(one) == 2
    err = capsys.readouterr().err
    assert "at least two samples" in err and "Traceback" not in err
    assert main(["film", "--model", str(bad)]) == 2
    assert "bad.toml, line 5" in capsys.readouterr().err
    assert main(["film"]) == 2
    assert "give the FILE(s)" in capsys.readouterr().err
