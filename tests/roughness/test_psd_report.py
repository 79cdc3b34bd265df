"""Section ``psd``: one part per sample group with maps, its figure and tables."""

from __future__ import annotations

from pathlib import Path

import pytest

from labbrdf.adapters.topography import HeightMap
from labbrdf.report.builder import Builder, Unavailable
from labbrdf.report.context import Context
from labbrdf.report.html import render
from labbrdf.report.sections.psd import psd_section
from labbrdf.samples import pair_samples

KC = (2e-28, 3e-6, 2.4)


def _ctx(tmp_path: Path, synth, *, loose: bool = True) -> Context:
    fine = tmp_path / "afm.txt"
    coarse = tmp_path / "wli.txt"
    other = tmp_path / "other.txt"
    ctx = Context(Builder("t"))
    ctx.height_maps += [
        HeightMap(synth.surface("k-correlation", KC, 64, 1e-7, 1), (1e-7, 1e-7), str(fine), "h"),
        HeightMap(synth.surface("k-correlation", KC, 64, 4e-7, 2), (4e-7, 4e-7), str(coarse), "h"),
    ]
    files = [fine, coarse]
    if loose:
        z = synth.surface("exponential", (1e-9, 1e-6), 64, 1e-7, 3)
        ctx.height_maps.append(HeightMap(z, (1e-7, 1e-7), str(other), "h"))
        files.append(other)
    ctx.samples[:] = pair_samples([(p, ()) for p in files], [[fine, coarse]], given_as="given")
    return ctx


def test_one_part_per_group_with_figure_and_tables(tmp_path, synth):
    ctx = _ctx(tmp_path, synth)
    with ctx.b.section("psd", "Surface power spectral density"):
        psd_section(ctx)
    sec = ctx.b.results["sections"][-1]
    assert sec["status"] == "ok"
    headings = [i["text"] for i in sec["items"] if i["kind"] == "heading"]
    assert len(headings) == 2 and "PSD of 2 map(s)" in headings[0]
    tables = ctx.b.results["tables"]
    bands = [t for tid, t in tables.items() if tid.startswith("psd_bands_")]
    fits = [t for tid, t in tables.items() if tid.startswith("psd_fit_")]
    assert len(bands) == 2 and len(fits) == 2
    assert [r["param"] for r in fits[0]["rows"]] == ["A", "B", "C"]
    assert len([f for f in ctx.b.images if f.startswith("psd_")]) == 2
    notes = [i["text"] for i in sec["items"] if i["kind"] == "note"]
    assert any("agree over" in n for n in notes)  # the two magnifications overlap
    ctx.b.finish()
    page = render(ctx.b.results, ctx.b.images)
    (tmp_path / "page.html").write_text(page, encoding="utf-8")
    assert "Band of each map" in page and "k-correlation fit over" in page


def test_unavailable_without_maps(tmp_path):
    ctx = Context(Builder("t"))
    with pytest.raises(Unavailable, match="no height map"):
        psd_section(ctx)
