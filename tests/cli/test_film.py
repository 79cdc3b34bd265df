"""`labbrdf film`: model file or --layer, table and JSON output, n,k CSV, errors (exit 2)."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

from labbrdf.cli import main
from labbrdf.dataset import Measurement, write
from labbrdf.films import Layer, Stack
from labbrdf.nk.dispersion import Cauchy

TRUE = Stack([Layer(Cauchy(A=1.46, B=0.004), 105.0, "film")], "si")


@pytest.fixture(scope="module")
def film_file(tmp_path_factory):
    wl = np.linspace(300, 1000, 40)
    W, T = np.meshgrid(wl, [60.0, 70.0], indexing="ij")
    w, t = W.ravel(), T.ravel()
    psi, delta = TRUE.psi_delta(w, t)
    rng = np.random.default_rng(0)
    parts = []
    for q, v, s in (("psi", psi, 0.02), ("delta", delta, 0.05)):
        parts.append(
            pd.DataFrame(
                {
                    "sample": "wafer",
                    "instrument": "sim",
                    "source": "film.parquet",
                    "quantity": q,
                    "value": np.mod(v + rng.normal(0, s, v.size), 360.0) if q == "delta" else v,
                    "sigma": s,
                    "unit": "deg",
                    "wavelength_nm": w,
                    "theta_i_deg": t,
                    "theta_r_deg": t,
                    "phi_r_deg": 180.0,
                }
            )
        )
    df = pd.concat(parts, ignore_index=True)
    df["quantity"] = df["quantity"].astype("category")
    p = tmp_path_factory.mktemp("film") / "film.parquet"
    write(Measurement(df, {}), p)
    return p


def test_film_with_layers_prints_the_table(film_file, capsys):
    code = main(
        ["film", str(film_file), "--layer", "film:cauchy:0..300:A=1.3..1.8:B=0..0.02",
         "--ci", "wald"]
    )  # fmt: skip
    out = capsys.readouterr().out
    assert code == 0
    assert "layer film (cauchy)" in out and "thickness_nm" in out
    assert "MSE =" in out and "chi2/nu =" in out
    line = next(x for x in out.splitlines() if "thickness_nm" in x)
    assert float(line.split()[1]) == pytest.approx(105.0, abs=0.5)


def test_film_with_a_model_file_writes_json_nk_csv_and_fit_json(film_file, tmp_path, capsys):
    model = tmp_path / "m.toml"
    model.write_text(
        '[substrate]\nmaterial = "si"\n\n[[layer]]\nname = "film"\nmaterial = "cauchy"\n'
        "thickness_nm = [50, 200]\nA = [1.3, 1.8]\nB = 0.004\n"
    )
    nk, fj = tmp_path / "nk.csv", tmp_path / "fit.json"
    argv = ["film", str(film_file), "--model", str(model), "--json", "-o", str(nk)]
    code = main([*argv, "--fit-json", str(fj), "--ci", "wald"])
    assert code == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["layers"][0]["parameters"]["thickness_nm"]["ci95"][0] < 105.0
    table = pd.read_csv(nk)
    assert list(table.columns) == [
        "wavelength_nm",
        "film_n",
        "film_n_stderr",
        "film_k",
        "film_k_stderr",
        "substrate_n",
        "substrate_n_stderr",
        "substrate_k",
        "substrate_k_stderr",
    ]
    assert len(table) == 40
    assert Stack.from_fit_json(fj).layers[0].thickness_nm == pytest.approx(105.0, abs=0.5)
    # outputs are never overwritten silently
    assert main([*argv, "--fit-json", str(fj)]) == 2
    assert "exists; pass --overwrite" in capsys.readouterr().err


@pytest.mark.parametrize(
    ("extra", "match"),
    [
        (["--layer", "film:cauchy"], "expected NAME:MATERIAL:THICKNESS"),
        (["--layer", "film:cauchy:10:Q=1"], "PARAM one of"),
        (["--layer", "film:cauchy:300..0"], "impossible bounds"),
        (["--layer", "film:unobtainium:10"], "unknown material"),
        (["--layer", "film:cauchy:1..20", "--wavelength-range", "900:100"], "MIN must not"),
        (["--layer", "film:cauchy:1..20", "--wavelength-range", "100:100"], "0 <= MIN < MAX"),
        (["--model", "absent.toml"], "cannot read the model file"),
    ],
)
def test_film_bad_input_exits_2_with_a_message(film_file, capsys, extra, match):
    assert main(["film", str(film_file), *extra]) == 2
    err = capsys.readouterr().err
    assert match in err and "Traceback" not in err


def test_film_model_file_error_names_file_and_line(film_file, tmp_path, capsys):
    model = tmp_path / "bad.toml"
    model.write_text(
        '[substrate]\nmaterial = "si"\n\n[[layer]]\nmaterial = "cauchy"\nthickness_nm = 5\nZ = 1\n'
    )
    assert main(["film", str(film_file), "--model", str(model)]) == 2
    err = capsys.readouterr().err
    assert "bad.toml, line 7: unknown parameter 'Z'" in err


def test_default_model_is_a_cauchy_layer_on_silicon(film_file, capsys):
    assert main(["film", str(film_file), "--json", "--ci", "wald"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["layers"][0]["material"]["model"] == "cauchy"
    assert doc["substrate"]["material"] == {"model": "tabulated", "reference": "si"}
    assert doc["layers"][0]["parameters"]["thickness_nm"]["value"] == pytest.approx(105, abs=1)


@pytest.mark.shared
def test_native_oxide_on_silicon_from_the_completeease_file(real_exports, capsys):
    f = real_exports / "woollam-completeease-ascii" / "complete_ease_example.dat"
    code = main(
        ["film", str(f), "--substrate", "si", "--layer", "oxide:sio2:0..20",
         "--wavelength-range", "250:1450", "--json"]
    )  # fmt: skip
    assert code == 0
    doc = json.loads(capsys.readouterr().out)
    d = doc["layers"][0]["parameters"]["thickness_nm"]
    # the file's sample is "2 nm SiO2 on Si"; Green's Si table and Malitson's SiO2
    assert 1.5 < d["value"] < 3.0
    assert d["ci95_scaled"][0] <= d["value"] <= d["ci95_scaled"][1]
    assert doc["mse"] < 20


def test_film_without_a_substrate_table_covering_the_data_exits_2(tmp_path, capsys):
    wl = np.array([200.0, 300.0, 400.0])
    df = pd.DataFrame(
        {"sample": "w", "instrument": "sim", "source": "x",
         "quantity": ["psi"] * 3 + ["delta"] * 3,
         "value": [20.0] * 3 + [100.0] * 3, "sigma": 0.01, "unit": "deg",
         "wavelength_nm": np.r_[wl, wl], "theta_i_deg": 70.0, "theta_r_deg": 70.0,
         "phi_r_deg": 180.0}
    )  # fmt: skip
    df["quantity"] = df["quantity"].astype("category")
    p = tmp_path / "uv.parquet"
    write(Measurement(df, {}), p)
    assert main(["film", str(p), "--layer", "ox:sio2:0..10"]) == 2
    err = capsys.readouterr().err
    assert "covers 250-1450 nm but the data span 200-400 nm" in err


def test_substrate_from_an_nk_file_and_a_bad_one(film_file, tmp_path, capsys):
    good = tmp_path / "si_copy.csv"
    lam = np.arange(250.0, 1451.0, 10.0)
    n_si = Stack([], "si").nk(lam)["substrate"]
    good.write_text("".join(f"{w},{n.real},{n.imag}\n" for w, n in zip(lam, n_si, strict=True)))
    argv = ["film", str(film_file), "--layer", "film:cauchy:50..200:A=1.3..1.8:B=0.004"]
    assert main([*argv, "--substrate", str(good), "--json", "--ci", "wald"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["layers"][0]["parameters"]["thickness_nm"]["value"] == pytest.approx(105, abs=0.5)
    bad = tmp_path / "bad.csv"
    bad.write_text("250,3.0,0.1\n300,oops,0.1\n")
    assert main([*argv, "--substrate", str(bad)]) == 2
    err = capsys.readouterr().err
    assert "bad.csv, line 2: expected numbers" in err and "Traceback" not in err


# ------------------------------------------------- files named inside the model are inputs


def _si_table(path):
    lam = np.arange(250.0, 1451.0, 10.0)
    n_si = Stack([], "si").nk(lam)["substrate"]
    path.write_text("".join(f"{w},{n.real},{n.imag}\n" for w, n in zip(lam, n_si, strict=True)))
    return path


def test_the_table_a_model_names_is_never_replaced_even_with_overwrite(
    film_file, tmp_path, capsys
):
    table = _si_table(tmp_path / "sub.csv")
    model = tmp_path / "m.toml"
    model.write_text(
        '[substrate]\nfile = "sub.csv"\n\n[[layer]]\nname = "film"\nmaterial = "cauchy"\n'
        "thickness_nm = [50, 200]\nA = [1.3, 1.8]\nB = 0.004\n"
    )
    before = (table.read_bytes(), table.stat().st_mtime_ns)
    for out in (["-o", str(table)], ["--fit-json", str(tmp_path / "sub.json")]):
        if out[0] == "--fit-json":  # the fit JSON named by the model file? a table of it
            (tmp_path / "sub.json").write_bytes(table.read_bytes())
            model.write_text(model.read_text().replace("sub.csv", "sub.json"))
        assert main(["film", str(film_file), "--model", str(model), *out, "--overwrite"]) == 2
        err = capsys.readouterr().err
        assert "is one of the input files" in err and "Traceback" not in err, err
    assert (table.read_bytes(), table.stat().st_mtime_ns) == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.toml", "sub.csv", "sub.json"]


def test_the_table_a_layer_names_is_never_replaced(film_file, tmp_path, capsys):
    table = _si_table(tmp_path / "nk.csv")
    before = table.read_bytes()
    argv = ["film", str(film_file), "--layer", f"f:{table}:50..200", "-o", str(table)]
    assert main([*argv, "--overwrite"]) == 2
    assert "is one of the input files" in capsys.readouterr().err
    assert table.read_bytes() == before


def test_a_device_or_fifo_named_in_a_model_exits_2_at_once(film_file, tmp_path, capsys):
    import os

    os.mkfifo(tmp_path / "pipe.csv")
    for name, kind in (("/dev/zero", "character device"), ("pipe.csv", "FIFO")):
        model = tmp_path / "m.toml"
        model.write_text(f'[substrate]\nfile = "{name}"\n')
        assert main(["film", str(film_file), "--model", str(model)]) == 2
        err = capsys.readouterr().err
        assert f"m.toml, line 2: {name if name.startswith('/') else tmp_path / name}" in err, err
        assert kind in err and "Traceback" not in err


def test_a_nan_thickness_names_the_model_file_and_line(film_file, tmp_path, capsys):
    model = tmp_path / "nan.toml"
    model.write_text(
        '[substrate]\nmaterial = "si"\n\n[[layer]]\nmaterial = "sio2"\nthickness_nm = nan\n'
    )
    assert main(["film", str(film_file), "--model", str(model)]) == 2
    err = capsys.readouterr().err
    assert f"{model}, line 6: thickness_nm: expected a finite number" in err, err


def _sample_file(folder, name: str, sample: str, angle: float):
    """Psi/Delta of :data:`TRUE` at one angle, stating the sample name ``sample``."""
    wl = np.linspace(300, 1000, 30)
    psi, delta = TRUE.psi_delta(wl, np.full(wl.size, angle))
    parts = [
        pd.DataFrame(
            {
                "sample": sample,
                "instrument": "sim",
                "source": name,
                "quantity": q,
                "value": v,
                "sigma": s,
                "unit": "deg",
                "wavelength_nm": wl,
                "theta_i_deg": angle,
                "theta_r_deg": angle,
                "phi_r_deg": 180.0,
            }
        )
        for q, v, s in (("psi", psi, 0.02), ("delta", np.mod(delta, 360.0), 0.05))
    ]
    df = pd.concat(parts, ignore_index=True)
    df["quantity"] = df["quantity"].astype("category")
    path = folder / name
    write(Measurement(df, {}), path)
    return path


@pytest.fixture
def two_samples(tmp_path):
    """Two files of the same stack that state different sample names."""
    return (
        _sample_file(tmp_path, "a.parquet", "wafer-A", 60.0),
        _sample_file(tmp_path, "b.parquet", "wafer-B", 70.0),
    )


LAYER = ["--layer", "film:cauchy:0..300:A=1.3..1.8:B=0.004", "--ci", "wald"]


def test_film_refuses_files_that_state_different_samples(two_samples, tmp_path, capsys):
    a, b = two_samples
    out = tmp_path / "nk.csv"
    assert main(["film", str(a), str(b), *LAYER, "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert f"{a} states 'wafer-A'" in err and f"{b} states 'wafer-B'" in err
    assert f"--same-sample {a},{b}" in err
    assert not out.exists()


def test_film_fits_files_said_to_be_one_sample_jointly(two_samples, capsys):
    a, b = two_samples
    assert main(["film", str(a), str(b), *LAYER, "--same-sample", f"{a},{b}", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["ndata"] == 4 * 30  # psi and Delta of both files
    assert doc["layers"][0]["parameters"]["thickness_nm"]["value"] == pytest.approx(105, abs=0.5)


def test_film_of_one_selected_sample_of_two_files_is_fitted(two_samples, capsys):
    a, b = two_samples
    assert main(["film", str(a), str(b), *LAYER, "--sample", "wafer-B", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["ndata"] == 2 * 30


def test_film_same_sample_must_name_the_inputs(two_samples, tmp_path, capsys):
    a, b = two_samples
    other = tmp_path / "c.parquet"
    assert main(["film", str(a), str(b), *LAYER, "--same-sample", f"{a},{other}"]) == 2
    err = capsys.readouterr().err
    assert f"{other} is not among the input files" in err and "Traceback" not in err


def test_film_prints_the_fits_own_report(film_file, capsys):
    """`labbrdf film` prints :meth:`FilmFit.fit_report` of the same fit, nothing else."""
    from labbrdf import read
    from labbrdf.films import FilmModel
    from labbrdf.fitting.film import fit_film

    argv = ["film", str(film_file), "--layer", "film:cauchy:0..300:A=1.3..1.8:B=0..0.02:C=0"]
    assert main([*argv, "--ci", "wald"]) == 0
    box = {"film.thickness_nm": (0.0, 300.0), "film.A": (1.3, 1.8), "film.B": (0.0, 0.02)}
    stack = Stack([Layer(Cauchy(A=1.55, B=0.01), 150.0, "film")], "si")
    fit = fit_film(FilmModel(stack, box), read(film_file), ci="wald")
    assert capsys.readouterr().out == fit.fit_report() + "\n"


# ------------------------------------------------------------------- intervals: Wald first

# B ends at its max; A, correlated with B (-0.77), then has a narrower profile interval
PINNED = ["--layer", "film:cauchy:0..300:A=1.3..1.8:B=0..0.002:C=0"]


def test_film_prints_the_wald_answer_first_on_a_terminal(film_file, capsys, monkeypatch):
    import sys

    monkeypatch.setattr(sys.stdout, "isatty", lambda: True)
    assert main(["film", str(film_file), *PINNED]) == 0  # the default: --ci auto
    out = capsys.readouterr().out
    first, sep, final = out.partition("computing the profile intervals of film.A, film.B ...")
    assert sep and "intervals: Wald; profile for" not in first
    assert "95 % profile [" not in first and "95 % profile [" in final
    assert "film.B (its Wald interval reaches a bound)" in final


@pytest.mark.parametrize("ci", [None, "auto", "wald", "profile"])
def test_film_says_which_interval_each_parameter_carries(film_file, capsys, ci):
    argv = ["film", str(film_file), *PINNED, "--json"] + (["--ci", ci] if ci else [])
    assert main(argv) == 0  # piped: no Wald answer before the JSON
    doc = json.loads(capsys.readouterr().out)
    got = {k: p["ci_method"] for k, p in doc["layers"][0]["parameters"].items() if p["vary"]}
    want = {"auto": {"thickness_nm": "wald", "A": "profile", "B": "profile"}}.get(
        ci or "auto", dict.fromkeys(got, ci)
    )
    assert doc["ci_method"] == (ci or "auto") and got == want


def test_film_refuses_an_unknown_ci(film_file, capsys):
    with pytest.raises(SystemExit) as exc:
        main(["film", str(film_file), "--ci", "fast"])
    assert exc.value.code == 2
    assert "invalid choice: 'fast'" in capsys.readouterr().err
