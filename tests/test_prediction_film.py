"""The prediction of a coated sample from its film fit, and the measured slope table."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from labbrdf.adapters.topography import read_height_map
from labbrdf.films import Layer, Roughness, Stack
from labbrdf.nk.dispersion import Cauchy
from labbrdf.prediction import (
    PredictionError,
    film_coating,
    predict_brdf,
    slope_table,
)
from labbrdf.tracer import Coating

pytest.importorskip("SurfaceTopography")

COAT_N, COAT_D = 1.5, 300.0


def _fit(stack: Stack, lo: float = 400.0, hi: float = 800.0) -> SimpleNamespace:
    """What the prediction reads of a FilmFit: its stack and the rows it saw."""
    data = pd.DataFrame({"wavelength_nm": [lo, hi], "source": ["coated_psi.dat"] * 2})
    return SimpleNamespace(stack=stack, data=data)


@pytest.fixture(scope="module")
def coated(sample_set: dict, prediction_sets, tmp_path_factory: pytest.TempPathFactory) -> dict:
    """A .bsdf traced with a 300 nm n = 1.5 coating on the sample, and its film fit."""
    ps = prediction_sets
    alpha = sample_set["fit"].alpha
    coat = Coating(n=COAT_N, k=0.0, thickness_nm=COAT_D, alpha=alpha)
    cfg = ps.brdf_config(alpha, coating=coat, seed=1, rays=16_384)
    bsdf = ps.write_bsdf(tmp_path_factory.mktemp("coated") / "coated.bsdf", cfg)
    stack = Stack([Layer(COAT_N, COAT_D, "varnish")], ps.TRUE_NK)
    return {"bsdf": bsdf, "fit": _fit(stack), "alpha": alpha}


def test_film_coating_takes_the_layer_and_the_substrate_at_the_wavelength(
    prediction_sets,
) -> None:
    # Cauchy n = A + B / lambda^2 [um], written out here
    stack = Stack([Layer(Cauchy(A=2.1, B=0.02), 183.5, "ta2o5")], prediction_sets.TRUE_NK)
    coat, sub = film_coating(_fit(stack), 600.0, 0.12)
    assert coat.n == pytest.approx(2.1 + 0.02 / 0.6**2, rel=1e-12)
    assert coat.k == 0.0 and coat.thickness_nm == 183.5
    assert coat.alpha == 0.12 and coat.ndf is None  # conformal: the map's roughness on top
    assert sub == pytest.approx(prediction_sets.TRUE_NK, rel=1e-12)


@pytest.mark.parametrize(
    ("layers", "wl", "match"),
    [
        ([], 600.0, r"coated_psi.dat: .* 0 layer\(s\)"),
        ([Layer(1.5, 100.0, "a"), Layer(2.0, 50.0, "b")], 600.0, r"2 layer\(s\) \['a', 'b'\]"),
        ([Layer(Roughness(), 5.0, "rough")], 600.0, r"1 layer\(s\) \['rough'\]"),
        ([Layer(1.5, 100.0, "a")], 900.0, r"900 nm is outside the fitted range \[400, 800\]"),
        ([Layer(1.5, 0.0, "a")], 600.0, r"0 nm thick; an incoherent coating needs"),
    ],
)
def test_film_coating_refuses_what_the_tracer_cannot_hold(
    layers: list, wl: float, match: str
) -> None:
    with pytest.raises(PredictionError, match=match):
        film_coating(_fit(Stack(layers, 3.0 + 1.0j)), wl, 0.1)


def test_coated_prediction_from_the_film_fit_agrees_with_the_coated_measurement(
    coated: dict, sample_set: dict
) -> None:
    p = predict_brdf(
        coated["bsdf"], None, sample_set["fit"], film=coated["fit"], rays=16_384, step_deg=2.0
    )
    assert p.index_from == "film fit" and p.slopes == "ggx"
    assert p.coating is not None
    assert (p.coating["n"], p.coating["thickness_nm"]) == (COAT_N, COAT_D)
    assert p.coating["alpha"] == pytest.approx(coated["alpha"], rel=1e-12)
    # two independent runs (seeds 0 and 1) of the same coated sample
    se = math.sqrt(2) * p.tis_predicted_stderr[0]
    assert abs(p.tis_predicted[0] - p.tis_measured[0]) < 3 * se
    assert bool(p.regions()["consistent"].all())


def test_the_bare_substrate_misses_the_coated_measurement(coated: dict, sample_set: dict) -> None:
    # without the film fit the prediction is the bare metal's: the varnish changes the TIS
    # by far more than the Monte Carlo error, so the test above is no accident
    p = predict_brdf(
        coated["bsdf"],
        None,
        sample_set["fit"],
        substrate_index=complex(1.2, 7.26),
        rays=16_384,
        step_deg=2.0,
    )
    assert p.index_from == "given" and p.coating is None
    assert abs(p.tis_predicted[0] / p.tis_measured[0] - 1) > 0.05
    assert not bool(p.regions()["consistent"].all())


def test_film_and_coating_together_are_refused(coated: dict, sample_set: dict) -> None:
    with pytest.raises(PredictionError, match="give the coating once"):
        predict_brdf(
            coated["bsdf"],
            None,
            sample_set["fit"],
            film=coated["fit"],
            coating=Coating(n=1.5, k=0.0, thickness_nm=10.0, alpha=0.1),
        )
    with pytest.raises(PredictionError, match="give the coating once"):
        predict_brdf(
            coated["bsdf"], None, sample_set["fit"], film=coated["fit"], substrate_index=2 + 1j
        )


def test_no_psi_delta_and_no_index_is_refused(coated: dict, sample_set: dict) -> None:
    with pytest.raises(PredictionError, match="give the psi/Delta rows or the substrate index"):
        predict_brdf(coated["bsdf"], None, sample_set["fit"])


def test_a_film_fit_outside_the_bsdf_wavelength_is_refused(coated: dict, sample_set: dict) -> None:
    fit = _fit(coated["fit"].stack, 300.0, 500.0)  # the .bsdf is at 600 nm
    with pytest.raises(PredictionError, match="600 nm is outside the fitted range"):
        predict_brdf(coated["bsdf"], None, sample_set["fit"], film=fit)


# --------------------------------------------------------------------------- slope table


def test_slope_table_is_the_one_trace_surface_uses(sample_set: dict) -> None:
    from labbrdf.tracer import Substrate

    hm = read_height_map(sample_set["height_map"])
    t = slope_table(hm)
    ref = Substrate.from_surface(hm.heights, tuple(hm.pixel_size)).ndf
    assert ref is not None
    assert np.array_equal(t.to_dict()["mass"], ref.to_dict()["mass"])


def test_slope_table_refuses_a_profile_and_a_missing_pitch() -> None:
    with pytest.raises(PredictionError, match="a line profile; a slope table needs"):
        slope_table(np.zeros(50), 1e-6)
    with pytest.raises(PredictionError, match="pixel_size is needed"):
        slope_table(np.zeros((8, 8)))


def test_measured_slopes_change_the_lobe_not_the_energy(sample_set: dict) -> None:
    # the sample's .bsdf was traced with GGX of the map's alpha; the map is a Gaussian
    # surface (Gaussian slopes, no GGX tail), so its measured table traces another lobe
    # shape (the regions disagree: the table is used) while the scattered energy, fixed by
    # the metal's Fresnel reflectance, moves only by shadowing and the grid's coverage
    hm = read_height_map(sample_set["height_map"])
    p = predict_brdf(
        sample_set["bsdf"],
        None,
        sample_set["fit"],
        substrate_index=complex(1.2, 7.26),
        ndf=slope_table(hm),
        rays=16_384,
    )
    assert p.slopes == "measured"
    assert abs(float(p.tis_predicted[0] / p.tis_measured[0]) - 1) < 0.05
    assert not bool(p.regions()["consistent"].any())
