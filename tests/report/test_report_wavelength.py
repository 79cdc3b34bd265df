"""`report --wavelength NM`: files that state no wavelength get it; placeholders are said."""

from __future__ import annotations

from pathlib import Path

import pytest

import labbrdf
from labbrdf.cli import main
from labbrdf.report.builder import Builder
from labbrdf.report.context import Context
from labbrdf.report.inputs import ingest_inputs
from labbrdf.report.sections.smoothness import _tis_rows
from labbrdf.report.user import _given_wavelength
from labbrdf.samples import SampleGroup
from labbrdf.writers.zemax import model_to_bsdf


def _bsdf(path: Path, wavelength: float | None = None) -> Path:
    model_to_bsdf(labbrdf.models.get("smooth3"), {"k1": 0.5, "k2": 0.0, "k3": 0.2}, path,
                  theta_i_deg=[20], radial_deg=range(0, 41, 8), azimuth_deg=[0, 180],
                  wavelength_nm=wavelength)  # fmt: skip
    return path


def _ingested(paths: list[Path], wl: float | None) -> Context:
    ctx = Context(Builder("t", progress=False), wavelength_nm=wl)
    with ctx.b.section("ingest", "Ingested files"):
        ingest_inputs(ctx, paths)
        if wl is not None:
            _given_wavelength(ctx, wl)
    return ctx


def test_the_given_wavelength_goes_to_files_that_state_none(tmp_path: Path):
    label, stated = _bsdf(tmp_path / "label.bsdf"), _bsdf(tmp_path / "stated.bsdf", 450.0)
    ctx = _ingested([label, stated], 633.0)
    rows = {f["source"].iloc[0]: set(f["wavelength_nm"]) for f in ctx.frames}
    assert rows == {"label.bsdf": {633.0}, "stated.bsdf": {450.0}}
    meta = {r["file"]: r["meta"] for r in ctx.files}
    assert meta["label.bsdf"]["wavelength_given"] and meta["label.bsdf"]["wavelength_stated"]
    text = str(ctx.b.results)
    assert "633 nm, for the files that state none (label.bsdf)" in text
    assert "the others keep their own (stated.bsdf)" in text


def test_smoothness_says_when_a_wavelength_is_a_placeholder(tmp_path: Path):
    label = _bsdf(tmp_path / "label.bsdf")
    for wl, compared in ((None, False), (633.0, True)):
        ctx = _ingested([label], wl)
        group = SampleGroup("s", (label,), "given")
        with ctx.b.section("smoothness", "Smoothness"):
            rows = _tis_rows(ctx, group, _FakeMap(), ctx.frames[0])
        said = "give it with labbrdf report --wavelength NM" in str(ctx.b.results)
        assert bool(rows) is compared and said is not compared


class _FakeMap:
    """What the smoothness judge reads of a map: its name, sigma in a band, u_rel."""

    name = "map"
    u_rel = 0.1

    def sigma_for(self, shortest_nm: float) -> tuple[float, float]:
        return 2.0, 1.0  # sigma [nm] and the band's coverage


def test_report_wavelength_must_be_a_number(tmp_path: Path, capsys):
    label = _bsdf(tmp_path / "label.bsdf")
    with pytest.raises(SystemExit) as exit_:  # argparse's own usage error: exit 2
        main(["report", str(label), "-o", str(tmp_path / "r"), "--wavelength", "x"])
    assert exit_.value.code == 2
    err = capsys.readouterr().err
    assert "--wavelength" in err and "Traceback" not in err


@pytest.mark.shared
def test_the_shared_bsdf_gets_the_given_wavelength(real_exports):
    f = real_exports / "zemax-bsdf" / "test_13_planesymmetric_brdf_zemax.bsdf"
    assert labbrdf.read(f).meta["wavelength_stated"] is False
    ctx = _ingested([f], 532.0)
    assert set(ctx.frames[0]["wavelength_nm"]) == {532.0}
