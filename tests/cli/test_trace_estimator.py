"""``labbrdf trace --estimator``: the choice reaches the run, a wrong one exits 2."""

from __future__ import annotations

import json

from labbrdf.cli import main

BASE = [
    "trace",
    "--substrate",
    "1.55+7.71j",
    "--alpha",
    "0.2",
    "--theta-i",
    "45",
    "--wavelength",
    "650",
    "--rays",
    "2000",
    "--scheduler",
    "serial",
    "--json",
]


def test_single_scattering_defaults_to_the_evaluated_estimator(capsys):
    assert main([*BASE, "--single-scattering"]) == 0
    s = json.loads(capsys.readouterr().out)
    assert s["estimator"] == "evaluated"
    assert s["config"]["estimator"] == "auto"


def test_counting_can_be_asked_for(capsys):
    assert main([*BASE, "--single-scattering", "--estimator", "counting"]) == 0
    assert json.loads(capsys.readouterr().out)["estimator"] == "counting"


def test_evaluated_without_single_scattering_exits_2_naming_the_option(capsys):
    assert main([*BASE, "--estimator", "evaluated"]) == 2
    err = capsys.readouterr().err
    assert "estimator" in err and "single" in err
    assert "Traceback" not in err


def test_scalar_flag_reaches_the_run(capsys):
    assert main([*BASE, "--single-scattering", "--scalar"]) == 0
    assert json.loads(capsys.readouterr().out)["config"]["scalar"] is True
