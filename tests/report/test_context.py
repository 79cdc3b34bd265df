"""The report's fits: they run through fit_many on the report's executor, and come back as
FitRecords equal to single fits of each (sample, wavelength) group; a group that cannot be
fitted stops the fits with its name and the reason."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest

import labbrdf
from labbrdf import parallel
from labbrdf.fitting import FitError, fit
from labbrdf.report.builder import Builder
from labbrdf.report.context import Context, run_fits
from labbrdf.report.published import paper_values, published_params, read_published


def scans(fixtures_dir: Path) -> pd.DataFrame:
    folder = fixtures_dir / "specular"
    d = labbrdf.read_many(sorted(folder.glob("*.csv"))).data
    return d.assign(quantity=d["quantity"].astype(str)).reset_index(drop=True)


def test_report_fits_equal_single_fits_of_each_group(fixtures_dir: Path) -> None:
    d = scans(fixtures_dir)
    ctx = Context(Builder("t"), executor=parallel.Executor("serial"), frames=[d])
    (recs,) = run_fits(ctx, [("smooth3", {})]).values()
    groups = d.groupby(["sample", "wavelength_nm"], sort=True)
    assert [(r.sample, r.wavelength_nm) for r in recs] == [(s, w) for (s, w), _ in groups]
    for rec, (_, g) in zip(recs, groups, strict=True):
        single = fit("smooth3", g, method=ctx.method, seed=ctx.seed)
        assert rec.values == single.values
        assert rec.summary["chisqr"] == single.chisqr
        pd.testing.assert_frame_equal(rec.data, g.reset_index(drop=True))
        assert rec.group == "all"


@pytest.mark.slow
def test_report_fits_do_not_depend_on_the_executor(fixtures_dir: Path) -> None:
    d = scans(fixtures_dir)
    out = []
    for ex in (parallel.Executor("serial"), parallel.Executor("processes", workers=2)):
        ctx = Context(Builder("t"), executor=ex, frames=[d])
        out.append([r.values for r in run_fits(ctx, [("smooth3", {})])["smooth3"]])
    assert out[0] == out[1]


def test_a_group_that_cannot_be_fitted_is_named_with_the_reason(fixtures_dir: Path) -> None:
    d = scans(fixtures_dir)
    first = d.groupby(["sample", "wavelength_nm"], sort=True).ngroup() == 0
    d = d[~first | (d.index % 40 == 0)].reset_index(drop=True)  # a group of 2 points
    s, w = d.loc[first[first].index[0], ["sample", "wavelength_nm"]]
    ctx = Context(Builder("t"), executor=parallel.Executor("serial"), frames=[d])
    with pytest.raises(
        FitError, match=rf"smooth3: group sample={s}, wavelength_nm={w}: not fitted"
    ):
        run_fits(ctx, [("smooth3", {})])


def test_published_tables_are_read_and_looked_up(fixtures_dir: Path, tmp_path: Path) -> None:
    tables, read = read_published(fixtures_dir / "published")
    assert read == ["zou2013_table1.csv", "zou2013_table2.csv", "zou2013_table3.csv"]
    row = tables["params"].iloc[0]
    pv = paper_values(tables, str(row["sample"]).upper(), float(row["wavelength_nm"]))
    assert pv == {"k1": row["k1"], "k2": row["k2"], "k3": row["k3"]}
    assert (
        published_params(tables, str(row["sample"]), float(row["wavelength_nm"]))["k1"]
        == (row["k1"])
    )
    assert published_params(tables, "nope", 1.0) == {} and paper_values(tables, "nope", 1) is None
    assert read_published(tmp_path) == ({}, [])
    assert published_params({}, "OSR", 550.0) == {} and paper_values({}, "OSR", 550.0) is None
