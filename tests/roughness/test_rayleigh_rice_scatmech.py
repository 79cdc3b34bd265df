"""Rayleigh-Rice against NIST SCATMECH's Microroughness_BRDF_Model (stored reference values).

The table (``data/scatmech_rr.csv``, made as ``data/README.md`` says) holds full Mueller
BRDFs of a conductor and two dielectrics, in and out of the plane of incidence. SCATMECH
computes in double precision with the same formulas written independently, so the
agreement is to rounding: 1e-9 of the largest element of each matrix (1e-6 asked).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from labbrdf.roughness import rayleigh_rice as rr

TABLE = Path(__file__).with_name("data") / "scatmech_rr.csv"
ELEMENTS = [f"M{i}{j}" for i in range(4) for j in range(4)]


@pytest.fixture(scope="module")
def table() -> pd.DataFrame:
    return pd.read_csv(TABLE)


def _abc(a_um4: float, b_um: float, c: float):
    """SCATMECH's ABC PSD in SI: A / (1 + (B f)^2)^(C/2)."""
    a, b = a_um4 * 1e-24, b_um * 1e-6

    def psd(fx, fy):
        return a / (1.0 + b * b * (np.asarray(fx) ** 2 + np.asarray(fy) ** 2)) ** (c / 2.0)

    return psd


@pytest.mark.parametrize("material", ["aluminium", "glass", "silicon"])
def test_mueller_brdf_matches_scatmech(table: pd.DataFrame, material: str) -> None:
    t = table[table["material"] == material]
    r = t.iloc[0]
    psd = _abc(r["A_um4"], r["B_um"], r["C"])
    m = rr.mueller_brdf(
        np.radians(t["theta_i_deg"].to_numpy()),
        np.radians(t["theta_s_deg"].to_numpy()),
        np.radians(t["phi_s_deg"].to_numpy() + 180.0),
        r["wavelength_um"] * 1e-6,
        complex(r["n"], r["k"]),
        psd,
    ).reshape(-1, 16)
    want = t[ELEMENTS].to_numpy()
    scale = np.abs(want).max(axis=1, keepdims=True)
    assert np.max(np.abs(m - want) / scale) < 1e-9
    # the three incident polarizations, in and out of plane
    for pol, sign in (("s", 1.0), ("p", -1.0)):
        f = rr.brdf(
            np.radians(t["theta_i_deg"].to_numpy()),
            np.radians(t["theta_s_deg"].to_numpy()),
            np.radians(t["phi_s_deg"].to_numpy() + 180.0),
            r["wavelength_um"] * 1e-6,
            complex(r["n"], r["k"]),
            psd,
            pol,
        )
        ref = t["M00"].to_numpy() + sign * t["M01"].to_numpy()
        np.testing.assert_allclose(f, ref, rtol=1e-9, atol=1e-12 * math.fsum(abs(ref)))
