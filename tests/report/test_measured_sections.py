"""The user report on real instrument exports: measured figures, optical constants, headline."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from labbrdf import adapters, nk
from labbrdf.dataset import Measurement, make_frame, write_csv
from labbrdf.report.builder import headline
from labbrdf.report.user import user_report

TA = "woollam-wvase-ascii/w2_10102006.dat"
EP4 = "accurion-ep4-dat/15-1-1.dat"
JASCO = "jasco-spectramanager-text/uvvis_abs.txt"
MUELLER = "sentech-spectraray-ascii/Wafer_MM_70.txt"
RP = "woollam-wvase-ascii/ta2o5_02262007_rp.dat"
MAP = "accurion-ep4-dat/post synthesis.dat"


def _report(paths: list[Path], out: Path, **kw: Any) -> dict:
    code = user_report(paths, "smooth3", out, progress=False, **kw)
    res = json.loads((out / "results.json").read_text())
    assert code == res["summary"]["exit_code"]
    return res


def _figures_of(res: dict, source: str) -> list[str]:
    return [
        fid
        for fid, f in res["figures"].items()
        if fid.startswith("measured_") and f["title"].startswith(source + ":")
    ]


@pytest.fixture(scope="module")
def few(real_exports: Path, tmp_path_factory: pytest.TempPathFactory) -> dict:
    out = tmp_path_factory.mktemp("few") / "rep"
    paths = [real_exports / p for p in (TA, EP4, JASCO, MUELLER, RP, MAP)]
    return _report(paths, out)


def test_one_figure_per_file_and_quantity_group(few: dict) -> None:
    assert _figures_of(few, "w2_10102006.dat") == ["measured_0_w2_10102006_dat_ellipsometric"]
    assert any(f.endswith("_spectra") for f in _figures_of(few, "uvvis_abs.txt"))
    assert any(f.endswith("_mueller") for f in _figures_of(few, "Wafer_MM_70.txt"))
    assert any(f.endswith("_spectra") for f in _figures_of(few, "ta2o5_02262007_rp.dat"))
    assert _figures_of(few, "15-1-1.dat")
    # post synthesis has 32 stage positions: maps of psi and Delta
    ep4 = _figures_of(few, "post synthesis.dat")
    assert any("_map_psi" in f for f in ep4) and any("_map_delta" in f for f in ep4)
    check = next(c for c in few["checks"] if c["id"] == "measured.figures")
    assert check["status"] == "pass"


def test_nk_of_tantalum_near_500_nm(few: dict) -> None:
    sec = {s["id"]: s for s in few["sections"]}
    assert sec["nk"]["status"] == "ok"
    row = next(r for r in few["tables"]["nk_summary"]["rows"] if r["file"] == "w2_10102006.dat")
    assert abs(row["wl_500"] - 500) < 5
    assert row["n_500"] == pytest.approx(2.3, abs=0.1)
    assert row["k_500"] == pytest.approx(3.0, abs=0.1)
    # the per-wavelength table is in results.json
    t = few["tables"]["nk_0_w2_10102006_dat"]["rows"]
    near = min(t, key=lambda r: abs(r["wavelength_nm"] - 500))
    assert near["n"] == pytest.approx(2.3, abs=0.1) and near["k"] == pytest.approx(3.0, abs=0.1)


def test_no_colour_from_polarised_ellipsometer_reflectance(few: dict) -> None:
    c = next(c for c in few["checks"] if c["id"].startswith("colour.ta2o5"))
    assert c["status"] == "skipped" and "single-polarisation" in c["reason"]
    assert "colour" not in few["tables"] or all(
        "ta2o5" not in r["source"] for r in few["tables"]["colour"]["rows"]
    )


def test_reflectance_comparison_with_a_spectrophotometer(
    real_exports: Path, tmp_path: Path
) -> None:
    ta = adapters.read(real_exports / TA)
    comb = nk.combined_table(ta)
    comb = comb[(comb["wavelength_nm"] > 400) & (comb["wavelength_nm"] < 800)]
    wl = np.arange(410.0, 790.0, 10.0)
    n = np.interp(wl, comb["wavelength_nm"], comb["n"])
    k = np.interp(wl, comb["wavelength_nm"], comb["k"])
    r = (((n - 1) ** 2 + k**2) / ((n + 1) ** 2 + k**2)).astype(float)
    frame = make_frame(
        sample="Ta spectro",
        instrument="synthetic",
        source="ta_spectro.csv",
        quantity="reflectance",
        value=r,
        sigma=0.005,
        unit="1",
        wavelength_nm=wl,
    )
    spectro = tmp_path / "ta_spectro.csv"
    write_csv(Measurement(frame, {}), spectro)
    # the two files state different sample names: paired by the mapping
    pair = [real_exports / TA, spectro]
    res = _report(pair, tmp_path / "rep", same_sample=[pair])
    rows = res["tables"]["nk_reflectance_comparison"]["rows"]
    assert len(rows) == 1 and rows[0]["refl_file"] == "ta_spectro.csv"
    assert rows[0]["points"] == len(wl)
    assert abs(rows[0]["mean_diff"]) < 0.01
    chk = next(c for c in res["checks"] if c["id"].startswith("nk.reflectance.x0"))
    assert chk["status"] == "pass"
    # a spectrophotometer reflectance gives a colour
    assert res["tables"]["colour"]["rows"][0]["source"] == "ta_spectro.csv"


def test_headline_of_only_skipped_checks_does_not_say_pass(
    real_exports: Path, tmp_path: Path
) -> None:
    res = _report([real_exports / JASCO], tmp_path / "rep")
    assert res["summary"]["headline"].startswith("nothing checked")
    page = (tmp_path / "rep" / "index.html").read_text()
    top = page[page.index('id="summary"') : page.index("</div>", page.index('id="summary"'))]
    assert "pass" not in top.lower().replace('class="', "")
    assert "nothing checked" in top
    assert headline([{"status": "pass"}, {"status": "skipped"}]) == (
        "1 check passed, 0 failed, 1 not applicable"
    )


@pytest.mark.slow
def test_all_real_exports_in_one_report(real_exports: Path, tmp_path: Path) -> None:
    files = sorted(
        p
        for p in real_exports.rglob("*")
        if p.is_file()
        and p.suffix != ".md"
        and "topography" not in p.relative_to(real_exports).parts
    )
    res = _report(files, tmp_path / "rep")
    read = [r["file"] for r in res["tables"]["ingested_files"]["rows"] if r["status"] == "read"]
    assert read
    for name in read:
        assert _figures_of(res, Path(name).name), f"no figure for {name}"
    assert "pass" not in res["summary"]["headline"].split(",")[0] or res["summary"]["pass"] > 1


def test_ellipsometer_intensity_is_not_fitted_as_brdf(real_exports: Path, tmp_path: Path) -> None:
    res = _report(
        [real_exports / "woollam-completeease-ascii/Woolam_staticTest.dat"], tmp_path / "rep"
    )
    fits = next(s for s in res["sections"] if s["id"] == "fits")
    assert fits["status"] == "not available" and "no BRDF fit" in fits["reason"]
    assert res["summary"]["exit_code"] == 0
    assert any(f.endswith("_spectra") for f in res["figures"])  # uR and depolarisation drawn
