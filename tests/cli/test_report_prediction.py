"""``labbrdf report`` end to end with one sample's height map, psi/Delta and ``.bsdf``."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from labbrdf.cli import main

pytest.importorskip("SurfaceTopography")


@pytest.mark.slow
def test_report_predicts_the_paired_sample_and_passes(sample_set: dict, tmp_path: Path) -> None:
    files = [str(sample_set[k]) for k in ("height_map", "psi_delta", "bsdf")]
    out = tmp_path / "rep"
    rc = main(["report", *files, "-o", str(out), "--same-sample", ",".join(files), "--quiet"])
    res = json.loads((out / "results.json").read_text())
    sec = {s["id"]: s for s in res["sections"]}
    assert sec["prediction"]["status"] == "ok"
    checks = [c for c in res["checks"] if c["id"].startswith("prediction.")]
    assert len(checks) == 2 and all(c["status"] == "pass" for c in checks)
    assert rc == 0
    html = (out / "index.html").read_text()
    assert "Predict, then measure" in html and "on the measurement in the specular lobe" in html


def test_report_without_pairing_says_why_there_is_no_prediction(
    sample_set: dict, tmp_path: Path
) -> None:
    # the psi/Delta alone: no height map, no BRDF, so nothing is traced
    out = tmp_path / "rep"
    main(["report", str(sample_set["psi_delta"]), "-o", str(out), "--quiet"])
    res = json.loads((out / "results.json").read_text())
    sec = {s["id"]: s for s in res["sections"]}["prediction"]
    assert sec["status"] != "ok"
    assert "of ONE sample" in json.dumps(sec)
    assert "lacks an areal height map, a .bsdf BRDF" in json.dumps(sec)
