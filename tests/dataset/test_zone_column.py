"""Optional integer-valued column ``zone`` (nulling-ellipsometer zone of a row)."""

from __future__ import annotations

import numpy as np
import pytest

from labbrdf.dataset import OPTIONAL_COLUMNS, DatasetError, Measurement, concat, make_frame

KW = dict(sample="a", instrument="i", source="f", quantity="psi", unit="deg")


def test_zone_is_a_declared_optional_column() -> None:
    assert "zone" in OPTIONAL_COLUMNS
    m = Measurement(make_frame(value=[1.0, 2.0], wavelength_nm=500.0, zone=[1, 3], **KW))
    assert m.data["zone"].tolist() == [1.0, 3.0]


@pytest.mark.parametrize("bad", [1.5, -1.0, np.inf])
def test_zone_must_be_a_whole_number_at_least_0(bad: float) -> None:
    with pytest.raises(DatasetError, match=r"column 'zone': expected an integer >= 0"):
        Measurement(make_frame(value=[1.0, 2.0], wavelength_nm=500.0, zone=[1, bad], **KW))


def test_rows_without_a_zone_are_nan_after_concat() -> None:
    a = Measurement(make_frame(value=[1.0], wavelength_nm=500.0, zone=2, **KW))
    b = Measurement(make_frame(value=[2.0], wavelength_nm=600.0, **KW))
    z = concat([a, b]).data["zone"]
    assert z.iloc[0] == 2.0 and np.isnan(z.iloc[1])
