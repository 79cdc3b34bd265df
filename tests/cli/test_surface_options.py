"""``labbrdf surface``: --form, the form warning, the Rayleigh verdict, no progress in logs."""

from __future__ import annotations

import json

import numpy as np
import pytest

from labbrdf.cli import main

R, PX, N = 10e-3, 1e-6, 96


def write_map(path, z):
    np.savetxt(path, z * 1e9, fmt="%.6f")
    return [str(path), "--pixel-size", f"{PX * 1e6}um", "--unit", "nm"]


@pytest.fixture
def cylinder(tmp_path):
    x = (np.arange(N) - N / 2) * PX
    z = np.sqrt(R**2 - x[:, None] ** 2) + np.zeros((1, N))
    z = z + 1e-9 * np.random.default_rng(0).standard_normal((N, N))
    return write_map(tmp_path / "cyl.txt", z)


def run_json(argv, capsys):
    assert main(["surface", *argv, "--json", "--blocks", "0"]) == 0
    return json.loads(capsys.readouterr().out)


def test_a_map_dominated_by_form_is_flagged_and_form_quadric_removes_it(cylinder, capsys):
    assert main(["surface", *cylinder, "--blocks", "0"]) == 0
    out = capsys.readouterr()
    assert "warning: form dominates" in out.out and "cylinder of radius 10 mm" in out.out
    assert out.err == ""  # no progress lines when stderr is not a terminal
    plane = run_json(cylinder, capsys)
    quadric = run_json([*cylinder, "--form", "quadric"], capsys)
    assert plane["form"]["dominated"] and plane["form"]["shape"] == "cylinder"
    assert quadric["form"] is None and quadric["levelling"].startswith("least-squares poly")
    assert quadric["sigma"] == pytest.approx(1e-9, rel=0.05)  # the noise alone
    assert run_json([*cylinder, "--degree", "2"], capsys)["sigma"] == quadric["sigma"]


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--form", "cone"], "--form 'cone': expected one of mean, plane, quadric"),
        (
            ["--form", "plane", "--degree", "1"],
            "--form and --degree both set the levelling: give one",
        ),
        (["--theta-i", "30"], "--theta-i needs --wavelength NM (the Rayleigh verdict)"),
    ],
)
def test_bad_levelling_and_verdict_options_exit_2(cylinder, capsys, extra, message):
    assert main(["surface", *cylinder, *extra]) == 2
    err = capsys.readouterr().err
    assert err == f"labbrdf surface: {message}\n"


def test_rayleigh_verdict_is_the_report_s_for_the_same_map(cylinder, capsys):
    from labbrdf import smoothness as sm

    d = run_json(
        [*cylinder, "--form", "quadric", "--wavelength", "633", "--theta-i", "60"], capsys
    )
    r = d["rayleigh"]
    assert r["wavelength_nm"] == 633 and r["theta_i"] == 60
    # the map (2 um .. 96 um) misses periods from 633 / (1 + sin 60) = 339 nm to 2 um
    assert r["coverage"] == "misses short periods"
    assert r["sigma_nm"] == pytest.approx(d["sigma"] * 1e9, rel=1e-12)
    assert r["g"] == pytest.approx(float(sm.rayleigh_parameter(r["sigma_nm"], 633, np.pi / 3)))
    assert r["thr_rayleigh"] == pytest.approx(633 / (8 * 0.5))
    assert r["rayleigh"] == "smooth"
    assert main(["surface", *cylinder, "--wavelength", "1", "--blocks", "0"]) == 0
    out = capsys.readouterr().out
    assert "Rayleigh at 1 nm, theta_i 0 deg" in out and "rough by Rayleigh" in out
