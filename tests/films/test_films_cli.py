"""The new layer kinds from the command line: a model file, and --layer with a mixture."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd

from labbrdf.cli import main
from labbrdf.dataset import Measurement, write
from labbrdf.films import Layer, Stack
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
