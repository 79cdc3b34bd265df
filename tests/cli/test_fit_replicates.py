"""``labbrdf fit --replicates R``: seed replicates of the layered model; refusals exit 2."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

from labbrdf import models
from labbrdf.cli import main
from labbrdf.writers.zemax import model_to_bsdf

AL = ["--param", "n=1.55", "--param", "k=7.71"]


@pytest.fixture(scope="module")
def microfacet_bsdf(tmp_path_factory):
    """A .bsdf of the closed-form GGX microfacet model of Al, alpha 0.25, at 30 deg."""
    path = tmp_path_factory.mktemp("replicates") / "al.bsdf"
    return model_to_bsdf(
        models.get("microfacet", n=1.55, k=7.71),
        {"alpha": 0.25},
        path,
        theta_i_deg=[30.0],
        radial_deg=[0, 5, 10, 15, 20, 30, 40, 50, 60],
        azimuth_deg=np.arange(0.0, 181.0, 20.0),
    )


def test_fit_layered_with_replicates_reports_the_seeds_and_their_spread(
    microfacet_bsdf, tmp_path, capsys
):
    """Two seeds: the JSON record and the CSV table carry both estimates and s_between.

    The reported value is their mean and its error at least s_between / sqrt(2).
    """
    out = tmp_path / "table.csv"
    argv = ["fit", str(microfacet_bsdf), "--model", "layered", *AL, "--replicates", "2"]
    argv += ["--param", "rays=2000", "--param", "grid=3x6", "--fix", "alpha_sub=0.25"]
    argv += ["--method", "LN_BOBYQA", "--json", "-o", str(out)]
    assert main(argv) == 0
    (row,) = json.loads(capsys.readouterr().out)
    assert row["success"]
    assert [r["seed"] for r in row["replicates"]] == [0, 1]
    est = [r["alpha_top"] for r in row["replicates"]]
    p = row["params"]["alpha_top"]
    assert p["value"] == pytest.approx(np.mean(est), abs=1e-12)
    sb = row["seed_spread"]["alpha_top"]
    assert sb == pytest.approx(np.std(est, ddof=1), rel=1e-9)
    assert p["stderr"] >= sb / np.sqrt(2)
    assert "2 seed replicates" in row["weighting"]
    table = pd.read_csv(out)
    assert table["replicates"].tolist() == [2]
    assert table["alpha_top_seed_spread"].iloc[0] == pytest.approx(sb)
    assert [float(v) for v in table["alpha_top_replicates"].iloc[0].split(";")] == pytest.approx(
        est
    )


@pytest.mark.parametrize(
    ("extra", "words"),
    [
        (["--model", "microfacet", *AL, "--replicates", "3"], "deterministic"),
        (
            ["--model", "layered", *AL, "--param", "coherent=true", "--replicates", "2"],
            "deterministic",
        ),
        (["--model", "microfacet", *AL, "--replicates", "0"], "--replicates must be"),
        (["--model", "layered", *AL, "--replicates", "-1"], "--replicates must be"),
    ],
)
def test_bad_replicates_exit_2_with_the_reason(microfacet_bsdf, capsys, extra, words):
    assert main(["fit", str(microfacet_bsdf), *extra]) == 2
    err = capsys.readouterr().err
    assert words in err and "Traceback" not in err


def test_non_integer_replicates_exit_2(microfacet_bsdf, capsys):
    with pytest.raises(SystemExit) as exc:
        main(["fit", str(microfacet_bsdf), "--model", "microfacet", *AL, "--replicates", "two"])
    assert exc.value.code == 2
    assert "--replicates" in capsys.readouterr().err


def test_one_replicate_of_a_deterministic_model_is_the_plain_fit(microfacet_bsdf, capsys):
    argv = ["fit", str(microfacet_bsdf), "--model", "microfacet", *AL, "--json"]
    assert main([*argv, "--replicates", "1"]) == 0
    (one,) = json.loads(capsys.readouterr().out)
    assert main(argv) == 0
    (plain,) = json.loads(capsys.readouterr().out)
    assert one["replicates"] is None and one["seed_spread"] is None
    assert one["params"] == plain["params"]
