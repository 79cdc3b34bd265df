"""``labbrdf report --same-sample``: the groups in the ingest section, and every refusal."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from labbrdf.cli import main
from labbrdf.dataset import Measurement, make_frame, write


def _dataset(path: Path, sample: str) -> Path:
    m = Measurement(
        make_frame(
            sample=sample,
            instrument="synthetic",
            source=path.name,
            quantity="reflectance",
            value=np.linspace(0.90, 0.95, 6),
            unit="1",
            wavelength_nm=np.linspace(400.0, 900.0, 6),
            theta_i_deg=8.0,
        ),
        {},
    )
    write(m, path)
    return path


@pytest.fixture
def three(tmp_path: Path) -> list[Path]:
    return [
        _dataset(tmp_path / "a.parquet", "Al-7"),
        _dataset(tmp_path / "b,2.parquet", "Al-7"),  # a comma in the name
        _dataset(tmp_path / "c.parquet", "Au-1"),
    ]


def _groups(out: Path) -> list[dict]:
    return json.loads((out / "results.json").read_text())["tables"]["sample_groups"]["rows"]


def test_report_pairs_files_by_stated_sample_name(three, tmp_path):
    out = tmp_path / "rep"
    assert main(["report", *map(str, three), "-o", str(out), "--quiet"]) == 0
    rows = _groups(out)
    assert [(r["sample"], r["files"]) for r in rows] == [
        ("Al-7", "a.parquet, b,2.parquet"),
        ("Au-1", "c.parquet"),
    ]
    assert rows[0]["reason"] == "sample name 'Al-7' in a.parquet and b,2.parquet"
    assert "Files grouped by sample" in (out / "index.html").read_text()


def test_report_same_sample_joins_files_with_the_reason(three, tmp_path):
    out = tmp_path / "rep"
    a, b, c = map(str, three)
    code = main(["report", a, b, c, "-o", str(out), "--quiet", "--same-sample", f"{c},{b}"])
    assert code == 0
    rows = _groups(out)
    assert len(rows) == 1 and rows[0]["n"] == 3
    assert "given with --same-sample (c.parquet and b,2.parquet)" in rows[0]["reason"]
    assert "sample name 'Al-7' in a.parquet and b,2.parquet" in rows[0]["reason"]


def test_report_same_sample_path_not_an_input_exits_2(three, tmp_path, capsys):
    out = tmp_path / "rep"
    other = tmp_path / "other.parquet"
    code = main(
        ["report", *map(str, three[:2]), "-o", str(out), "--same-sample", f"{three[0]},{other}"]
    )
    assert code == 2
    err = capsys.readouterr().err
    assert "other.parquet is not among the input files" in err
    assert "Traceback" not in err
    assert not out.exists()


def test_report_file_in_two_same_sample_groups_exits_2(three, tmp_path, capsys):
    a, b, c = map(str, three)
    code = main(
        [
            "report", a, b, c, "-o", str(tmp_path / "rep"),
            "--same-sample", f"{a},{c}", "--same-sample", f"{c},{b}",
        ]
    )  # fmt: skip
    assert code == 2
    assert "c.parquet is in same-sample groups 1 and 2" in capsys.readouterr().err


def test_report_same_sample_of_one_file_exits_2(three, tmp_path, capsys):
    code = main(["report", str(three[0]), "-o", str(tmp_path / "r"), "--same-sample", "a.x"])
    assert code == 2
    assert "expected two or more files" in capsys.readouterr().err


def test_report_groups_the_names_contradict_fail_a_check(three, tmp_path):
    # a and b state 'Al-7': the user's two groups (a, c) and (b, d) are one sample
    d = _dataset(tmp_path / "d.parquet", "Cu-2")
    a, b, c = three
    out = tmp_path / "rep"
    code = main(
        [
            "report", *map(str, (a, b, c, d)), "-o", str(out), "--quiet",
            "--same-sample", f"{a},{c}", "--same-sample", f"{b},{d}",
        ]
    )  # fmt: skip
    assert code == 1
    res = json.loads((out / "results.json").read_text())
    check = next(c for c in res["checks"] if c["id"] == "ingest.samples")
    assert check["status"] == "fail"
    assert "'Al-7' in a.parquet and b,2.parquet" in check["reason"]
    assert "sample_groups" not in res["tables"]


@pytest.mark.shared
def test_report_smoothness_section_for_a_real_map_paired_with_real_reflectance(
    real_exports, tmp_path, capsys
):
    pytest.importorskip("SurfaceTopography")
    profile = real_exports / "topography" / "opdx-3.opdx"  # Dektak, 50 um, 16.7 nm pitch
    refl = real_exports / "jasco-jws-binary" / "uvvis_refl.jws"  # JASCO V-730 reflectance
    out = tmp_path / "rep"
    args = ["report", str(profile), str(refl), "-o", str(out), "--quiet"]
    assert main([*args, "--same-sample", f"{refl},{profile}"]) == 0
    res = json.loads((out / "results.json").read_text())
    sec = {s["id"]: s for s in res["sections"]}
    assert sec["smoothness"]["status"] == "ok"
    rows = res["tables"]["smoothness_test_opdx_3_opdx"]["rows"]
    assert rows and {r["coverage"] for r in rows} == {"band-limited"}
    for r in rows:
        lam = r["wavelength_nm"]
        assert r["g"] == pytest.approx((4 * math.pi * r["sigma_nm"] / lam) ** 2, rel=1e-12)
        assert r["rayleigh"] in ("smooth", "rough", "undecided")
    html = (out / "index.html").read_text()
    assert "Roughness against wavelength" in html
    # without the mapping nothing pairs the two files: the section says how to pair them
    out2 = tmp_path / "rep2"
    assert main(["report", str(profile), str(refl), "-o", str(out2), "--quiet"]) == 0
    res2 = json.loads((out2 / "results.json").read_text())
    sec2 = {s["id"]: s for s in res2["sections"]}["smoothness"]
    assert sec2["status"] == "not available" and "--same-sample" in sec2["reason"]
