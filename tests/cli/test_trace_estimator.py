"""``labbrdf trace --estimator``: the choice reaches the run, a wrong one exits 2."""

from __future__ import annotations

import json

import pytest

from labbrdf.cli import main


@pytest.fixture
def base(trace_argv: list[str]) -> list[str]:
    return [*trace_argv, "--json"]


def test_single_scattering_defaults_to_the_evaluated_estimator(capsys, base):
    assert main([*base, "--single-scattering"]) == 0
    s = json.loads(capsys.readouterr().out)
    assert s["estimator"] == "evaluated"
    assert s["config"]["estimator"] == "auto"


def test_counting_can_be_asked_for(capsys, base):
    assert main([*base, "--single-scattering", "--estimator", "counting"]) == 0
    assert json.loads(capsys.readouterr().out)["estimator"] == "counting"


def test_evaluated_without_single_scattering_exits_2_naming_the_option(capsys, base):
    assert main([*base, "--estimator", "evaluated"]) == 2
    err = capsys.readouterr().err
    assert "estimator" in err and "single" in err
    assert "Traceback" not in err


def test_scalar_flag_reaches_the_run(capsys, base):
    assert main([*base, "--single-scattering", "--scalar"]) == 0
    assert json.loads(capsys.readouterr().out)["config"]["scalar"] is True
