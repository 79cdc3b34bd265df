"""The user report reads its inputs through ``read_inputs``: each file once, by its kind."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from labbrdf import adapters
from labbrdf.adapters import inputs as inputs_mod
from labbrdf.adapters import topography
from labbrdf.report.builder import Builder
from labbrdf.report.context import Context
from labbrdf.report.sections.ingest import ingest_inputs
from labbrdf.surface import gaussian_surface


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


def test_a_file_of_neither_kind_is_an_optical_failure_naming_it(
    tmp_path: Path, fixtures_dir: Path
) -> None:
    wvase = fixtures_dir / "ellipsometry" / "al_bare_wvase.dat"
    junk = tmp_path / "junk.dat"
    junk.write_text("nothing here\n")
    ctx, res = _ingested([wvase, junk])
    rows = {r["file"]: r for r in res["tables"]["ingested_files"]["rows"]}
    assert rows["junk.dat"]["status"] == "error"
    assert rows["junk.dat"]["error"].startswith(str(junk))
    assert "ingested_height_maps" not in res["tables"]
    (check,) = [c for c in res["checks"] if c["id"] == "ingest.read"]
    assert check["status"] == "fail" and "junk.dat" in check["reason"]


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
