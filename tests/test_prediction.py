"""Predict, then measure: the tracer's prediction from a height map and psi/Delta, no fit."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from labbrdf import optics, read
from labbrdf.adapters import AdapterError
from labbrdf.adapters.topography import read_height_map
from labbrdf.prediction import (
    PredictionError,
    ellipsometer_dop,
    predict_brdf,
    roughness_alpha,
    specular_dop_comparison,
    substrate_nk,
)
from labbrdf.tracer import Coating

pytest.importorskip("SurfaceTopography")


def _data(path) -> pd.DataFrame:
    return read(path).data


def _reflectance(nk: complex, theta: float) -> float:
    rs, rp = optics.reflectance(1.0, nk, theta)
    return float((rs + rp) / 2)


# --------------------------------------------------------------------------- inputs


def test_alpha_of_the_generated_surface_is_its_slope_statistics(sample_set: dict) -> None:
    # Dong 2022, text after eq. (15): alpha = sqrt(2) sigma / c = 0.106 for the ensemble; one
    # 128 x 128 patch of 32 correlation lengths scatters by a few percent about it
    fit = sample_set["fit"]
    assert fit.alpha == pytest.approx(math.sqrt(2) * 0.3 / 4, rel=0.15)
    assert 0 < fit.alpha_u < 0.05 * fit.alpha


def test_substrate_nk_recovers_the_index_the_file_was_written_with(
    sample_set: dict, prediction_sets
) -> None:
    nk = substrate_nk(_data(sample_set["psi_delta"]), [500.0, 600.0])
    assert nk["n"] == pytest.approx([prediction_sets.TRUE_NK.real] * 2, abs=1e-6)
    assert nk["k"] == pytest.approx([prediction_sets.TRUE_NK.imag] * 2, abs=1e-6)


def test_ellipsometer_dop_is_cos_2psi_of_each_row(sample_set: dict, prediction_sets) -> None:
    e = ellipsometer_dop(_data(sample_set["psi_delta"]))
    assert len(e) == 9 and e["depolarization"].isna().all()
    psi, _ = optics.psi_delta(prediction_sets.TRUE_NK, e["theta_i_deg"].to_numpy())
    assert e["dop"].to_numpy() == pytest.approx(np.abs(np.cos(2 * np.radians(psi))), abs=1e-9)
    want = 2 * np.abs(np.sin(2 * np.radians(psi))) * np.radians(0.02)
    assert e["dop_sigma"].to_numpy() == pytest.approx(want, rel=1e-9)


def test_ellipsometer_dop_uses_the_depolarization_at_the_same_angle(sample_set: dict) -> None:
    df = _data(sample_set["psi_delta"])
    psi = df[df["quantity"].astype(str) == "psi"]
    at65 = psi[np.isclose(psi["theta_i_deg"], 65.0)]
    dep = at65.assign(quantity="depolarization", value=0.1, sigma=0.01, unit="1")
    e = ellipsometer_dop(pd.concat([df, dep], ignore_index=True))
    plain = ellipsometer_dop(df)
    m65 = np.isclose(e["theta_i_deg"], 65.0)
    assert e.loc[m65, "depolarization"].tolist() == [0.1] * 3
    assert e.loc[m65, "dop"].to_numpy() == pytest.approx(0.9 * plain.loc[m65, "dop"].to_numpy())
    assert e.loc[~m65, "dop"].to_numpy() == pytest.approx(plain.loc[~m65, "dop"].to_numpy())


# --------------------------------------------------------------------------- DOP (Fig. 6)


def test_tracer_specular_dop_equals_the_ellipsometers_for_a_bare_substrate(
    sample_set: dict,
) -> None:
    # single scattering: at exact specular the facet normal is the mean normal, so the
    # traced DOP is |cos 2psi| up to the bin average over +-0.5 deg about specular, a
    # second-order effect bounded by (0.5 deg / lobe width)^2
    alpha = sample_set["fit"].alpha
    c = specular_dop_comparison(_data(sample_set["psi_delta"]), alpha, max_wavelengths=2)
    t = c.table
    assert len(t) == 6 and sorted(t["theta_i_deg"].unique()) == [55.0, 65.0, 75.0]
    lobe = math.degrees(math.atan(alpha))
    tol = (0.5 / lobe) ** 2
    assert np.abs(t["dop_tracer"] - t["dop_ellipsometer"]).max() < tol
    assert (t["dop_tracer_stderr"] < 1e-6).all()  # closed form: no Monte Carlo error


def test_depolarizing_ellipsometer_is_flagged_against_the_tracer(sample_set: dict) -> None:
    df = _data(sample_set["psi_delta"])
    psi = df[df["quantity"].astype(str) == "psi"]
    dep = psi.assign(quantity="depolarization", value=0.2, sigma=0.005, unit="1")
    c = specular_dop_comparison(
        pd.concat([df, dep], ignore_index=True), sample_set["fit"].alpha, max_wavelengths=1
    )
    assert (c.table["z"] > 5).all()  # the tracer (no depolarization) sits far above


def test_coated_specular_dop_errors_are_honest_between_seeds(sample_set: dict) -> None:
    # with a varnish over the metal the subsurface walk has Monte Carlo noise: two seeds
    # must agree within their combined batch errors, and the coating's own reflection
    # (near Brewster's angle of n = 1.5 at 55 deg) lifts the DOP far above the bare metal's
    coat = Coating(n=1.5, k=0.0, thickness_nm=300.0, alpha=sample_set["fit"].alpha)
    df = _data(sample_set["psi_delta"])
    runs = [
        specular_dop_comparison(
            df,
            sample_set["fit"].alpha,
            wavelengths_nm=[600.0],
            coating=coat,
            rays=16_384,
            seed=seed,
            step_deg=2.0,
        ).table
        for seed in (0, 1)
    ]
    a, b = runs
    assert (a["dop_tracer_stderr"] > 0).all()
    z = (a["dop_tracer"] - b["dop_tracer"]) / np.hypot(
        a["dop_tracer_stderr"], b["dop_tracer_stderr"]
    )
    assert np.abs(z).max() < 4
    assert (a["z"] > 10).all()  # the bare-metal ellipsometer DOP is not the coated sample's


# --------------------------------------------------------------------------- BRDF


@pytest.fixture(scope="module")
def right(sample_set: dict):
    return predict_brdf(sample_set["bsdf"], _data(sample_set["psi_delta"]), sample_set["fit"])


@pytest.fixture(scope="module")
def wrong(sample_set: dict):
    return predict_brdf(
        sample_set["bsdf"], _data(sample_set["psi_delta_wrong"]), sample_set["fit"]
    )


def test_prediction_from_the_same_sample_matches_the_measurement(right) -> None:
    assert right.wavelength_nm == 600.0 and right.theta_i_deg.tolist() == [45.0]
    assert right.consistent.all()
    up = right.above & (right.measured > 0)
    rel = np.abs(right.predicted[up] / right.measured[up] - 1)
    assert rel.max() < 1e-5  # the file's six digits
    assert right.tis_predicted == pytest.approx(right.tis_measured, rel=1e-5)
    assert right.tis_file == pytest.approx(right.tis_measured, rel=1e-5)
    assert right.regions()["consistent"].all()
    assert right.verdict().count("on the measurement") == 2


def test_wrong_index_is_flagged_with_the_fresnel_ratio_in_the_lobe(right, wrong) -> None:
    assert not wrong.consistent.all()
    reg = wrong.regions().set_index("region")
    # near specular the facets are near the mean normal: the ratio is that of the
    # unpolarized Fresnel reflectances at 45 deg (to the lobe's spread of local angles)
    want = _reflectance(1.5 + 3.0j, 45.0) / _reflectance(1.2 + 7.26j, 45.0)
    assert reg.loc["specular lobe", "ratio"] == pytest.approx(want, rel=0.02)
    assert not reg["consistent"].any()
    v = wrong.verdict()
    pct = round(abs(reg.loc["specular lobe", "ratio"] - 1) * 100)
    assert f"{pct:.0f} % low in the specular lobe" in v
    assert v.startswith("At 45 deg the prediction is")
    assert wrong.tis_predicted[0] < 0.95 * wrong.tis_measured[0]
    assert wrong.albedo[0] == pytest.approx(right.albedo[0] * want, rel=0.03)


def test_coated_prediction_agrees_within_its_stated_monte_carlo_error(
    sample_set: dict, prediction_sets, tmp_path
) -> None:
    # two independent runs (seeds 1 and 0): their difference over sqrt(2) SE must look like
    # a unit normal if the batch errors are honest
    alpha = sample_set["fit"].alpha
    coat = Coating(n=1.5, k=0.0, thickness_nm=300.0, alpha=alpha)
    cfg = prediction_sets.brdf_config(alpha, coating=coat, seed=1, rays=16_384)
    bsdf = prediction_sets.write_bsdf(tmp_path / "coated.bsdf", cfg)
    p = predict_brdf(
        bsdf,
        _data(sample_set["psi_delta"]),
        sample_set["fit"],
        coating=coat,
        rays=16_384,
        step_deg=2.0,
    )
    ok = p.above & (p.measured > 0) & (p.predicted_stderr > 0)
    z = (p.predicted[ok] - p.measured[ok]) / (math.sqrt(2) * p.predicted_stderr[ok])
    assert ok.sum() > 500
    assert 0.7 < float(np.std(z)) < 1.4
    assert float(np.mean(np.abs(z) > 4)) < 0.01
    assert (
        abs(p.tis_predicted[0] - p.tis_measured[0]) < 3 * math.sqrt(2) * p.tis_predicted_stderr[0]
    )


# --------------------------------------------------------------------------- errors


def test_a_profile_has_no_alpha(tmp_path) -> None:
    with pytest.raises(PredictionError, match="line profile"):
        roughness_alpha(np.linspace(0, 1e-6, 50), 1e-6)
    with pytest.raises(PredictionError, match="pixel_size is needed"):
        roughness_alpha(np.zeros((8, 8)))


def test_heightmap_error_names_the_file(sample_set: dict) -> None:
    hm = read_height_map(sample_set["height_map"])
    prof = type(hm)(hm.heights[0], hm.pixel_size[:1], hm.path, hm.channel)
    with pytest.raises(PredictionError, match=r"sample_a_heights\.nc: a line profile"):
        roughness_alpha(prof)


def test_no_psi_rows_is_refused(sample_set: dict) -> None:
    df = read(sample_set["bsdf"]).data
    with pytest.raises(PredictionError, match=r"sample_a\.bsdf: no psi rows"):
        ellipsometer_dop(df)


def test_wavelength_outside_the_psi_delta_is_refused(sample_set: dict) -> None:
    with pytest.raises(PredictionError, match=r"sample_a_psi\.dat: .*outside the measured"):
        substrate_nk(_data(sample_set["psi_delta"]), [900.0])


def test_stack_psi_delta_is_refused(sample_set: dict, tmp_path) -> None:
    df = _data(sample_set["psi_delta"]).copy()
    psi = df["quantity"].astype(str) == "psi"
    df.loc[psi, "value"] += np.where(np.isclose(df.loc[psi, "theta_i_deg"], 75.0), 2.0, 0.0)
    with pytest.raises(PredictionError, match="stack"):
        substrate_nk(df, [600.0])


def test_two_files_of_psi_delta_are_refused(sample_set: dict) -> None:
    df = pd.concat(
        [_data(sample_set["psi_delta"]), _data(sample_set["psi_delta_wrong"])],
        ignore_index=True,
    )
    with pytest.raises(PredictionError, match="one file"):
        specular_dop_comparison(df, 0.1)


def _edit_bsdf(src, dst, old: str, new: str):
    text = src.read_text()
    assert old in text
    dst.write_text(text.replace(old, new, 1))
    return dst


def test_bsdf_without_wavelength_is_refused(sample_set: dict, tmp_path) -> None:
    p = _edit_bsdf(sample_set["bsdf"], tmp_path / "nowl.bsdf", "#labbrdf wavelength_nm", "#x")
    with pytest.raises(PredictionError, match=r"nowl\.bsdf: the file states no wavelength"):
        predict_brdf(p, _data(sample_set["psi_delta"]), 0.1)
    # given explicitly, it runs
    assert predict_brdf(p, _data(sample_set["psi_delta"]), 0.1, wavelength_nm=600.0).n > 0


def test_btdf_is_refused(sample_set: dict, tmp_path) -> None:
    p = _edit_bsdf(
        sample_set["bsdf"], tmp_path / "t.bsdf", "ScatterType  BRDF", "ScatterType  BTDF"
    )
    with pytest.raises(PredictionError, match=r"t\.bsdf: BTDF data"):
        predict_brdf(p, _data(sample_set["psi_delta"]), 0.1)


def test_unreadable_bsdf_names_the_file(sample_set: dict, tmp_path) -> None:
    p = tmp_path / "bad.bsdf"
    p.write_text("Source Measured\nSymmetry Nonsense\n")
    with pytest.raises(AdapterError, match=r"bad\.bsdf"):
        predict_brdf(p, _data(sample_set["psi_delta"]), 0.1)


# --------------------------------------------------------------------------- real exports


@pytest.mark.shared
@pytest.mark.parametrize(
    ("rel", "matched"),
    [
        ("woollam-wvase-ascii/wafer_2_01242007.dat", 2028),  # dpolE at every psi point
        ("woollam-wvase-ascii/wvase_example.dat", 0),  # dpolE at 55-58 deg, psi at 65-75
        ("filmsense-txt/Filmsense_staticTest.txt", 8),  # 1 - P per wavelength
    ],
)
def test_real_depolarization_is_matched_by_file_wavelength_and_angle(
    real_exports, rel: str, matched: int
) -> None:
    path = real_exports / rel
    if not path.is_file():
        pytest.skip(f"{path} absent")
    df = read(path).data
    e = ellipsometer_dop(df)
    assert int(e["depolarization"].notna().sum()) == matched
    d = np.clip(np.nan_to_num(e["depolarization"].to_numpy(), nan=0.0), 0.0, 1.0)
    want = (1 - d) * np.abs(np.cos(2 * np.radians(e["psi_deg"].to_numpy())))
    assert e["dop"].to_numpy() == pytest.approx(want, abs=1e-12)
    assert ((e["dop"] >= 0) & (e["dop"] <= 1)).all()


def test_several_rotations_are_refused(sample_set: dict, tmp_path) -> None:
    from labbrdf.writers.zemax import write_bsdf

    p = write_bsdf(
        tmp_path / "rot.bsdf",
        theta_i_deg=[45.0],
        radial_deg=[0.0, 10.0],
        azimuth_deg=[0.0, 180.0],
        values=np.ones((2, 1, 1, 2, 2)),
        rotation_deg=[0.0, 90.0],
        symmetry="PlaneSymmetrical",
    )
    with pytest.raises(PredictionError, match=r"rot\.bsdf: 2 rotation\(s\) x 1 channel"):
        predict_brdf(p, _data(sample_set["psi_delta"]), 0.1, wavelength_nm=600.0)
