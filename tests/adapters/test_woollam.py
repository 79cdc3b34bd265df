"""Woollam WVASE32 / CompleteEASE: the real files added later, and hardening."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import labbrdf
from labbrdf.adapters import AdapterError

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


@pytest.mark.parametrize("spelling", [b"inf", b"1e999", b"-inf", b"Infinity"])
def test_completeease_dynamic_time_must_be_finite(
    real_exports: Path, tmp_path: Path, spelling: bytes
) -> None:
    raw = (real_exports / "woollam-completeease-ascii/Woolam_kineticTest.dat").read_bytes()
    # line 5: "370.324	70.000	30.0225	121.5848	0.0988	0.2195		0.0232" (time in min last)
    old = b"370.324\t70.000\t30.0225\t121.5848\t0.0988\t0.2195\t\t0.0232"
    bad = tmp_path / "kinetic.dat"
    bad.write_bytes(raw.replace(old, old[:-6] + spelling, 1))
    with pytest.raises(AdapterError, match=r"line 5: dynamic data: the time .* must be finite"):
        labbrdf.read(bad)
