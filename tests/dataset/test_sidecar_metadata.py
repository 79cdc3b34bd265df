"""Dataset CSV: metadata in a sidecar ``<stem>.meta.json``, not in a first comment line."""

from __future__ import annotations

import json
from pathlib import Path

import pandas as pd
import pytest

import labbrdf
from labbrdf.dataset import COLUMNS, DatasetError, Measurement, make_frame, read_csv, write_csv


def _m() -> Measurement:
    f = make_frame(
        sample="s",
        instrument="i",
        source="f.dat",
        quantity="psi",
        value=[10.5, 0.1 + 0.2],
        unit="deg",
        wavelength_nm=[500.0, 600.0],
        theta_i_deg=65.0,
    )
    return Measurement(f, {"title": "wafer 2", "nested": {"a": [1, 2.5, None]}, "long": "x" * 500})


def test_csv_starts_with_the_column_header_and_meta_goes_to_a_sidecar(tmp_path: Path) -> None:
    p = write_csv(_m(), tmp_path / "run.csv")
    first = p.read_text(encoding="utf-8").split("\n", 1)[0]
    assert first == ",".join(COLUMNS)
    side = tmp_path / "run.meta.json"
    assert json.loads(side.read_text(encoding="utf-8")) == _m().meta
    # a spreadsheet (or pandas without options) sees a plain table
    assert list(pd.read_csv(p).columns) == list(COLUMNS)
    assert sorted(q.name for q in tmp_path.iterdir()) == ["run.csv", "run.meta.json"]


def test_round_trip_through_the_sidecar_is_exact(tmp_path: Path) -> None:
    m = _m()
    back = read_csv(write_csv(m, tmp_path / "run.csv"))
    assert back.meta == m.meta
    pd.testing.assert_frame_equal(back.data, m.data)
    via_dispatch = labbrdf.read(tmp_path / "run.csv")
    assert via_dispatch.meta["title"] == "wafer 2"
    assert via_dispatch.meta["format"] == "labbrdf-dataset-csv"


def test_older_csv_with_the_meta_comment_line_still_reads(tmp_path: Path) -> None:
    m = _m()
    p = tmp_path / "old.csv"
    with open(p, "w", encoding="utf-8", newline="") as fh:
        fh.write("# labbrdf-meta: " + json.dumps(m.meta) + "\n")
        m.data.to_csv(fh, index=False, lineterminator="\n")
    back = read_csv(p)
    assert back.meta == m.meta
    pd.testing.assert_frame_equal(back.data, m.data)
    assert labbrdf.read(p).meta["title"] == "wafer 2"


def test_bad_sidecar_json_names_the_sidecar(tmp_path: Path) -> None:
    p = write_csv(_m(), tmp_path / "run.csv")
    (tmp_path / "run.meta.json").write_text("{broken", encoding="utf-8")
    with pytest.raises(DatasetError, match=r"run\.meta\.json.*not valid JSON"):
        read_csv(p)
