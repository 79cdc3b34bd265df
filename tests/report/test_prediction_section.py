"""The ``prediction`` section: tracer prediction beside a measured BRDF, per sample."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from labbrdf.report.builder import Builder, Unavailable
from labbrdf.report.context import Context
from labbrdf.report.inputs import ingest_inputs
from labbrdf.report.pairing import sample_groups
from labbrdf.report.sections.prediction import prediction_section

pytest.importorskip("SurfaceTopography")


def _run(paths: list[Path], same_sample: list[list[Path]]) -> dict:
    """Ingest, pair and run the section alone (the rest of the report is not needed)."""
    b = Builder("t", progress=False)
    ctx = Context(b)
    with b.section("ingest", "Ingested files"):
        ingest_inputs(ctx, paths)
        sample_groups(ctx, paths, same_sample)
    with b.section("prediction", "Predict, then measure"):
        prediction_section(ctx)
    b.finish()
    return b.results


def _section(res: dict) -> dict:
    return {s["id"]: s for s in res["sections"]}["prediction"]


def _texts(res: dict) -> list[str]:
    return [it["text"] for it in _section(res)["items"] if it["kind"] in ("text", "note")]


@pytest.fixture(scope="module")
def two_samples(sample_set: dict, tmp_path_factory: pytest.TempPathFactory) -> dict:
    """Sample A (consistent files) and sample B (its psi/Delta of the wrong index)."""
    d = tmp_path_factory.mktemp("two")
    a = [
        shutil.copy(sample_set[k], d / Path(sample_set[k]).name)
        for k in ("height_map", "psi_delta", "bsdf")
    ]
    b = [
        shutil.copy(sample_set["height_map"], d / "b_heights.nc"),
        shutil.copy(sample_set["psi_delta_wrong"], d / "b_psi.dat"),
        shutil.copy(sample_set["bsdf"], d / "b.bsdf"),
    ]
    a, b = [Path(p) for p in a], [Path(p) for p in b]
    return {"a": a, "b": b, "res": _run(a + b, [a, b])}


def test_each_sample_gets_its_figures_tables_and_sentence(two_samples: dict) -> None:
    res = two_samples["res"]
    assert _section(res)["status"] == "ok"
    figs = [f for f in res["figures"] if f.startswith("prediction_")]
    assert sum(f.startswith("prediction_dop_") for f in figs) == 2
    assert sum(f.startswith("prediction_maps_") for f in figs) == 2
    assert sum(f.startswith("prediction_cuts_") for f in figs) == 2
    tis = [t for t in res["tables"] if t.startswith("prediction_tis_")]
    assert len(tis) == 2
    texts = _texts(res)
    assert any("on the measurement in the specular lobe" in t for t in texts)
    assert any("34 % low in the specular lobe" in t for t in texts)


def test_checks_pass_for_the_right_index_and_fail_for_the_wrong_one(two_samples: dict) -> None:
    checks = {c["id"]: c for c in two_samples["res"]["checks"] if c["id"].startswith("prediction")}
    brdf = {k: c["status"] for k, c in checks.items() if k.startswith("prediction.brdf.")}
    assert sorted(brdf.values()) == ["fail", "pass"]
    (bad,) = [c for c in checks.values() if c["status"] == "fail"]
    assert "b_bsdf" in bad["id"] and bad["value"] == pytest.approx(0.34, abs=0.01)
    # the DOP of a bare substrate depends on its own n, k only: both agree
    assert all(c["status"] == "pass" for k, c in checks.items() if k.startswith("prediction.dop."))


def test_tis_table_compares_like_with_like(two_samples: dict) -> None:
    res = two_samples["res"]
    rows = [
        r for t, v in res["tables"].items() if t.startswith("prediction_tis_") for r in v["rows"]
    ]
    ratios = sorted(r["ratio"] for r in rows)
    assert ratios[0] == pytest.approx(0.661, abs=0.002)
    assert ratios[1] == pytest.approx(1.0, abs=1e-5)
    for r in rows:
        assert r["tis_file"] == pytest.approx(r["tis_measured"], rel=1e-5)


def test_files_not_paired_are_not_predicted(sample_set: dict) -> None:
    paths = [Path(sample_set[k]) for k in ("height_map", "psi_delta", "bsdf")]
    with pytest.raises(Unavailable, match=r"of ONE sample .*lacks an areal height map"):
        b = Builder("t", progress=False)
        ctx = Context(b)
        with b.section("ingest", "x"):
            ingest_inputs(ctx, paths)
            sample_groups(ctx, paths, [])
        prediction_section(ctx)


def test_a_group_lacking_a_file_is_listed_with_what_it_lacks(two_samples: dict) -> None:
    a, b = two_samples["a"], two_samples["b"]
    res = _run(a + b[:2], [a, b[:2]])
    rows = res["tables"]["prediction_not_predicted"]["rows"]
    assert rows == [
        {
            "sample": rows[0]["sample"],
            "files": "b_heights.nc, b_psi.dat",
            "missing": "a .bsdf BRDF",
        }
    ]


def test_a_bsdf_without_wavelength_gets_a_note(two_samples: dict, tmp_path: Path) -> None:
    a = two_samples["a"]
    nowl = tmp_path / "nowl.bsdf"
    nowl.write_text(a[2].read_text().replace("#labbrdf wavelength_nm", "#x", 1))
    files = [a[0], a[1], nowl]
    res = _run(files, [files])
    assert any("nowl.bsdf: the file states no wavelength" in t for t in _texts(res))
    assert not any(t.startswith("prediction_maps_") for t in res["figures"])
    assert any(t.startswith("prediction_dop_") for t in res["figures"])  # the DOP still runs


def test_a_stack_psi_delta_gets_notes_not_a_traceback(two_samples: dict, tmp_path: Path) -> None:
    a = two_samples["a"]
    lines = a[1].read_bytes().decode().split("\r\n")
    # 75 deg psi shifted by 2 deg: the angles disagree, a stack's pseudo-constants
    out = lines[:4] + [
        "\t".join([*f.split("\t")[:2], str(float(f.split("\t")[2]) + 2.0), *f.split("\t")[3:]])
        if f.split("\t")[1].startswith("75")
        else f
        for f in lines[4:]
    ]
    stack = tmp_path / "stack.dat"
    stack.write_bytes("\r\n".join(out).encode())
    files = [a[0], stack, a[2]]
    res = _run(files, [files])
    notes = [it for it in _section(res)["items"] if it["kind"] == "note"]
    assert len(notes) == 2 and all("stack" in n["text"] for n in notes)


def test_extra_files_of_a_sample_are_named_as_not_used(two_samples: dict) -> None:
    a, b = two_samples["a"], two_samples["b"]
    files = [a[0], a[1], b[1], a[2]]
    res = _run(files, [files])
    assert any(
        "Not used (the first height map and psi/Delta file are): b_psi.dat" in t
        for t in _texts(res)
    )
    checks = [c for c in res["checks"] if c["id"].startswith("prediction.brdf.")]
    assert [c["status"] for c in checks] == ["pass"]  # predicted from a_psi.dat, the first


def test_two_inputs_of_one_name_are_not_told_apart(two_samples: dict, tmp_path: Path) -> None:
    a = two_samples["a"]
    other = tmp_path / "x"
    other.mkdir()
    twin = Path(shutil.copy(two_samples["b"][1], other / a[1].name))  # same name, other index
    files = [a[0], a[1], twin, a[2]]
    res = _run(files, [files])
    assert _section(res)["status"] != "ok"
    assert "lacks a psi/Delta file" in json.dumps(_section(res))
