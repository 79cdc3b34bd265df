"""Section film: the film model is fitted to its sample's files only, never to its substrate's.

The model's substrate may be a bare wafer's ellipsometer file among the report's inputs;
its psi/Delta are a bare substrate's, and a film fitted to them (thickness at a bound, A
undetermined) is no sample's film.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from labbrdf import films
from labbrdf.cli import main
from labbrdf.nk import tabulated_from_file
from labbrdf.report.builder import Builder
from labbrdf.report.context import Context
from labbrdf.report.inputs import ingest_inputs
from labbrdf.report.pairing import sample_groups
from labbrdf.report.sections.film import _applies_to, _flagged
from labbrdf.samples import pair_samples

TABLE = "# wavelength_nm n k\n300 3.9 0.02\n1000 3.6 0.01\n"


def _model(substrate: Path) -> films.FilmModel:
    stack = films.Stack([films.Layer("sio2", 100.0, "film")], films.as_material(
        {"model": "tabulated", "file": str(substrate)}, tabulated_from_file))  # fmt: skip
    return films.FilmModel(stack, {"film.thickness_nm": (0.0, 300.0)})


def _ctx(paths: list[Path], same: list[list[Path]] = ()) -> Context:
    ctx = Context(Builder("t", progress=False))
    ctx.samples = pair_samples(paths, same)
    return ctx


def _flag(*names: str) -> list:
    """Flagged files as section film lists them (rows and verdict unused by the rule)."""
    return [(n, None, None) for n in names]


@pytest.fixture
def files(tmp_path: Path) -> dict[str, Path]:
    out = {}
    for name in ("coated.dat", "bare.dat", "other.dat"):
        out[name] = tmp_path / name
        out[name].write_text(TABLE)
    return out


def _apply(ctx: Context, model, flagged: list, film_files) -> list:
    with ctx.b.section("film", "Film stacks"):
        return _applies_to(ctx, model, flagged, film_files)


def _names(kept: list) -> list[str]:
    return [s for s, _g, _v in kept]


def test_the_substrate_file_is_never_fitted(files):
    ctx = _ctx(list(files.values()))
    kept = _apply(ctx, _model(files["bare.dat"]), _flag("coated.dat", "bare.dat"), None)
    assert _names(kept) == ["coated.dat"]
    text = str(ctx.b.results)
    assert "bare.dat (the model reads it as a table: a bare substrate, not a film)" in text


def test_a_file_of_the_same_name_elsewhere_is_not_the_substrate(files, tmp_path: Path):
    elsewhere = tmp_path / "sub" / "bare.dat"
    elsewhere.parent.mkdir()
    elsewhere.write_text(TABLE)
    ctx = _ctx([files["coated.dat"], files["bare.dat"]])
    kept = _apply(ctx, _model(elsewhere), _flag("coated.dat", "bare.dat"), None)
    assert _names(kept) == ["coated.dat", "bare.dat"]


def test_the_sample_group_decides_and_film_files_override(files):
    paths = list(files.values())
    ctx = _ctx(paths, [[files["coated.dat"], files["other.dat"]]])
    flagged = _flag("coated.dat", "bare.dat", "other.dat")
    model = _model(files["bare.dat"])
    assert _names(_apply(ctx, model, flagged, None)) == ["coated.dat", "other.dat"]
    ctx = _ctx(paths)  # no group of several files: every flagged file but the substrate's
    assert _names(_apply(ctx, model, flagged, None)) == ["coated.dat", "other.dat"]
    assert _names(_apply(ctx, model, flagged, ["other.dat"])) == ["other.dat"]
    # even when named, the substrate's file is not fitted
    assert _names(_apply(ctx, model, flagged, ["bare.dat"])) == []


def test_film_files_must_be_inputs(files, tmp_path: Path, capsys):
    argv = ["report", str(files["coated.dat"]), "-o", str(tmp_path / "rep"), "--film-default"]
    assert main([*argv, "--film-files", str(tmp_path / "absent.dat")]) == 2
    err = capsys.readouterr().err
    assert "--film-files" in err and "not among the input files" in err
    assert "Traceback" not in err


@pytest.mark.shared
def test_w1_trio_with_the_bare_wafer_as_substrate_fits_only_w1(real_exports):
    d = real_exports / "woollam-wvase-ascii"
    trio = [d / "w1_12082006.dat", d / "w1_12082006_p-pol_refl.dat",
            d / "w1_12082006_s-pol_refl.dat"]  # fmt: skip
    bare = d / "w2_10102006.dat"
    b = Builder("t", progress=False)
    ctx = Context(b)
    with b.section("ingest", "Ingested files"):
        ingest_inputs(ctx, [*trio, bare])
        sample_groups(ctx, [*trio, bare], [trio])
    frames = [(str(s), g) for f in ctx.frames for s, g in f.groupby("source", sort=False)]
    flagged = _flagged([(s, g) for s, g in frames if g["quantity"].isin(["psi"]).any()])
    # both psi/Delta files have angles that disagree somewhere: both were fitted before
    assert sorted(_names(flagged)) == ["w1_12082006.dat", "w2_10102006.dat"]
    model = _model(bare)
    assert _names(_apply(ctx, model, flagged, None)) == ["w1_12082006.dat"]
    # without the mapping (three sample names) the rule is the same: not the substrate
    ctx.samples = pair_samples([*trio, bare], [])
    assert _names(_apply(ctx, model, flagged, None)) == ["w1_12082006.dat"]
