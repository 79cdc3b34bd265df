"""Section ``smoothness``: a height map against one sample's reflectance, and the fit flags."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from labbrdf.adapters.topography import HeightMap
from labbrdf.dataset import make_frame
from labbrdf.report.builder import Builder
from labbrdf.report.context import Context
from labbrdf.report.roughness import rayleigh_flags
from labbrdf.report.sections.smoothness import smoothness_section
from labbrdf.roughness.synthetic import gaussian_surface
from labbrdf.samples import pair_samples

N, K = 1.5, 3.0  # bulk n, k given to the section as an ellipsometer's combined table
R_FRESNEL = abs((complex(N, K) - 1) / (complex(N, K) + 1)) ** 2  # normal incidence, by hand


def _ctx(tmp_path: Path, sigma_nm: float, *, paired: bool = True, nk: bool = False) -> Context:
    """A 20 um Gaussian map (pixel 156 nm, c = 2 um) and reflectance at 400..1000 nm."""
    s = gaussian_surface(128, 20e-6, sigma_nm * 1e-9, 2e-6, rng=3)
    hm_path = tmp_path / "map.di"
    hm = HeightMap(s.z, tuple(s.spacing), str(hm_path), "height")
    wl = np.array([400.0, 600.0, 800.0, 1000.0])
    refl = make_frame(
        sample="S",
        instrument="synthetic",
        source="refl.csv",
        quantity="reflectance",
        value=np.full(4, 0.95 * R_FRESNEL),
        unit="1",
        wavelength_nm=wl,
    )
    scan = make_frame(
        sample="S",
        instrument="synthetic",
        source="scan.csv",
        quantity="specular_intensity",
        value=np.ones(2),
        unit="1",
        wavelength_nm=400.0,
        theta_i_deg=[30.0, 60.0],
    )
    ctx = Context(Builder("t"))
    ctx.height_maps.append(hm)
    ctx.frames += [refl, scan]
    paths = [hm_path, tmp_path / "refl.csv", tmp_path / "scan.csv", tmp_path / "ell.dat"]
    ctx.files += [
        {"path": str(p), "samples": ["S"] if p.suffix != ".di" else [], "meta": {}}
        for p in paths[1:]
    ]
    same = [[paths[0], paths[1]]] if paired else []
    ctx.samples[:] = pair_samples(
        [(paths[0], ()), *[(p, "S") for p in paths[1:]]], same, given_as="given"
    )
    if nk:
        ctx.nk_combined["ell.dat"] = pd.DataFrame(
            {
                "sample": "S",
                "source": "ell.dat",
                "wavelength_nm": [300.0, 1100.0],
                "n": N,
                "k": K,
                "n_sigma": 0.0,
                "k_sigma": 0.0,
                "nk_cov": 0.0,
            }
        )
    return ctx


def _run(ctx: Context) -> dict:
    with ctx.b.section("smoothness", "t"):
        smoothness_section(ctx)
    return ctx.b.results


def test_section_table_follows_the_formulas_and_the_band(tmp_path):
    res = _run(_ctx(tmp_path, 20.0, nk=True))
    assert res["sections"][0]["status"] == "ok"
    rows = res["tables"]["smoothness_S_map_di"]["rows"]
    assert [r["wavelength_nm"] for r in rows] == [400.0, 600.0, 800.0, 1000.0]
    for r in rows:
        lam = r["wavelength_nm"]
        # 2 pixels = 312 nm < lambda: the map resolves all that scatters; sigma band-limited
        assert r["coverage"] == "band-limited"
        # c = 2 um >> lambda: nearly all the height variance scatters
        assert r["sigma_nm"] == pytest.approx(20.0, rel=0.15)
        assert r["g"] == pytest.approx((4 * math.pi * r["sigma_nm"] / lam) ** 2, rel=1e-12)
        assert r["loss"] == pytest.approx(math.exp(-r["g"]), rel=1e-12)
        assert r["thr_rayleigh"] == pytest.approx(lam / 8, rel=1e-12)
        assert r["rayleigh"] == "smooth"  # 20 nm < 50 nm at 400 nm
        assert r["ratio"] == pytest.approx(0.95, rel=1e-9)  # measured / Fresnel
    # Fraunhofer thresholds 12.5, 18.75, 25, 31.25 nm: rough at 400 nm, smooth at 1000 nm,
    # never smooth before rough as lambda grows
    fr = [r["fraunhofer"] for r in rows]
    assert fr[0] == "rough" and fr[-1] == "smooth"
    order = {"rough": 0, "undecided": 1, "smooth": 2}
    assert [order[v] for v in fr] == sorted(order[v] for v in fr)
    assert any(it.get("kind") == "figure" for it in res["sections"][0]["items"])


def test_section_without_pairing_is_not_available_and_says_how(tmp_path):
    res = _run(_ctx(tmp_path, 20.0, paired=False))
    sec = res["sections"][0]
    assert sec["status"] == "not available"
    assert "--same-sample" in sec["reason"]


def test_section_without_height_map_is_not_available(tmp_path):
    ctx = _ctx(tmp_path, 20.0)
    ctx.height_maps.clear()
    sec = _run(ctx)["sections"][0]
    assert sec["status"] == "not available" and "no height map" in sec["reason"]


def test_map_smaller_than_the_wavelength_says_so_instead_of_a_table(tmp_path):
    ctx = _ctx(tmp_path, 2.0)
    hm = ctx.height_maps[0]
    # the same heights on a 128 x 128 nm map: no period that scatters visible light
    ctx.height_maps[0] = HeightMap(hm.heights, (1e-9, 1e-9), hm.path, "height")
    res = _run(ctx)
    assert "smoothness_S_map_di" not in res["tables"]
    texts = [it["text"] for it in res["sections"][0]["items"] if it["kind"] == "text"]
    assert any("says nothing about their specular loss" in t for t in texts)


def test_rayleigh_flags_mark_rough_angles_of_the_fits_sample(tmp_path):
    ctx = _ctx(tmp_path, 60.0)  # Rayleigh threshold at 400 nm: 57.7 nm (30 deg), 100 (60)
    flags = rayleigh_flags(ctx, ["scan.csv"], 400.0, [30.0, 60.0, 30.0])
    assert flags and all(f.startswith("Rayleigh (map.di): ") for f in flags)
    assert any(f.endswith("at 30 deg") for f in flags)
    assert not any(f == "Rayleigh (map.di): rough at 60 deg" for f in flags)
    assert rayleigh_flags(ctx, ["other.csv"], 400.0, [30.0]) == []
    smooth = _ctx(tmp_path, 5.0)
    assert rayleigh_flags(smooth, ["scan.csv"], 400.0, [30.0, 60.0]) == []


def test_bsdf_tis_of_the_sample_is_set_against_bennett_porteus(tmp_path):
    ctx = _ctx(tmp_path, 20.0)
    bsdf = tmp_path / "v.bsdf"
    ctx.frames.append(
        make_frame(
            sample="v",
            instrument="zemax-bsdf",
            source="v.bsdf",
            quantity="brdf",
            value=[0.1, 0.1],
            unit="sr-1",
            wavelength_nm=555.0,
            theta_i_deg=[15.0, 45.0],
            theta_r_deg=[15.0, 45.0],
            phi_r_deg=180.0,
        )
    )
    tis = [{"theta_i_deg": 15.0, "tis": 0.13}, {"theta_i_deg": 45.0, "tis": 0.11}]
    ctx.files.append({"path": str(bsdf), "samples": ["v"], "meta": {"tis": tis}})
    groups = pair_samples(
        [(Path(ctx.height_maps[0].path), ()), (tmp_path / "refl.csv", "S"), (bsdf, "v")],
        [[ctx.height_maps[0].path, bsdf, tmp_path / "refl.csv"]],
    )
    ctx.samples[:] = groups
    res = _run(ctx)
    rows = res["tables"]["smoothness_tis_S_map_di"]["rows"]
    assert [(r["theta_i"], r["tis"]) for r in rows] == [(15.0, 0.13), (45.0, 0.11)]
    smooth_rows = res["tables"]["smoothness_S_map_di"]["rows"]
    sigma = smooth_rows[0]["sigma_nm"]  # band-limited at 400 nm; at 555 nm its own band
    for r in rows:
        g = r["tis_r0_small"]
        assert g == pytest.approx(
            (4 * math.pi * sigma * math.cos(math.radians(r["theta_i"])) / 555.0) ** 2, rel=0.05
        )
        assert r["tis_r0"] == pytest.approx(1 - math.exp(-g), rel=1e-12)


def test_smooth3_fit_rows_carry_the_rayleigh_flag_of_their_sample(tmp_path, fixtures_dir):
    from labbrdf import read
    from labbrdf.parallel import as_executor
    from labbrdf.report.sections.fits import fits_section

    # sigma 70 +- 2 x 6.5 nm; at 360 nm the thresholds are 52, 64, 90 nm at 30, 45, 60 deg
    ctx = _ctx(tmp_path, 70.0)
    scans = read(fixtures_dir / "specular" / "osr_specular.csv").data
    scans = scans[scans["wavelength_nm"] == 360.0].assign(source="scan.csv", sample="S")
    ctx.frames[1] = scans.reset_index(drop=True)
    ctx.executor = as_executor("serial")
    with ctx.b.section("fits", "t"):
        fits_section(ctx, [("smooth3", {})])
    rows = ctx.b.results["tables"]["fit_smooth3"]["rows"]
    assert len(rows) == 1
    flags = rows[0]["flags"]
    assert "Rayleigh (map.di): rough at 30 deg" in flags
    assert "Rayleigh (map.di): undecided at 45 deg" in flags
    assert "at 60 deg" not in flags


def test_ratio_falls_back_to_a_fitted_film_stack_of_the_sample(tmp_path):
    class Stack:  # stands for a FilmFit: its compare_reflectance, as the film section's
        def compare_reflectance(self, rows: pd.DataFrame) -> pd.DataFrame:
            return pd.DataFrame(
                {
                    "wavelength_nm": rows["wavelength_nm"].to_numpy(float),
                    "theta_i_deg": 0.0,
                    "measured": rows["value"].to_numpy(float),
                    "measured_sigma": np.nan,
                    "predicted": rows["value"].to_numpy(float) / 0.9,
                    "predicted_sigma": 0.0,
                }
            )

    ctx = _ctx(tmp_path, 20.0)
    ctx.film_fits["ell.dat"] = Stack()
    rows = _run(ctx)["tables"]["smoothness_S_map_di"]["rows"]
    assert [r["ratio"] for r in rows] == pytest.approx([0.9] * 4, rel=1e-12)
    assert {r["nk_file"] for r in rows} == {"ell.dat (film stack)"}
    ctx = _ctx(tmp_path, 20.0, nk=True)
    ctx.film_fits["ell.dat"] = Stack()  # bulk n, k first where both exist
    rows = _run(ctx)["tables"]["smoothness_S_map_di"]["rows"]
    assert {r["nk_file"] for r in rows} == {"ell.dat (bulk n, k)"}
