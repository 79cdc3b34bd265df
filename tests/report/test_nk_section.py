"""Section nk of the user report: pseudo-constants of a stack are not material constants."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from labbrdf.report.user import user_report

W1 = "woollam-wvase-ascii/w1_12082006.dat"
W1_RP = "woollam-wvase-ascii/w1_12082006_p-pol_refl.dat"
W1_RS = "woollam-wvase-ascii/w1_12082006_s-pol_refl.dat"


@pytest.fixture(scope="module")
def trio(real_exports: Path, tmp_path_factory: pytest.TempPathFactory) -> dict:
    out = tmp_path_factory.mktemp("trio") / "rep"
    paths = [real_exports / p for p in (W1, W1_RP, W1_RS)]
    # three files of one wafer that state three different names: paired by the mapping
    code = user_report(paths, "smooth3", out, progress=False, same_sample=[paths])
    res = json.loads((out / "results.json").read_text())
    res["_code"] = code
    res["_page"] = (out / "index.html").read_text()
    return res


def test_coated_wafer_report_passes_with_reflectance_not_applicable(trio: dict) -> None:
    assert trio["_code"] == 0 and trio["summary"]["fail"] == 0
    refl = [c for c in trio["checks"] if c["id"].startswith("nk.reflectance")]
    assert len(refl) == 2  # the p- and the s-polarised file
    for c in refl:
        assert c["status"] == "skipped"
        assert "pseudo-constants of a stack" in c["reason"]
        assert "does not apply" in c["reason"]
    k = next(c for c in trio["checks"] if c["id"].startswith("nk.k_physical"))
    assert k["status"] == "skipped"


def test_coated_wafer_gives_no_constants_and_no_prediction(trio: dict) -> None:
    t = trio["tables"]["nk_0_w1_12082006_dat"]["rows"]
    assert t and all(r["n"] is None and r["k"] is None for r in t)
    row = trio["tables"]["nk_summary"]["rows"][0]
    assert row["n_500"] is None and row["verdict"].startswith("angle-dependent")
    assert "nk_reflectance_comparison" not in trio["tables"]
    figs = set(trio["figures"])
    assert "nk_0_w1_12082006_dat_pseudo" in figs
    assert not any(f.endswith("_r0") or f.endswith("_combined") for f in figs)
    assert "pseudo-constants of a stack" in trio["_page"]


def test_coated_wafer_without_a_film_model_says_how_to_fit_one(trio: dict) -> None:
    film = next(s for s in trio["sections"] if s["id"] == "film")
    assert film["status"] == "not available"
    assert "w1_12082006.dat: pseudo-constants of a stack" in film["reason"]
    assert "--film-model" in film["reason"]


# ------------------------------------------------------------- rough samples' reflectance
N, K = 1.5, 3.0  # bulk n, k of the sample, as an ellipsometer's combined table gives them


def _rough_ctx(tmp_path: Path, *, paired: bool):
    """A 20 nm Gaussian map (20 um, c 2 um) and the reflectance a rough sample of n, k
    reflects: the smooth Fresnel R times Davies' exp(-g) from the map's sigma, 1 % sigma."""
    import numpy as np
    import pandas as pd

    from labbrdf.adapters.topography import HeightMap
    from labbrdf.dataset import make_frame
    from labbrdf.report.builder import Builder
    from labbrdf.report.context import Context
    from labbrdf.roughness import smoothness as sm
    from labbrdf.roughness.synthetic import gaussian_surface
    from labbrdf.samples import pair_samples

    s = gaussian_surface(128, 20e-6, 20e-9, 2e-6, rng=3)
    hm_path, refl_path = tmp_path / "map.di", tmp_path / "refl.csv"
    hm = HeightMap(s.z, tuple(s.spacing), str(hm_path), "height")
    wl = np.linspace(400.0, 1000.0, 13)
    r0 = abs((complex(N, K) - 1) / (complex(N, K) + 1)) ** 2
    sigma = float(np.std(s.z - s.z.mean())) * 1e9
    r = r0 * sm.specular_loss(sm.rayleigh_parameter(sigma, wl))
    refl = make_frame(
        sample="S", instrument="synthetic", source="refl.csv", quantity="reflectance",
        value=r, sigma=0.01 * r, unit="1", wavelength_nm=wl,
    )  # fmt: skip
    ctx = Context(Builder("t", progress=False))
    ctx.height_maps.append(hm)
    ctx.frames.append(refl)
    ctx.files.append({"path": str(refl_path), "samples": ["S"], "meta": {}})
    same = [[hm_path, refl_path]] if paired else []
    ctx.samples[:] = pair_samples([(hm_path, ()), (refl_path, "S")], same, given_as="given")
    comb = pd.DataFrame(
        {"sample": "S", "source": "ell.dat", "wavelength_nm": [300.0, 1100.0], "n": N, "k": K,
         "n_sigma": 0.0, "k_sigma": 0.0, "nk_cov": 0.0}
    )  # fmt: skip
    return ctx, comb, refl


def _compared(ctx, comb, refl) -> tuple[dict, dict, list[str]]:
    from labbrdf.report.sections.nk import _compare

    rows: list = []
    with ctx.b.section("nk", "t"):
        _compare(ctx, "t", "ell.dat", comb, refl, "refl.csv", rows)
    res = ctx.b.results
    (c,) = [c for c in res["checks"] if c["id"] == "nk.reflectance.t"]
    notes = [i["text"] for s in res["sections"] for i in s["items"] if i["kind"] == "note"]
    return c, rows[0], notes


def test_rough_sample_paired_with_its_map_is_compared_with_fresnel_times_exp_minus_g(tmp_path):
    """Before: chi2/dof in the thousands against the smooth Fresnel R, FAIL."""
    c, row, notes = _compared(*_rough_ctx(tmp_path, paired=True))
    assert c["status"] == "pass", c
    assert "exp(-g) of map.di" in c["name"] and "exp(-g)" in c["justification"]
    assert row["prediction"] == "Fresnel x exp(-g), map.di"
    # the band-limited sigma (periods above lambda) differs from the full map's by < 1 %
    assert row["chi2_dof"] < 1.0
    assert not any("roughness is a possible" in n for n in notes)


def test_rough_sample_without_a_map_fails_and_names_roughness_as_a_possible_cause(tmp_path):
    c, row, notes = _compared(*_rough_ctx(tmp_path, paired=False))
    assert c["status"] == "fail" and row["prediction"] == "Fresnel" and row["mean_diff"] < 0
    assert "roughness is a possible cause" in c["justification"]
    assert any("refl.csv" in n and "roughness is a possible cause" in n for n in notes)
