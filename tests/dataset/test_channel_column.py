"""Optional string column ``channel``: a missing value merges as the empty string."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

import labbrdf
from labbrdf.dataset import Measurement, concat, make_frame


def test_read_many_merges_files_with_and_without_a_channel_column(real_exports: Path) -> None:
    psi_delta = real_exports / "woollam-wvase-ascii/w2_10102006.dat"  # no channel column
    rs = real_exports / "woollam-wvase-ascii/ta2o5_02262007_rs.dat"  # channel "s"
    m = labbrdf.read_many([psi_delta, rs])
    d = m.data
    assert len(d) == 4056 + 676
    by_source = d.groupby("source")["channel"].agg(lambda c: sorted(set(c)))
    assert by_source["w2_10102006.dat"] == [""]
    assert by_source["ta2o5_02262007_rs.dat"] == ["s"]


def test_concat_of_frames_with_and_without_channel_keeps_strings() -> None:
    kw = dict(sample="a", instrument="i", source="f", quantity="psi", unit="deg")
    a = Measurement(make_frame(value=[1.0], wavelength_nm=[500.0], **kw))
    b = Measurement(make_frame(value=[2.0], wavelength_nm=[600.0], channel="pp", **kw))
    d = concat([a, b]).data
    assert d["channel"].tolist() == ["", "pp"]
    assert d["channel"].dtype == object


def test_none_and_nan_channel_become_empty_string() -> None:
    kw = dict(sample="a", instrument="i", source="f", quantity="psi", unit="deg")
    f = make_frame(value=[1.0, 2.0, 3.0], wavelength_nm=[1.0, 2.0, 3.0], **kw)
    f["channel"] = pd.Series(["p", None, np.nan], dtype=object)
    assert Measurement(f).data["channel"].tolist() == ["p", "", ""]
