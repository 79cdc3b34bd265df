"""Woollam WVASE32 / CompleteEASE: the real files added later, and hardening."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import labbrdf

WVASE = "woollam-wvase-ascii"


def test_rtmethod_s_reflectance_at_45_deg(real_exports: Path) -> None:
    m = labbrdf.read(real_exports / WVASE / "ta2o5_02262007_rs.dat")
    d = m.data
    assert len(d) == 676 and set(d["quantity"]) == {"reflectance"}
    assert set(d["channel"]) == {"s"}
    # line 300: "sR	716.856299	45.000000	0.227157	0.0145431"
    row = d[np.isclose(d["wavelength_nm"], 716.856299, rtol=0, atol=1e-9)].iloc[0]
    assert row["value"] == pytest.approx(0.227157, rel=1e-12)
    assert row["sigma"] == pytest.approx(0.0145431, rel=1e-12)
    assert row["theta_i_deg"] == 45.0 == row["theta_r_deg"]
