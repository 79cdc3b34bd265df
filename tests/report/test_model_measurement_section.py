"""The validation report's ``model_measurement`` section on the bundled consistent set.

The set (fixtures/predict_measure/) agrees with itself by construction, so its checks must
pass; the tests then break one file at a time and watch the matching check fail.
"""

from __future__ import annotations

import json
import math
import shutil
from pathlib import Path

import pytest

from labbrdf import report
from labbrdf.report.sections.model_measurement import (
    CONTROL_FILE,
    FORMULA_RTOL,
    SET_DIR,
    SET_FILES,
    formula_deviations,
)

pytest.importorskip("SurfaceTopography")

SID = "model_measurement"


def _validate(out: Path, fixtures_dir: Path | None = None) -> tuple[int, dict]:
    code = report.validate(
        out=out, quick=True, progress=False, sections_to_run=[SID], fixtures_dir=fixtures_dir
    )
    return code, json.loads((out / "results.json").read_text(encoding="utf-8"))


def _checks(res: dict) -> dict[str, dict]:
    return {c["id"]: c for c in res["checks"] if c["section"] == SID}


@pytest.fixture(scope="module")
def consistent(tmp_path_factory: pytest.TempPathFactory) -> tuple[int, dict]:
    return _validate(tmp_path_factory.mktemp("mm") / "r")


def test_consistent_set_passes_every_check_of_the_section(consistent):
    code, res = consistent
    sec = {s["id"]: s for s in res["sections"]}[SID]
    assert sec["status"] == "ok", sec["reason"]
    checks = _checks(res)
    assert {c["status"] for c in checks.values()} == {"pass"}, {
        k: c["reason"] for k, c in checks.items() if c["status"] != "pass"
    }
    for cid in (
        "model_measurement.rayleigh_formula",
        "model_measurement.rayleigh_verdicts",
        "model_measurement.specular_loss",
        "model_measurement.bennett_porteus",
        "model_measurement.control_flagged",
    ):
        assert cid in checks
    assert any(k.startswith("prediction.dop.") for k in checks)
    assert any(k.startswith("prediction.brdf.") for k in checks)
    assert code == 0


def test_section_draws_the_user_report_figures_and_tables(consistent):
    _, res = consistent
    figs, tables = set(res["figures"]), set(res["tables"])
    for prefix in ("smoothness_", "prediction_dop_", "prediction_maps_", "prediction_cuts_"):
        assert any(f.startswith(prefix) for f in figs), prefix
    assert any(t.startswith("smoothness_tis_") for t in tables)
    assert {"model_measurement_files", "model_measurement_control", "sample_groups"} <= tables
    (group,) = res["tables"]["sample_groups"]["rows"]
    assert group["n"] == len(SET_FILES) and "SYNTHETIC P1" in group["reason"]


def test_smoothness_rows_span_rough_and_smooth_and_match_the_davies_factor(consistent):
    _, res = consistent
    (tid,) = [t for t in res["tables"] if t.startswith("smoothness_") and "_tis_" not in t]
    rows = res["tables"][tid]["rows"]
    assert {r["rayleigh"] for r in rows} == {"rough", "smooth"}
    for r in rows:
        # g by hand: (4 pi sigma / lambda)^2 at normal incidence
        assert r["theta_i"] == 0.0
        assert r["g"] == pytest.approx((4 * math.pi * r["sigma_nm"] / r["wavelength_nm"]) ** 2)
        assert r["ratio"] == pytest.approx(math.exp(-r["g"]), rel=2e-5)


def test_wrong_index_control_is_a_third_low(consistent):
    _, res = consistent
    c = _checks(res)["model_measurement.control_flagged"]
    assert c["value"] == pytest.approx(0.34, abs=0.01)
    rows = res["tables"]["model_measurement_control"]["rows"]
    assert not all(r["consistent"] for r in rows)


def test_formula_check_catches_a_wrong_number_and_a_wrong_verdict():
    row = {
        "wavelength_nm": 600.0,
        "theta_i": 30.0,
        "sigma_nm": 40.0,
        "u_sigma_nm": 1.0,
        "thr_rayleigh": 600 / (8 * math.cos(math.radians(30))),
        "thr_fraunhofer": 600 / (32 * math.cos(math.radians(30))),
        "rayleigh": "smooth",
        "fraunhofer": "rough",
    }
    g = (4 * math.pi * 40.0 * math.cos(math.radians(30)) / 600.0) ** 2
    row.update(g=g, u_g=2 * g / 40.0, loss=math.exp(-g))
    worst, wrong = formula_deviations([row])
    assert worst <= FORMULA_RTOL and wrong == []
    worst, _ = formula_deviations([{**row, "g": g * (1 + 1e-6)}])
    assert worst > FORMULA_RTOL
    _, wrong = formula_deviations([{**row, "rayleigh": "rough"}])
    assert wrong == ["rayleigh at 600 nm, 30 deg: rough != smooth"]
    # sigma + 2u straddles the Rayleigh threshold (86.6 nm): undecided
    _, wrong = formula_deviations([{**row, "sigma_nm": 85.0, "u_sigma_nm": 1.0}])
    assert "rayleigh at 600 nm, 30 deg: smooth != undecided" in wrong


@pytest.fixture
def fixtures_copy(fixtures_dir: Path, tmp_path: Path) -> Path:
    fx = tmp_path / "fixtures"
    shutil.copytree(fixtures_dir, fx, ignore=shutil.ignore_patterns("__pycache__"))
    return fx


def test_control_with_the_true_index_and_a_wrong_spectrum_fail(fixtures_copy, tmp_path):
    d = fixtures_copy / SET_DIR
    # the "control" now holds the sample's own psi/Delta: the prediction agrees, not flagged
    shutil.copy(d / SET_FILES[1], d / CONTROL_FILE)
    # the spectrum 5 % high at every wavelength: measured / Fresnel is no longer exp(-g)
    spec = d / SET_FILES[2]
    lines = spec.read_bytes().decode("ascii").split("\r\n")
    start = lines.index("#DATA") + 1
    for i in range(start, len(lines)):
        if lines[i]:
            w, v = lines[i].split("\t")
            lines[i] = f"{w}\t{float(v) * 1.05:.6g}"
    spec.write_bytes("\r\n".join(lines).encode("ascii"))
    code, res = _validate(tmp_path / "r", fixtures_copy)
    checks = _checks(res)
    assert checks["model_measurement.control_flagged"]["status"] == "fail"
    assert checks["model_measurement.specular_loss"]["status"] == "fail"
    assert checks["model_measurement.specular_loss"]["value"] == pytest.approx(0.05, rel=1e-3)
    assert checks["model_measurement.rayleigh_formula"]["status"] == "pass"
    assert code == 1


def test_missing_set_makes_the_section_not_available_never_passed(fixtures_copy, tmp_path):
    (fixtures_copy / SET_DIR / SET_FILES[3]).unlink()
    code, res = _validate(tmp_path / "r", fixtures_copy)
    sec = {s["id"]: s for s in res["sections"]}[SID]
    assert sec["status"] == "not available"
    assert SET_FILES[3] in sec["reason"]
    assert [c["status"] for c in _checks(res).values()] == ["skipped"]
    assert code == 0
