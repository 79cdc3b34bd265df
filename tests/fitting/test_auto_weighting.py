"""auto_weighting: the data's sigmas when every row has one, else relative weights."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from labbrdf.fitting import auto_weighting


@pytest.mark.parametrize(
    ("sigma", "expected"),
    [
        ([0.1, 0.2], None),
        ([0.1, np.nan], "relative"),
        ([0.1, 0.0], "relative"),
        ([0.1, -0.1], "relative"),
        ([], "relative"),
    ],
)
def test_sigma_only_when_every_row_has_one(sigma, expected) -> None:
    df = pd.DataFrame({"value": np.ones(len(sigma)), "sigma": np.asarray(sigma, float)})
    assert auto_weighting(df) == expected


def test_a_measurement_is_judged_by_its_rows(fixtures_dir) -> None:
    import labbrdf

    m = labbrdf.read(fixtures_dir / "specular" / "osr_specular.csv")
    assert auto_weighting(m) == auto_weighting(m.data)
    with_sigma = m.data.assign(sigma=0.01)
    assert auto_weighting(with_sigma) is None
    assert auto_weighting(with_sigma.assign(sigma=np.nan)) == "relative"
