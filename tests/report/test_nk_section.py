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
