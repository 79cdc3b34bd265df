"""The common dataset: schema validation, Measurement, concatenation, exact round trips."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from labbrdf.dataset import (
    COLUMNS,
    DatasetError,
    Measurement,
    concat,
    make_frame,
    read,
    read_csv,
    read_parquet,
    validate,
    wrap_delta,
    write,
)


def _psi_delta(source="a.dat", sample="Al", n=5):
    wl = np.linspace(300.0, 700.0, n)
    rows = [
        make_frame(
            sample=sample,
            instrument="woollam-wvase",
            source=source,
            quantity="psi",
            value=np.linspace(40, 44, n),
            sigma=0.01,
            unit="deg",
            wavelength_nm=wl,
            theta_i_deg=64.999634,
        ),
        make_frame(
            sample=sample,
            instrument="woollam-wvase",
            source=source,
            quantity="delta",
            value=np.linspace(100, 359.999, n),
            sigma=np.nan,
            unit="deg",
            wavelength_nm=wl,
            theta_i_deg=64.999634,
        ),
    ]
    return Measurement(pd.concat(rows, ignore_index=True), {"title": "Al <test>", "n": n})


def test_validate_gives_canonical_columns_and_dtypes():
    m = _psi_delta()
    assert list(m.data.columns) == list(COLUMNS)
    assert isinstance(m.data["quantity"].dtype, pd.CategoricalDtype)
    assert m.data["value"].dtype == np.float64
    assert m.quantities == ["psi", "delta"]


@pytest.mark.parametrize(
    ("column", "bad", "match"),
    [
        ("value", np.nan, "column 'value': expected finite"),
        ("value", np.inf, "column 'value': expected finite"),
        ("sigma", -1.0, "column 'sigma'"),
        ("wavelength_nm", 0.0, "column 'wavelength_nm'"),
        ("theta_i_deg", 91.0, "column 'theta_i_deg'"),
        ("theta_r_deg", -1.0, "column 'theta_r_deg'"),
        ("phi_r_deg", 360.0, "column 'phi_r_deg'"),
        ("quantity", "colour", "unknown quantity"),
        ("unit", "%", "column 'unit'"),
        ("sample", "", "column 'sample'"),
        ("source", None, "column 'source'"),
    ],
)
def test_validate_names_column_and_row(column, bad, match):
    df = _psi_delta().data.copy()
    df["quantity"] = df["quantity"].astype(str)
    df[column] = df[column].astype(object)
    df.loc[3, column] = bad
    with pytest.raises(DatasetError, match=match) as info:
        validate(df)
    assert "rows 3" in str(info.value)


def test_validate_psi_and_delta_ranges():
    df = _psi_delta().data.copy()
    df.loc[0, "value"] = 91.0
    with pytest.raises(DatasetError, match="psi outside"):
        validate(df)
    df = _psi_delta().data.copy()
    df.loc[9, "value"] = 360.0
    with pytest.raises(DatasetError, match=r"delta outside \[0, 360\)"):
        validate(df)


def test_validate_missing_unknown_and_empty():
    df = _psi_delta().data
    with pytest.raises(DatasetError, match="missing column"):
        validate(df.drop(columns="sigma"))
    with pytest.raises(DatasetError, match="unknown column"):
        validate(df.assign(foo=1.0))
    with pytest.raises(DatasetError, match="no rows"):
        validate(df.iloc[:0])
    with pytest.raises(DatasetError, match="expected a pandas DataFrame"):
        validate({"a": 1})


def test_meta_must_be_json_safe():
    df = _psi_delta().data
    with pytest.raises(DatasetError, match="JSON-safe"):
        Measurement(df, {"x": np.nan})
    with pytest.raises(DatasetError, match="JSON-safe"):
        Measurement(df, {"x": object()})


def test_concat_keeps_sources_and_metas():
    a, b = _psi_delta("a.dat", "Al"), _psi_delta("b.dat", "Cu", n=3)
    c = concat([a, b])
    assert len(c) == len(a) + len(b)
    assert [p["source"] for p in c.meta["parts"]] == ["a.dat", "b.dat"]
    assert c.meta["parts"][1]["meta"] == b.meta
    # nesting stays flat
    d = concat([c, _psi_delta("c.dat")])
    assert [p["source"] for p in d.meta["parts"]] == ["a.dat", "b.dat", "c.dat"]
    with pytest.raises(DatasetError, match="nothing to concatenate"):
        concat([])


@pytest.mark.parametrize("suffix", [".parquet", ".csv"])
def test_round_trip_is_exact(tmp_path, suffix):
    m = concat([_psi_delta("a.dat", 'Al, "quoted" <x>'), _psi_delta("b.dat", "Cu")])
    df = m.data.copy()
    df["time_s"] = np.linspace(0, 1, len(df)) / 3.0  # non-terminating binary fractions
    df["channel"] = "pp"
    m = Measurement(df, m.meta)
    path = write(m, tmp_path / f"out{suffix}")
    back = read(path)
    pd.testing.assert_frame_equal(back.data, m.data, check_exact=True)
    assert back.meta == m.meta
    sidecar = ["out.meta.json"] if suffix == ".csv" else []
    assert sorted(p.name for p in tmp_path.iterdir()) == [f"out{suffix}", *sidecar]  # no temp


@settings(max_examples=50, deadline=None)
@given(
    st.lists(st.floats(allow_nan=False, allow_infinity=False, width=64), min_size=1, max_size=20)
)
def test_csv_round_trip_floats_exactly(tmp_path_factory, values):
    m = Measurement(
        make_frame(
            sample="s",
            instrument="i",
            source="f",
            quantity="brdf",
            value=values,
            unit="sr-1",
            wavelength_nm=500.0,
        ),
        {},
    )
    p = tmp_path_factory.mktemp("rt") / "x.csv"
    write(m, p)
    np.testing.assert_array_equal(read_csv(p).data["value"].to_numpy(), np.asarray(values))


def test_bad_files_raise_dataset_error(tmp_path):
    p = tmp_path / "x.parquet"
    p.write_bytes(b"not parquet")
    with pytest.raises(DatasetError, match="not a readable Parquet"):
        read_parquet(p)
    q = tmp_path / "x.csv"
    q.write_text("# labbrdf-meta: {bad json\nsample\n")
    with pytest.raises(DatasetError, match="line 1: bad labbrdf-meta"):
        read_csv(q)
    with pytest.raises(DatasetError, match=r"\.parquet or \.csv"):
        write(_psi_delta(), tmp_path / "x.xlsx")
    with pytest.raises(DatasetError, match="not a labbrdf dataset"):
        read(tmp_path / "x.xlsx")


def test_write_failure_leaves_previous_file(tmp_path, monkeypatch):
    p = tmp_path / "out.csv"
    write(_psi_delta(), p)
    before = p.read_bytes()
    import labbrdf.dataset as ds

    def boom(*a, **k):
        raise OSError("disk full")

    monkeypatch.setattr(ds.os, "replace", boom)
    with pytest.raises(OSError, match="disk full"):
        write(_psi_delta(n=7), p)
    assert p.read_bytes() == before
    assert sorted(x.name for x in tmp_path.iterdir()) == ["out.csv", "out.meta.json"]


def test_summary_is_json_safe():
    s = _psi_delta().summary()
    json.dumps(s, allow_nan=False)
    assert s["theta_i_deg"] == [65.0]
    assert s["wavelength_nm"] == [300.0, 700.0]


def test_wrap_delta_into_0_360():
    np.testing.assert_array_equal(
        wrap_delta([-180.0, 0.0, 360.0, 725.0, -1e-17]), [180.0, 0.0, 0.0, 5.0, 0.0]
    )
