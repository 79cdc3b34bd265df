"""``labbrdf trace --medium``: the scattering coating reaches the run; bad values exit 2."""

from __future__ import annotations

import json

import pytest

from labbrdf.cli import main
from labbrdf.tracer import Coating, Medium, Substrate, TraceConfig, trace

BASE = ["trace", "--theta-i", "30", "--wavelength", "650", "--rays", "2000"]
BASE += ["--scheduler", "serial", "--json", "--single-scattering", "--base-albedo", "0.8"]
COATED = ["--coating", "1.5", "--thickness", "500", "--coating-alpha", "0.2"]


def test_the_medium_reaches_the_run_as_in_python(capsys):
    assert main([*BASE, *COATED, "--medium", "0.8,0.9,0.5"]) == 0
    s = json.loads(capsys.readouterr().out)
    assert s["config"]["coating"]["medium"] == {"tau": 0.8, "ssa": 0.9, "g": 0.5}
    coat = Coating(n=1.5, thickness_nm=500.0, alpha=0.2, medium=Medium(0.8, 0.9, 0.5))
    cfg = TraceConfig(
        wavelength_nm=650.0,
        theta_i_deg=30.0,
        substrate=Substrate.lambertian(0.8),
        coating=coat,
        rays=2000,
        seed=1,
        scattering="single",
    )
    # the same walk with the same seed: the same number, to round-off
    assert s["albedo"] == pytest.approx(trace(cfg).albedo(), rel=1e-12)


@pytest.mark.parametrize(
    ("extra", "words"),
    [
        (["--medium", "0.8,0.9"], "expected TAU,SSA,G"),
        (["--medium", "0.8,0.9,nan"], "expected TAU,SSA,G"),
        (["--medium", "0.8,0.9,0.5"], "--medium needs a coating: --coating and --thickness"),
        ([*COATED, "--medium", "0.8,2,0.5"], "--medium coating.medium.ssa must be"),
    ],
)
def test_bad_medium_exits_2_with_the_reason(capsys, extra, words):
    try:
        code = main([*BASE, *extra])
    except SystemExit as exc:  # argparse's own refusal of the option's text
        code = exc.code
    assert code == 2
    err = capsys.readouterr().err
    assert words in err
    assert "Traceback" not in err
