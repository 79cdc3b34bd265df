"""``labbrdf trace --base-albedo``: a Lambertian base reaches the run; conflicts exit 2."""

from __future__ import annotations

import json

import numpy as np
import pytest

from labbrdf.cli import main

BASE = [
    "trace",
    "--theta-i",
    "30",
    "--wavelength",
    "650",
    "--rays",
    "2000",
    "--scheduler",
    "serial",
    "--json",
]


def test_bare_base_albedo_reaches_the_run(capsys):
    assert main([*BASE, "--base-albedo", "0.6"]) == 0
    s = json.loads(capsys.readouterr().out)
    assert s["config"]["substrate"]["albedo"] == 0.6
    assert s["estimator"] == "evaluated"  # a bare base is its closed form
    assert s["albedo"] == pytest.approx(0.6, abs=1e-12)


def test_coated_base_runs_and_saves(tmp_path, capsys):
    out = tmp_path / "run.npz"
    args = [*BASE, "--base-albedo", "0.8", "--coating", "1.5", "--thickness", "500"]
    assert main([*args, "--coating-alpha", "0.2", "-o", str(out)]) == 0
    s = json.loads(capsys.readouterr().out)
    assert s["config"]["coating"]["alpha"] == 0.2
    assert 0.3 < s["albedo"] < 0.8
    from labbrdf.tracer import TraceResult

    res = TraceResult.load(out)
    assert res.config.substrate.kind == "lambertian"
    assert np.isfinite(res.mueller).all()


@pytest.mark.parametrize(
    ("extra", "named"),
    [
        (["--substrate", "1.55+7.71j"], "--substrate"),
        (["--alpha", "0.2"], "--alpha"),
        (["--substrate", "1.55+7.71j", "--alpha", "0.2"], "--substrate, --alpha"),
    ],
)
def test_base_albedo_with_the_metal_options_exits_2_naming_them(capsys, extra, named):
    assert main([*BASE, "--base-albedo", "0.5", *extra]) == 2
    err = capsys.readouterr().err
    assert "--base-albedo replaces the metal substrate" in err and named in err
    assert "Traceback" not in err


def test_base_albedo_with_nk_from_exits_2(tmp_path, capsys):
    f = tmp_path / "nk.csv"
    f.write_text("wavelength,psi,delta\n650,30,100\n", encoding="utf-8")
    assert main([*BASE, "--base-albedo", "0.5", "--nk-from", str(f)]) == 2
    assert "drop --nk-from" in capsys.readouterr().err


@pytest.mark.parametrize("bad", ["1.2", "-0.1", "nan"])
def test_albedo_outside_zero_one_exits_2(capsys, bad):
    assert main([*BASE, "--base-albedo", bad]) == 2
    err = capsys.readouterr().err
    assert "--base-albedo" in err and "substrate.albedo must be a finite number in [0, 1]" in err


def test_coated_base_needs_the_coating_roughness(capsys):
    args = [*BASE, "--base-albedo", "0.5", "--coating", "1.5", "--thickness", "500"]
    assert main(args) == 2
    assert "needs its roughness: --coating-alpha" in capsys.readouterr().err


def test_coherent_base_exits_2(capsys):
    args = [*BASE, "--base-albedo", "0.5", "--coating", "1.5", "--thickness", "500"]
    assert main([*args, "--coating-alpha", "0.2", "--coherent"]) == 2
    err = capsys.readouterr().err
    assert "coherent must be False with a Lambertian base" in err
    assert "Traceback" not in err
