"""The user report reads its inputs through ``read_inputs``: each file once, by its kind."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest

from labbrdf import adapters
from labbrdf.adapters import inputs as inputs_mod
from labbrdf.adapters import topography
from labbrdf.report.builder import Builder
from labbrdf.report.context import Context
from labbrdf.report.inputs import ingest_inputs
from labbrdf.roughness.synthetic import gaussian_surface


def write_bcrf(path: Path, n: int = 32) -> Path:
    """A BCR-STM float file (SurfaceTopography's ``bcrf``): heights [nm], 32 x 32 um."""
    z = np.asarray(gaussian_surface(n, float(n), 100.0, 4.0, rng=5).z, dtype="<f4")
    hdr = (
        f"fileformat = bcrf\nheadersize = 2048\nxpixels = {n}\nypixels = {n}\n"
        f"xlength = {float(n)!r}\nylength = {float(n)!r}\nxunit = um\nyunit = um\n"
        "zunit = nm\nintelmode = 1\n"
    )
    path.write_bytes(hdr.encode().ljust(2048, b" ") + z.tobytes())
    return path


@pytest.fixture
def counted(monkeypatch: pytest.MonkeyPatch) -> dict[str, int]:
    """Calls of every optical parser and of the height-map reader, by file name."""
    calls: dict[str, int] = {}

    def counting(fn):
        def wrapped(path, *a, **kw):
            calls[Path(path).name] = calls.get(Path(path).name, 0) + 1
            return fn(path, *a, **kw)

        return wrapped

    for name, f in list(adapters.READERS.items()):
        monkeypatch.setitem(adapters.READERS, name, dataclasses.replace(f, read=counting(f.read)))
    monkeypatch.setattr(inputs_mod, "read_height_map", counting(topography.read_height_map))
    return calls


def _ingested(paths: list[Path]) -> tuple[Context, dict]:
    b = Builder("t")
    ctx = Context(b)
    with b.section("ingest", "Ingested files"):
        ingest_inputs(ctx, paths)
    return ctx, b.results


def test_the_report_reads_each_input_once_by_its_kind(
    tmp_path: Path, fixtures_dir: Path, counted: dict[str, int]
) -> None:
    pytest.importorskip("SurfaceTopography")
    wvase = fixtures_dir / "ellipsometry" / "al_bare_wvase.dat"
    hm = write_bcrf(tmp_path / "afm.bcrf")
    ctx, res = _ingested([wvase, hm])
    assert counted == {wvase.name: 1, hm.name: 1}
    assert len(ctx.frames) == 1 and len(ctx.height_maps) == 1
    assert [r["file"] for r in res["tables"]["ingested_files"]["rows"]] == [wvase.name]
    (row,) = res["tables"]["ingested_height_maps"]["rows"]
    assert row["file"] == hm.name and row["points"] == "32 x 32" and row["size_um"] == "32 x 32"


def test_a_file_of_neither_kind_is_named_as_unreadable_and_left_out(
    tmp_path: Path, fixtures_dir: Path
) -> None:
    wvase = fixtures_dir / "ellipsometry" / "al_bare_wvase.dat"
    junk = tmp_path / "junk.dat"
    junk.write_text("nothing here\n")
    ctx, res = _ingested([wvase, junk])
    assert [r["file"] for r in res["tables"]["ingested_files"]["rows"]] == [wvase.name]
    assert "ingested_height_maps" not in res["tables"]
    (check,) = [c for c in res["checks"] if c["id"] == "ingest.unreadable"]
    assert check["status"] == "fail" and str(junk) in check["reason"]
    (note,) = [i for s in res["sections"] for i in s["items"] if i["kind"] == "note"]
    assert str(junk) in note["text"]


@pytest.mark.shared
def test_a_metropro_dat_is_parsed_once_as_a_height_map(
    real_exports: Path, counted: dict[str, int]
) -> None:
    pytest.importorskip("SurfaceTopography")
    mp = real_exports / "topography" / "metropro-1.dat"
    ctx, _ = _ingested([mp])
    assert counted == {mp.name: 1}  # no optical parser tried it first
    (hm,) = ctx.height_maps
    assert hm.heights.shape == (640, 480)


def _nms(path: Path, cut: int = 0) -> Path:
    """A Nanofocus .nms (3468-byte header, uint16 heights), ``cut`` bytes short."""
    hdr = bytearray(3468)
    hdr[16:32] = np.array([-2.3, 4.1], "<f8").tobytes()  # z range [um]
    hdr[1368:1392] = np.array([64, 64], "<u4").tobytes() + np.full(2, 312.5e-6).tobytes()
    data = bytes(hdr) + np.arange(64 * 64, dtype="<u2").tobytes()
    path.write_bytes(data[: len(data) - cut])
    return path


def _report(tmp_path: Path, name: str, paths: list[Path], **kw) -> dict:
    from labbrdf.report import user_report

    code = user_report(paths, "smooth3", tmp_path / name, progress=False, **kw)
    res = json.loads((tmp_path / name / "results.json").read_text())
    res["code"] = code
    return res


def _notes(res: dict) -> list[str]:
    items = [i for s in res["sections"] for i in s["items"]]
    return [i["text"] for i in items if i["kind"] == "note" and i["label"] == "not read"]


@pytest.mark.parametrize("how", ["refused", "reader bug"])
def test_an_unreadable_file_leaves_the_rest_of_the_report_as_without_it(
    tmp_path: Path, fixtures_dir: Path, monkeypatch: pytest.MonkeyPatch, how: str
) -> None:
    """The tables of [good + bad] are those of [good] alone; a note and a check name the bad
    file and the reason (before: a failed row in the tables, or, for a reader's IndexError,
    a report with no table at all)."""
    pytest.importorskip("SurfaceTopography")
    good = fixtures_dir / "ellipsometry" / "al_bare_wvase.dat"
    alone = _report(tmp_path, "alone", [good])
    bad = _nms(tmp_path / "conf.nms", cut=1000)
    if how == "reader bug":
        bad = _nms(tmp_path / "conf.nms")

        def broken(path, *a, **kw):
            raise IndexError("list index out of range")

        monkeypatch.setattr(inputs_mod, "read_height_map", broken)
    both = _report(tmp_path, "both", [good, bad], same_sample=[[good, bad]])
    assert both["tables"] == alone["tables"] and alone["tables"]["ingested_files"]["rows"]
    reason = "too small" if how == "refused" else "unexpected IndexError"
    (note,) = _notes(both)
    assert str(bad) in note and reason in note
    c = {x["id"]: x for x in both["checks"]}
    assert (
        c["ingest.unreadable"]["status"] == "fail" and str(bad) in c["ingest.unreadable"]["reason"]
    )
    assert both["code"] == 1 and alone["code"] == 0
    rest = {k: v["status"] for k, v in c.items() if k != "ingest.unreadable"}
    assert rest == {x["id"]: x["status"] for x in alone["checks"]}


def test_a_start_value_outside_its_bounds_is_refused_before_any_work(
    tmp_path: Path, specular_scan: Path
) -> None:
    from labbrdf.cli import main
    from labbrdf.report import user_report

    out = tmp_path / "r"
    with pytest.raises(
        ValueError, match=r"start: model 'microfacet': scale=30 is outside its bounds"
    ):
        user_report(
            [specular_scan],
            "microfacet",
            out,
            options={"ideal_mirror": True},
            start={"scale": 30.0},
            progress=False,
        )
    assert not out.exists()
    argv = ["report", str(specular_scan), "--model", "microfacet", "--param", "ideal_mirror=true"]
    argv += ["--param", "scale=30"]
    assert main([*argv, "-o", str(out)]) == 2
    assert not out.exists()
