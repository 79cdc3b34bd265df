"""The prediction section chooses the theory by the Rayleigh criterion (smooth: Rayleigh-Rice)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from labbrdf import models
from labbrdf.report.builder import Builder
from labbrdf.report.context import Context
from labbrdf.report.inputs import ingest_inputs
from labbrdf.report.pairing import sample_groups
from labbrdf.report.sections.prediction import prediction_section
from labbrdf.report.smooth_prediction import choose
from labbrdf.roughness import psd_models
from labbrdf.writers.zemax import model_to_bsdf

pytest.importorskip("SurfaceTopography")

#: the smooth sample's K-correlation PSD (psd_models' form; A [um^4], B [um]): sigma ~ 2 nm
KC = {"A": 1e-5, "B": 5.0, "C": 1.6}


def kc_surface(n: int, size: float, seed: int) -> np.ndarray:
    """A periodic random surface [m] with the K-correlation PSD ``KC`` (FFT filtering).

    ``z = ifft2(fft2(w) H)`` for unit white noise ``w`` has variance ``sum H^2 / N^2``;
    ``H^2 = N^2 PSD2(f) / size^2`` makes it ``sum PSD2 df^2`` (df = 1 / size), the PSD's
    integral over the grid's frequencies.
    """
    f = np.fft.fftfreq(n, d=size / n)
    fr = np.hypot(f[:, None], f[None, :])
    psd = psd_models.k_correlation_2d(fr, KC["A"] * 1e-24, KC["B"] * 1e-6, KC["C"])
    psd[0, 0] = 0.0
    h = np.sqrt(psd) * n / size
    w = np.random.default_rng(seed).standard_normal((n, n))
    return np.fft.ifft2(np.fft.fft2(w) * h).real


@pytest.mark.parametrize(
    "verdicts, choice",
    [
        (["smooth", "smooth"], "rayleigh-rice"),
        (["rough"], "tracer"),
        (["smooth", "rough"], "both"),
        (["undecided"], "both"),
        (["smooth", "outside the map's band"], "both"),
    ],
)
def test_choice_by_the_verdicts(verdicts, choice):
    assert choose(verdicts) == choice


@pytest.fixture(scope="module")
def smooth(prediction_sets, tmp_path_factory) -> dict:
    """Height map, psi/Delta and a .bsdf of the Rayleigh-Rice BRDF of the map's true PSD."""
    from SurfaceTopography import Topography

    ps = prediction_sets
    d = tmp_path_factory.mktemp("smooth")
    n, size = 128, 64e-6
    z = kc_surface(n, size, seed=5)
    hm = d / "mirror_heights.nc"
    Topography(z, physical_sizes=(size, size), unit="m").to_netcdf(str(hm))
    psi = ps.write_wvase(d / "mirror_psi.dat", ps.TRUE_NK, "SYNTHETIC mirror")
    nk = ps.TRUE_NK
    bsdf = model_to_bsdf(
        models.get("rayleigh_rice", n=nk.real, k=nk.imag),
        KC,
        d / "mirror.bsdf",
        theta_i_deg=[30.0, 60.0],
        radial_deg=np.arange(0.0, 81.0, 2.0),
        azimuth_deg=np.arange(0.0, 181.0, 15.0),
        wavelength_nm=600.0,
    )
    paths = [Path(hm), Path(psi), Path(bsdf)]
    b = Builder("t", progress=False)
    ctx = Context(b)
    with b.section("ingest", "Ingested files"):
        ingest_inputs(ctx, paths)
        sample_groups(ctx, paths, [paths])
    with b.section("prediction", "Predict, then measure"):
        prediction_section(ctx)
    b.finish()
    return b.results


def test_a_smooth_sample_is_predicted_by_rayleigh_rice_only(smooth):
    figs = [f for f in smooth["figures"] if f.startswith("prediction_")]
    assert any(f.startswith("prediction_rr_cuts_") for f in figs)
    assert any(f.startswith("prediction_rr_psd_") for f in figs)
    assert not any(f.startswith("prediction_maps_") for f in figs)  # no tracer BRDF
    sec = {s["id"]: s for s in smooth["sections"]}["prediction"]
    texts = [it["text"] for it in sec["items"] if it["kind"] == "text"]
    assert any("Smooth at every angle" in t for t in texts)


def test_the_prediction_from_the_map_meets_the_measurement(smooth):
    """In the map's band, TIS within 30 %: the map holds (64 / 5)^2 ~ 160 correlation areas,
    so its band variance has a relative standard error of about sqrt(2 / 160) = 11 %:
    about 3 of them. Over the whole grid the prediction is lower (the map does not resolve
    the periods below 1 um that scatter at large angles)."""
    (rows,) = [v["rows"] for k, v in smooth["tables"].items() if k.startswith("prediction_rr_tis")]
    for r in rows:
        assert 0.3 * r["points"] < r["in_band"] < r["points"]
        assert abs(r["band_ratio"] - 1.0) < 0.3, r
        assert r["ratio"] < r["band_ratio"]


def test_the_psd_recovered_from_the_brdf_is_the_maps(smooth):
    (fit,) = [v["rows"] for k, v in smooth["tables"].items() if k.startswith("prediction_rr_fit")]
    assert {r["name"] for r in fit} == {"A", "B", "C"}
    sec = {s["id"]: s for s in smooth["sections"]}["prediction"]
    (text,) = [
        it["text"]
        for it in sec["items"]
        if it["kind"] == "text" and "inverse problem" in it["text"]
    ]
    med = float(text.split("is ")[-1].split(" times")[0])
    assert math.isfinite(med) and 0.7 < med < 1.4


def test_a_sample_in_between_gets_both_and_the_page_says_where(prediction_sets, tmp_path):
    """sigma ~ 110 nm at 600 nm: rough at 30 deg (threshold 87 nm), smooth at 75 deg
    (threshold 290 nm): both theories, each named with its angles."""
    from SurfaceTopography import Topography

    from labbrdf.report.smooth_prediction import choose_theory

    z = kc_surface(128, 64e-6, seed=7)
    z *= 110e-9 / z.std()
    hm = tmp_path / "between.nc"
    Topography(z, physical_sizes=(64e-6, 64e-6), unit="m").to_netcdf(str(hm))
    nk = prediction_sets.TRUE_NK
    bsdf = model_to_bsdf(
        models.get("rayleigh_rice", n=nk.real, k=nk.imag),
        KC,
        tmp_path / "between.bsdf",
        theta_i_deg=[30.0, 75.0],
        radial_deg=[0.0, 5.0, 10.0],
        azimuth_deg=[0.0, 90.0, 180.0],
        wavelength_nm=600.0,
    )
    b = Builder("t", progress=False)
    ctx = Context(b)
    with b.section("ingest", "Ingested files"):
        ingest_inputs(ctx, [Path(hm), Path(bsdf)])
    theory = choose_theory(ctx, ctx.height_maps[0], Path(bsdf))
    assert theory.choice == "both"
    assert "smooth at 75 deg" in theory.text and "rough at 30 deg" in theory.text
    assert choose_theory(ctx, ctx.height_maps[0], Path(bsdf), coated=True).choice == "tracer"
    # a coated sample whose film fit gives a coherent stack keeps Rayleigh-Rice, via the stack
    from types import SimpleNamespace

    from labbrdf import films
    from labbrdf.nk.dispersion import Constant
    from labbrdf.report.smooth_prediction import rr_part

    stack = films.Stack([films.Layer(Constant(1.46), 100.0, "coat")], Constant(nk.real, nk.imag))
    coated = choose_theory(ctx, ctx.height_maps[0], Path(bsdf), coated=True, stack=stack)
    assert coated.choice == "both" and "the fitted stack" in coated.text
    slab = films.Stack(stack.layers, stack.substrate, substrate_thickness_nm=1e6)
    refused = choose_theory(ctx, ctx.height_maps[0], Path(bsdf), coated=True, stack=slab)
    assert refused.choice == "tracer" and "cannot take its stack" in refused.text
    with b.section("prediction", "Predict, then measure"):
        rr_part(ctx, "c", ctx.height_maps, Path(bsdf), None, SimpleNamespace(stack=stack))
    b.finish()
    sec = {s["id"]: s for s in b.results["sections"]}["prediction"]
    texts = [it["text"] for it in sec["items"] if it["kind"] == "text"]
    assert any("the film fit's stack (top first: coat 100 nm, 1.46" in t for t in texts)
    assert any("the stack fixed as above" in t for t in texts)


def test_the_wavelength_given_to_the_report_is_taken_for_a_bsdf_that_states_none():
    from types import SimpleNamespace

    from labbrdf.report.smooth_prediction import given_wavelength

    files = [
        {"path": "/d/x.bsdf", "meta": {"wavelength_given": True, "wavelength_nm": 633.0}},
        {"path": "/d/y.bsdf", "meta": {"wavelength_nm": 555.0}},
    ]
    ctx: Any = SimpleNamespace(files=files)
    assert given_wavelength(ctx, Path("/e/x.bsdf")) == 633.0
    assert given_wavelength(ctx, Path("/d/y.bsdf")) is None
