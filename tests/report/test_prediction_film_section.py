"""Section prediction: the sample's film fit as the coating, and the measured slope table."""

from __future__ import annotations

import shutil
from pathlib import Path
from types import SimpleNamespace

import pandas as pd
import pytest

from labbrdf.films import Layer, Stack
from labbrdf.report.builder import Builder
from labbrdf.report.context import Context
from labbrdf.report.inputs import ingest_inputs
from labbrdf.report.pairing import sample_groups
from labbrdf.report.sections.prediction import prediction_section, sample_inputs
from labbrdf.tracer import Coating

pytest.importorskip("SurfaceTopography")


def _ctx(paths: list[Path], film: object | None) -> Context:
    b = Builder("t", progress=False)
    ctx = Context(b)
    with b.section("ingest", "Ingested files"):
        ingest_inputs(ctx, paths)
        sample_groups(ctx, paths, [paths])
    if film is not None:
        ctx.film_fits[paths[1].name] = film  # what section film leaves for this one
    return ctx


def _run(ctx: Context, **kw: str) -> dict:
    with ctx.b.section("prediction", "Predict, then measure"):
        prediction_section(ctx, **kw)
    ctx.b.finish()
    return ctx.b.results


def _items(res: dict) -> list[dict]:
    return {s["id"]: s for s in res["sections"]}["prediction"]["items"]


@pytest.fixture(scope="module")
def coated(sample_set: dict, prediction_sets, tmp_path_factory: pytest.TempPathFactory) -> dict:
    """The sample's map and psi/Delta, a .bsdf traced with a varnish, and its film fit."""
    d = tmp_path_factory.mktemp("coated_section")
    alpha = sample_set["fit"].alpha
    coat = Coating(n=1.5, k=0.0, thickness_nm=300.0, alpha=alpha)
    bsdf = prediction_sets.write_bsdf(
        d / "coated.bsdf", prediction_sets.brdf_config(alpha, coating=coat, seed=1)
    )
    hm = Path(shutil.copy(sample_set["height_map"], d / "coated_heights.nc"))
    psi = Path(shutil.copy(sample_set["psi_delta"], d / "coated_psi.dat"))
    stack = Stack([Layer(1.5, 300.0, "varnish")], prediction_sets.TRUE_NK)
    data = pd.DataFrame({"wavelength_nm": [500.0, 700.0], "source": [psi.name] * 2})
    film = SimpleNamespace(stack=stack, data=data)
    return {"paths": [hm, psi, bsdf], "film": film}


def test_the_film_fit_is_the_coating_and_the_page_says_so(coated: dict) -> None:
    ctx = _ctx(coated["paths"], coated["film"])
    (ready,), _ = sample_inputs(ctx)
    assert ready["film"] is coated["film"]
    res = _run(ctx)
    texts = [it["text"] for it in _items(res) if it["kind"] == "text"]
    line = next(t for t in texts if t.startswith("coated.bsdf at 600 nm"))
    assert "substrate n + ik = 1.2 + 7.26i (the film fit's substrate)" in line
    assert "coating n + ik = 1.5 + 0i, 300 nm thick (the film fit's layer, incoherent)" in line
    assert "conformal coating, the map taken as measured on its top" in line
    assert "GGX alpha" in line
    notes = [it for it in _items(res) if it["kind"] == "note"]
    assert [n["label"] for n in notes] == ["specular DOP not compared"]
    assert "coherent film's" in notes[0]["text"]
    assert not any(f.startswith("prediction_dop_") for f in res["figures"])
    assert any(f.startswith("prediction_maps_") for f in res["figures"])


def test_without_a_film_fit_the_bare_substrate_is_said(coated: dict) -> None:
    res = _run(_ctx(coated["paths"], None))
    line = next(
        t for it in _items(res) if (t := it.get("text", "")).startswith("coated.bsdf at 600 nm")
    )
    assert line.startswith("coated.bsdf at 600 nm: bare substrate n + ik = 1.2 + 7.26i")
    assert any(f.startswith("prediction_dop_") for f in res["figures"])


def test_a_film_fit_that_gives_no_coating_is_a_note(coated: dict, prediction_sets) -> None:
    two = Stack([Layer(1.5, 300.0, "a"), Layer(2.0, 20.0, "b")], prediction_sets.TRUE_NK)
    film = SimpleNamespace(stack=two, data=coated["film"].data)
    res = _run(_ctx(coated["paths"], film))
    notes = {it["label"]: it["text"] for it in _items(res) if it["kind"] == "note"}
    assert "coated.bsdf not predicted" in notes
    assert "2 layer(s) ['a', 'b']" in notes["coated.bsdf not predicted"]
    assert not any(f.startswith("prediction_maps_") for f in res["figures"])


def test_measured_slopes_are_traced_when_asked(coated: dict) -> None:
    res = _run(_ctx(coated["paths"], None), slopes="measured")
    texts = [it["text"] for it in _items(res) if it["kind"] == "text"]
    assert any("traced: the map's measured slope table" in t for t in texts)
    assert any("the height map's measured slope table (GGX alpha" in t for t in texts)


def test_an_unknown_slope_model_is_refused(coated: dict) -> None:
    with pytest.raises(ValueError, match="slopes: expected one of ggx, measured, got 'gauss'"):
        prediction_section(_ctx(coated["paths"], None), slopes="gauss")
