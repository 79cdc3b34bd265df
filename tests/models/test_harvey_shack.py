"""Harvey-Shack (K-correlation in direction cosines): TIS closed form and recovery."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from labbrdf import fit, models
from labbrdf.adapters.zemax_bsdf import read_zemax_bsdf
from labbrdf.bsdf_geometry import scatter_to_angles
from labbrdf.integrate import hemispherical_reflectance
from labbrdf.models import ModelError
from labbrdf.models.harvey_shack import knee_integral
from labbrdf.writers.zemax import write_bsdf

TRUE = {"b0": 40.0, "L": 0.012, "S": -2.6}
TI = np.array([0.0, 20.0, 40.0])
RAD = np.array([0.0, 0.5, 1, 2, 4, 7, 12, 20, 30, 45, 60, 80])
AZ = np.arange(0.0, 181.0, 30.0)


def _hs(p: dict, ti: np.ndarray, tr: np.ndarray, pr: np.ndarray) -> np.ndarray:
    """Independent form: b0 (1 + |beta - beta0|^2 / L^2)^(S/2), beta from unit vectors."""
    d2 = (np.sin(tr) * np.cos(pr) + np.sin(ti)) ** 2 + (np.sin(tr) * np.sin(pr)) ** 2
    return p["b0"] * (1 + d2 / p["L"] ** 2) ** (p["S"] / 2)


@pytest.mark.parametrize("S", [-2.0, -3.0, -1.5])
def test_tis_closed_form_matches_quadrature(S: float) -> None:
    m = models.get("harvey_shack")
    p = {"b0": 5.0, "L": 0.03, "S": S}
    ti = [0.0, 35.0, 70.0]
    quad = hemispherical_reflectance(m, p, ti, method="quadrature", rtol=1e-8)
    np.testing.assert_allclose(m.hemispherical(ti, p), quad, rtol=1e-6)


def test_knee_integral_limits() -> None:
    # S = -2 is the logarithm; nearby slopes approach it continuously
    assert float(knee_integral(1.0, 0.1, -2.0)) == pytest.approx(0.5 * 0.01 * math.log(101.0))
    assert float(knee_integral(1.0, 0.1, -2.0 + 1e-7)) == pytest.approx(
        float(knee_integral(1.0, 0.1, -2.0)), rel=1e-5
    )
    assert float(knee_integral(0.3, 0.1, 0.0)) == pytest.approx(0.045)  # S = 0: R^2 / 2


@pytest.mark.parametrize(("scatter_type", "seed"), [("BRDF", 11), ("BTDF", 12)])
def test_recovery_from_bsdf(tmp_path: Path, scatter_type: str, seed: int) -> None:
    tr, pr, above = scatter_to_angles(TI[:, None, None], RAD[None, None, :], AZ[None, :, None])
    f = _hs(TRUE, np.radians(TI)[:, None, None], np.radians(tr), np.radians(pr))
    f = f * (1 + 0.02 * np.random.default_rng(seed).standard_normal(f.shape))
    path = write_bsdf(
        tmp_path / "hs.bsdf",
        theta_i_deg=TI,
        radial_deg=RAD,
        azimuth_deg=AZ,
        values=np.where(above, f, 0.0)[None, None],
        symmetry="PlaneSymmetrical",
        scatter_type=scatter_type,
    )
    model = models.get("harvey_shack", transmission=scatter_type == "BTDF")
    res = fit(model, read_zemax_bsdf(path), weighting="relative")
    for k, v in TRUE.items():
        p = res.params[k]
        assert p.stderr is not None and abs(p.value - v) < 3 * p.stderr, (k, p.value, v)
    assert not res.flags


def test_bad_input() -> None:
    with pytest.raises(ModelError, match="'harvey_shack' got unknown options"):
        models.get("harvey_shack", knee=1)
    with pytest.raises(ModelError, match="L must be > 0"):
        models.get("harvey_shack").evaluate(0.1, 0.2, params={"L": 0.0})
