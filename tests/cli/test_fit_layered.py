"""``labbrdf fit FILE --model layered``: fits through the CLI, AIC/BIC out, errors exit 2."""

from __future__ import annotations

import json

import numpy as np
import pytest

from labbrdf import models
from labbrdf.cli import main
from labbrdf.writers.zemax import model_to_bsdf

AL = ["--param", "n=1.55", "--param", "k=7.71"]


@pytest.fixture(scope="module")
def microfacet_bsdf(tmp_path_factory):
    """A .bsdf of the closed-form GGX microfacet model of Al, alpha 0.25, at 30 and 50 deg."""
    path = tmp_path_factory.mktemp("layered") / "al.bsdf"
    return model_to_bsdf(
        models.get("microfacet", n=1.55, k=7.71),
        {"alpha": 0.25},
        path,
        theta_i_deg=[30.0, 50.0],
        radial_deg=[0, 5, 10, 15, 20, 30, 40, 50, 60],
        azimuth_deg=np.arange(0.0, 181.0, 20.0),
    )


def test_fit_layered_recovers_a_bare_conductor_through_a_zero_thickness_film(
    microfacet_bsdf, capsys
):
    """A 0 nm coherent film is the bare conductor, so alpha_top must come out at 0.25.

    The file is the closed-form microfacet model; the layered model evaluates bin averages
    of the tracer's first-surface map on its grid, interpolated (a bias well below 1 %).
    """
    argv = ["fit", str(microfacet_bsdf), "--model", "layered", *AL]
    argv += ["--param", "coherent=true", "--fix", "thickness_nm=0", "--json"]
    assert main(argv) == 0
    (row,) = json.loads(capsys.readouterr().out)
    assert row["success"]
    assert row["params"]["alpha_top"]["value"] == pytest.approx(0.25, rel=0.01)
    n, k = row["ndata"], 1
    # least-squares AIC and BIC: n ln(chi2 / n) + 2 k and + k ln n
    assert row["bic"] - row["aic"] == pytest.approx(k * (np.log(n) - 2.0), rel=1e-9)


def test_fit_table_lists_aic_and_bic_for_every_model(microfacet_bsdf, capsys):
    """The text table has AIC and BIC columns (microfacet here: closed form, quick)."""
    argv = ["fit", str(microfacet_bsdf), "--model", "microfacet", *AL]
    assert main(argv) == 0
    header = capsys.readouterr().out.splitlines()[0].split()
    assert "aic" in header and "bic" in header


def test_fit_layered_incoherent_reports_how_the_monte_carlo_noise_entered(microfacet_bsdf, capsys):
    """The traced (incoherent) model on one incidence: the weighting names the MC error."""
    argv = ["fit", str(microfacet_bsdf), "--model", "layered", *AL, "--theta-i-range", "29:31"]
    argv += ["--param", "rays=2000", "--param", "grid=3x6", "--fix", "alpha_sub=0.25"]
    argv += ["--method", "LN_BOBYQA", "--json", "--replicates", "1"]  # one seed: cheaper
    assert main(argv) == 0
    (row,) = json.loads(capsys.readouterr().out)
    assert "Monte Carlo error (median" in row["weighting"]
    assert 0.02 <= row["params"]["alpha_top"]["value"] <= 1.0


@pytest.mark.parametrize(
    ("extra", "words"),
    [
        ([], "needs the substrate index n="),
        ([*AL, "--param", "base=glass"], "'base' must be one of"),
        ([*AL, "--param", "rays=10"], "'rays' must be an integer"),
        ([*AL, "--param", "grid=4x7"], "theta step must be one of"),
        ([*AL, "--fix", "alpha=0.2"], "has no parameter 'alpha'"),
        ([*AL, "--param", "base=diffuse"], "takes no substrate index n, k"),
        (
            [*AL, "--param", "scattering=multiple", "--param", "coherent=true"],
            "scattering='multiple' over a conductor needs the incoherent coating",
        ),
    ],
)
def test_fit_layered_errors_exit_2_with_the_reason(microfacet_bsdf, capsys, extra, words):
    assert main(["fit", str(microfacet_bsdf), "--model", "layered", *extra]) == 2
    err = capsys.readouterr().err
    assert words in err
    assert "Traceback" not in err


def test_residual_maps_are_drawn_for_the_fitted_group(microfacet_bsdf, tmp_path, capsys):
    """--residual-maps writes a PNG of measured, model and residual per incidence."""
    png = tmp_path / "maps.png"
    argv = ["fit", str(microfacet_bsdf), "--model", "layered", *AL, "--param", "coherent=true"]
    argv += ["--fix", "thickness_nm=0", "--residual-maps", str(png)]
    assert main(argv) == 0
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert png.stat().st_size > 10_000


def test_residual_maps_refuse_several_groups_before_any_fit(
    microfacet_bsdf, tmp_path, capsys, monkeypatch
):
    """Several groups and one map: refused at once, nothing fitted, -o not written."""
    import labbrdf.fitting

    def no_fit(*a, **k):
        raise AssertionError("a fit ran before --residual-maps was refused")

    monkeypatch.setattr(labbrdf.fitting, "fit_many", no_fit)
    png, table = tmp_path / "maps.png", tmp_path / "table.csv"
    argv = ["fit", str(microfacet_bsdf), "--model", "microfacet", *AL, "--by", "theta_i_deg"]
    argv += ["--residual-maps", str(png), "-o", str(table)]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "draws one fitted group; the data hold 2 (theta_i_deg=30.0; theta_i_deg=50.0)" in err
    assert "--residual-maps" in err and "Traceback" not in err
    assert not png.exists() and not table.exists()
