"""PerkinElmer UV WinLab ASCII: the real files added to the shared exports later."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import labbrdf

PE = "perkinelmer-uvwinlab-asc"


def test_lambda950_absorbance_file_with_comma_and_spaces_in_its_name(real_exports: Path) -> None:
    m = labbrdf.read(real_exports / PE / "F4-P3HT 1-10 0,5 mgml.Probe.Raw.asc")
    assert m.meta["format"] == "perkinelmer-uvwinlab-asc"
    d = m.data
    assert len(d) == 2181  # header line 86: "2181"
    assert set(d["quantity"]) == {"absorbance"}
    # line 91: "2500.000000	0.012944"
    row = d[np.isclose(d["wavelength_nm"], 2500.0, rtol=0, atol=1e-9)]
    assert row["value"].tolist() == [pytest.approx(0.012944, rel=1e-12)]
    assert d["wavelength_nm"].min() == 320.0
