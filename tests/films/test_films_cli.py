"""The new layer kinds from the command line: a model file, --layer with a mixture, and the
forms of thick, graded and spread layers (the same models as the TOML keys)."""

from __future__ import annotations

import argparse
import json

import numpy as np
import pandas as pd
import pytest

from labbrdf.cli import main
from labbrdf.cli.film import _film_model
from labbrdf.dataset import Measurement, write
from labbrdf.films import Layer, Stack, load_model
from labbrdf.nk.dispersion import Cauchy

GLASS = """\
wavelength_nm = [400, 1000]

[substrate]
material = "sio2"
thickness_nm = 1e6

[[layer]]
name = "film"
material = "cauchy"
A = [1.6, 2.4]
B = 0.012
thickness_nm = [50, 250]
"""


def _rt_file(path):
    truth = Stack([Layer(Cauchy(A=2.05, B=0.012), 140.0, "film")], "sio2", 1.0, 1e6)
    wl = np.linspace(400.0, 1000.0, 41)
    r, _ = truth.reflectance(wl, 0.0)
    t, _ = truth.transmittance(wl, 0.0)
    rng = np.random.default_rng(2)
    df = pd.concat(
        [
            pd.DataFrame(
                {
                    "sample": "glass",
                    "instrument": "sim",
                    "source": "rt.parquet",
                    "quantity": q,
                    "value": v + rng.normal(0, 0.002, wl.size),
                    "sigma": 0.002,
                    "unit": "1",
                    "wavelength_nm": wl,
                    "theta_i_deg": 0.0,
                    "theta_r_deg": 0.0,
                    "phi_r_deg": 0.0,
                }
            )
            for q, v in (("reflectance", r), ("transmittance", t))
        ],
        ignore_index=True,
    )
    df["quantity"] = df["quantity"].astype("category")
    write(Measurement(df, {}), path)
    return path


def test_film_on_glass_from_a_model_file_with_its_backside(tmp_path, capsys):
    data = _rt_file(tmp_path / "rt.parquet")
    (tmp_path / "glass.toml").write_text(GLASS)
    model = str(tmp_path / "glass.toml")
    code = main(["film", str(data), "--model", model, "--json", "--ci", "wald"])
    doc = json.loads(capsys.readouterr().out)
    assert code == 0
    d = doc["layers"][0]["parameters"]["thickness_nm"]
    assert d["ci95"][0] <= 140.0 <= d["ci95"][1]
    assert doc["stack"]["substrate_thickness_nm"] == 1e6


def test_a_mixture_layer_with_a_bad_reference_exits_2(tmp_path, capsys):
    data = _rt_file(tmp_path / "rt.parquet")
    code = main(["film", str(data), "--layer", "r:ema(@nope,void):1", "--substrate", "sio2"])
    assert code == 2
    assert "'@nope' names no other layer" in capsys.readouterr().err


OPTIONS = ("--substrate-thickness", "--thickness-spread", "--bandwidth", "--angle-spread")


def _cli(layers, substrate="si", **opts) -> argparse.Namespace:
    ns = {o[2:].replace("-", "_"): opts.get(o[2:].replace("-", "_")) for o in OPTIONS}
    return argparse.Namespace(model=None, layer=layers, substrate=substrate, **ns)


@pytest.mark.parametrize(
    ("layers", "opts", "toml"),
    [
        (
            ["sheet:sio2:2e5:incoherent", "f:cauchy:50..250:A=1.6..2.4:B=0.012"],
            {"substrate_thickness": "1e6"},
            '[substrate]\nmaterial = "si"\nthickness_nm = 1e6\n\n'
            '[[layer]]\nname = "sheet"\nmaterial = "sio2"\nthickness_nm = 2e5\n'
            "coherent = false\n\n"
            '[[layer]]\nname = "f"\nmaterial = "cauchy"\nA = [1.6, 2.4]\nB = 0.012\n'
            "thickness_nm = [50, 250]\n",
        ),
        (
            ["f:cauchy:100..300:graded=A:A_top=1.9..2.3:A_bottom=2.1:sublayers=5"],
            {"thickness_spread": "0..0.05", "bandwidth": "2", "angle_spread": "0..1"},
            "thickness_spread = [0, 0.05]\nbandwidth_nm = 2\nangle_spread_deg = [0, 1]\n"
            '[substrate]\nmaterial = "si"\n\n[[layer]]\nname = "f"\nmaterial = "cauchy"\n'
            'graded = "A"\nsublayers = 5\nA_top = [1.9, 2.3]\nA_bottom = 2.1\n'
            "thickness_nm = [100, 300]\n",
        ),
        (
            ["i:ema(@f,void):0..5:graded=fraction", "f:cauchy:150..200"],
            {"substrate_thickness": "5e5..2e6"},
            '[substrate]\nmaterial = "si"\nthickness_nm = [5e5, 2e6]\n\n'
            '[[layer]]\nname = "i"\nmaterial = "ema(@f, void)"\ngraded = "fraction"\n'
            'thickness_nm = [0, 5]\n\n[[layer]]\nname = "f"\nmaterial = "cauchy"\n'
            "thickness_nm = [150, 200]\n",
        ),
    ],
)
def test_each_form_is_the_model_of_its_toml_keys(tmp_path, layers, opts, toml):
    p = tmp_path / "m.toml"
    p.write_text(toml)
    ref = load_model(p)
    got = _film_model(_cli(layers, **opts))
    assert got.stack.to_dict() == ref.stack.to_dict()
    assert got.free == ref.free


def test_a_film_on_glass_from_the_command_line(tmp_path, capsys):
    """The backside without a model file: the same answer as tests/films/test_films_cli."""
    data = _rt_file(tmp_path / "rt.parquet")
    argv = ["film", str(data), "--substrate", "sio2", "--substrate-thickness", "1e6",
            "--layer", "film:cauchy:50..250:A=1.6..2.4:B=0.012", "--json", "--ci", "wald",
            "--wavelength-range", "400:1000"]  # fmt: skip
    code = main(argv)
    doc = json.loads(capsys.readouterr().out)
    assert code == 0
    d = doc["layers"][0]["parameters"]["thickness_nm"]
    assert d["ci95"][0] <= 140.0 <= d["ci95"][1]
    assert doc["stack"]["substrate_thickness_nm"] == 1e6
    assert "depolarization" not in doc["channels"]  # R, T: no such rows


@pytest.mark.parametrize(
    ("extra", "words"),
    [
        (["--layer", "f:cauchy:100:graded=Q"], "--layer f: graded=Q: expected one of the param"),
        (["--layer", "f:cauchy:100:sublayers=3"], "sublayers=N needs graded=PARAM"),
        (["--layer", "f:cauchy:100:graded=A:sublayers=x"], "expected sublayers=N, an integer"),
        (["--layer", "f:cauchy:100:graded=A:sublayers=900"], "sublayers"),
        (["--layer", "f:sio2:100:graded=n"], "none (a table)"),
        (["--layer", "g:sio2:1e6:incoherent=1"], "expected 'incoherent' alone"),
        (["--layer", "f:cauchy:100:coherent"], "or a keyword (incoherent, graded=PARAM"),
        (["--layer", "f:cauchy:100", "--bandwidth", "30"], "--bandwidth 30: expected a value"),
        (["--layer", "f:cauchy:100", "--angle-spread", "x"], "--angle-spread: 'x' is not a"),
        (["--layer", "f:cauchy:100", "--thickness-spread", "0.1..0.5"], "--thickness-spread"),
        (["--layer", "f:cauchy:100", "--substrate-thickness", "0"], "--substrate-thickness 0"),
        (["--model", "MODEL", "--bandwidth", "1"], "--bandwidth with --model: give it in"),
        (["--layer", "f:cauchy:100", "--dpol", "on"], "no depolarization rows to fit"),
    ],
)
def test_bad_forms_exit_2_with_one_line(tmp_path, capsys, extra, words):
    data = _rt_file(tmp_path / "rt.parquet")
    (tmp_path / "m.toml").write_text('[substrate]\nmaterial = "si"\n')
    extra = [str(tmp_path / "m.toml") if a == "MODEL" else a for a in extra]
    code = main(["film", str(data), "--sigma", "reflectance=0.01", *extra])
    err = capsys.readouterr().err
    assert code == 2
    assert words in err and len(err.strip().splitlines()) == 1, err
