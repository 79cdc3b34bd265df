"""``labbrdf fit --fix/--param NAME=V`` outside the model's bounds: exit 2 before any work.

Every registry model (each option set that changes its parameters), every parameter just
below and just above its bounds, NaN and infinities: one message naming the option, the
parameter and the allowed range; the files are not even read.
"""

from __future__ import annotations

import math

import pytest

import labbrdf.adapters
from labbrdf import models
from labbrdf.cli import main

CONFIGS = [
    ("smooth3", {}),
    ("five_param", {}),
    ("five_param", {"shadowing": "mb"}),
    ("microfacet", {"n": 1.55, "k": 7.71}),
    ("microfacet", {"n": 1.55, "k": 7.71, "diffuse": True}),
    ("layered", {"n": 1.55, "k": 7.71}),
    ("layered", {"n": 1.55, "k": 7.71, "coherent": True}),
    ("layered", {"base": "diffuse"}),
    ("layered", {"n": 1.55, "k": 7.71, "floor": True}),
]


def _cases() -> list[tuple[str, dict, str, str, str]]:
    """(model, options, option, NAME=VALUE, expected words) for every parameter."""
    out = []
    for name, opts in CONFIGS:
        for pname, p in models.get(name, **opts).params.items():
            allowed = f"{p.min:g} <= {pname} <= {p.max:g}"
            width = p.max - p.min if math.isfinite(p.max - p.min) else 1.0
            outside = [v for v in (p.min - 1e-3 * width, p.max + 1e-3 * width) if math.isfinite(v)]
            for option in ("--fix", "--param"):
                out += [(name, opts, option, f"{pname}={v!r}", allowed) for v in outside]
            for text in ("nan", "inf", "-inf"):
                out.append((name, opts, "--fix", f"{pname}={text}", "finite"))
            out.append((name, opts, "--param", f"{pname}=nan", "finite"))
    return out


CASES = _cases()


def _options(opts: dict) -> list[str]:
    words = []
    for k, v in opts.items():
        words += ["--param", f"{k}={str(v).lower()}"]
    return words


@pytest.fixture
def data_file(tmp_path, monkeypatch):
    """An input that exists; reading it fails the test (the refusal comes before)."""
    path = tmp_path / "scan.csv"
    path.write_text("not read\n")

    def no_read(*a, **k):
        raise AssertionError("the data were read before the option was refused")

    monkeypatch.setattr(labbrdf.adapters, "read_many", no_read)
    return path


@pytest.mark.parametrize(
    ("name", "opts", "option", "item", "words"),
    CASES,
    ids=[f"{m}{sorted(o)}{opt}{item}" for m, o, opt, item, _ in CASES],
)
def test_a_value_outside_the_bounds_exits_2_naming_the_option(
    data_file, capsys, name, opts, option, item, words
):
    argv = ["fit", str(data_file), "--model", name, *_options(opts), option, item]
    assert main(argv) == 2
    err = capsys.readouterr().err
    pname = item.partition("=")[0]
    assert err.startswith(f"labbrdf fit: {option} ") and pname in err, err
    assert words in err and "Traceback" not in err
    assert err.count("\n") == 1


def test_layered_alpha_top_minus_one_is_an_option_error(data_file, capsys):
    """The reported case: once a SystemError traceback from inside the tracer."""
    argv = ["fit", str(data_file), "--model", "layered", "--param", "n=1.55"]
    argv += ["--param", "k=7.71", "--fix", "alpha_top=-1"]
    assert main(argv) == 2
    assert capsys.readouterr().err == (
        "labbrdf fit: --fix alpha_top=-1: model 'layered': alpha_top=-1 is outside its "
        "bounds: expected 0.02 <= alpha_top <= 1\n"
    )


def test_unknown_free_parameter_exits_2_before_reading(data_file, capsys):
    argv = ["fit", str(data_file), "--model", "smooth3", "--free", "alpha"]
    assert main(argv) == 2
    assert "--free alpha: model 'smooth3' has no parameter 'alpha'" in capsys.readouterr().err


def test_nk_from_values_are_checked_against_the_models_bounds(data_file, tmp_path, capsys):
    """With --nk-from the index comes later, but the bounds are known at once."""
    nk = tmp_path / "nk.csv"
    nk.write_text("not read either\n")
    argv = ["fit", str(data_file), "--model", "microfacet", "--nk-from", str(nk)]
    argv += ["--wavelength", "633", "--fix", "alpha=2"]
    assert main(argv) == 2
    assert "--fix alpha=2: model 'microfacet': alpha=2 is outside" in capsys.readouterr().err


@pytest.mark.parametrize("count", ["1001", "1000000"])
def test_replicates_beyond_the_cap_exit_2_before_reading(data_file, capsys, count):
    argv = ["fit", str(data_file), "--model", "layered", "--param", "n=1.55"]
    argv += ["--param", "k=7.71", "--replicates", count]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert f"--replicates must be an integer in [1, 1000]; got {count}" in err


@pytest.mark.parametrize("command", ["fit", "film"])
@pytest.mark.parametrize("seed", ["-5", str(2**32), "99999999999999999999999", "1.5"])
def test_a_seed_outside_the_optimisers_range_exits_2_naming_the_option(
    data_file, capsys, command, seed
):
    """nlopt's srand takes an unsigned long: such seeds once ended in an OverflowError."""
    argv = [command, str(data_file), "--seed", seed]
    argv += ["--model", "smooth3"] if command == "fit" else []
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert "--seed" in err and "expected an integer in [0, 4294967295]" in err


@pytest.mark.parametrize("floor", ["nan", "-1", "0", "1", "inf", "2"])
def test_a_relative_floor_outside_0_1_exits_2_before_reading(data_file, capsys, floor):
    """Once every group failed one by one ("not fitted"), exit 3, after reading the data."""
    with pytest.raises(SystemExit) as exc:
        main(["fit", str(data_file), "--model", "smooth3", "--relative-floor", floor])
    assert exc.value.code == 2
    assert "--relative-floor" in capsys.readouterr().err
