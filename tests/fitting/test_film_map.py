"""Wafer maps: one film fit per point through the executor, the same table whatever it is."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from labbrdf.cli import main
from labbrdf.dataset import write_csv
from labbrdf.films import FilmError, FilmModel, Layer, Stack
from labbrdf.fitting.film_map import fit_film_map, read_map_listing
from labbrdf.nk.dispersion import Cauchy, Constant
from labbrdf.parallel import Executor

from .test_film_multi import A, _sample

pytest.importorskip("tmm")

#: five points of a wafer [mm] and their thicknesses [nm] (thicker at the centre)
POINTS = [(0.0, 0.0), (40.0, 0.0), (0.0, 40.0), (-40.0, 0.0), (0.0, -40.0)]
THICK = [130.0, 121.0, 122.5, 120.0, 119.0]


@pytest.fixture(scope="module")
def listing(tmp_path_factory):
    d = tmp_path_factory.mktemp("map")
    lines = ["file,x,y"]
    for j, ((x, y), t) in enumerate(zip(POINTS, THICK, strict=True)):
        write_csv(_sample(f"p{j}", t, seed=10 + j), d / f"p{j}.csv")
        lines.append(f"p{j}.csv,{x},{y}")
    (d / "map.csv").write_text("\n".join(lines) + "\n")
    model = d / "film.toml"
    model.write_text(
        '[substrate]\nmaterial = "constant"\nn = 3.9\nk = 0.02\n\n'
        '[[layer]]\nname = "film"\nmaterial = "cauchy"\nthickness_nm = [60, 200]\n'
        "A = [1.3, 1.7]\nB = [0, 0.02]\n"
    )
    return d / "map.csv", model


def test_map_is_the_same_serially_and_on_processes(listing):
    path, model = listing
    serial = fit_film_map(model, path, executor="serial")
    procs = fit_film_map(model, path, executor=Executor("processes", workers=2))
    pd.testing.assert_frame_equal(serial.table, procs.table, check_exact=True)
    t = serial.table
    assert list(zip(t["x_mm"], t["y_mm"], strict=True)) == POINTS
    # each point alone: within 4 of its standard errors (a miss has probability 6e-5)
    z = (t["film.thickness_nm"] - THICK) / t["film.thickness_nm_stderr"]
    assert np.all(np.abs(z) < 4), z.tolist()
    assert np.all(t["film.thickness_nm_ci95_lo"] < t["film.thickness_nm"])
    assert np.allclose(t["film.n_633nm"], A + 0.004 / 0.633**2, atol=1e-3)
    assert "film.thickness_nm: mean" in str(serial)


def test_map_cli_writes_table_and_figure(listing, tmp_path, capsys):
    path, model = listing
    out, png = tmp_path / "t.csv", tmp_path / "m.png"
    args = ["film-map", str(path), "--model", str(model), "--scheduler", "serial"]
    assert main([*args, "-o", str(out), "--png", str(png)]) == 0
    assert "Film map: 5 points" in capsys.readouterr().out
    assert len(pd.read_csv(out)) == 5 and png.stat().st_size > 10_000


def test_map_errors_name_the_listing_line_or_the_point_file(listing, tmp_path, capsys):
    path, model = listing
    bad = tmp_path / "bad.csv"
    bad.write_text("file,x,y\np0.csv,1,2\np1.csv,nan,2\n")
    with pytest.raises(FilmError, match=r"bad.csv, line 3: x = 'nan'"):
        read_map_listing(bad)
    bad.write_text("file,x\np0.csv,1\n")
    with pytest.raises(FilmError, match=r"bad.csv, line 1: missing column\(s\) \['y'\]"):
        read_map_listing(bad)
    bad.write_text(f"file,x,y\n{path.parent / 'p0.csv'},0,0\n{tmp_path / 'gone.csv'},1,1\n")
    args = ["film-map", str(bad), "--model", str(model), "--scheduler", "serial"]
    assert main(args) == 2
    err = capsys.readouterr().err
    assert "gone.csv" in err and "Traceback" not in err
    empty = FilmModel(Stack([Layer(Cauchy(A=1.5), 100.0, "film")], Constant(n=3.9, k=0.02)))
    with pytest.raises(FilmError, match="at least one point"):
        fit_film_map(empty, [])


@pytest.mark.parametrize("overwrite", [False, True])
def test_map_output_never_replaces_a_point_file_the_listing_names(listing, capsys, overwrite):
    # -o TABLE.csv naming p1.csv (listed inside map.csv) is refused before any fit
    path, model = listing
    point = path.parent / "p1.csv"
    before = point.read_bytes()
    args = ["film-map", str(path), "--model", str(model), "--scheduler", "serial"]
    assert main([*args, "-o", str(point), *(["--overwrite"] if overwrite else [])]) == 2
    err = capsys.readouterr().err
    assert "p1.csv" in err and "Traceback" not in err
    assert point.read_bytes() == before
