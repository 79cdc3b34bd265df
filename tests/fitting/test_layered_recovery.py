"""Synthetic recovery: .bsdf files written from the layered model, fitted back.

The file is traced with seed 12345 and 2 % Gaussian noise; the fit traces with its own
seed 0 (common random numbers across its parameter values), so it sees Monte Carlo noise
independent of the file's, and its weights carry that noise (``Model.point_variance``).
Both use the same 3 x 6 degree grid, so the comparison is free of the grid's bias
(``docs/models.md`` 7).
"""

from __future__ import annotations

import numpy as np
import pytest

from labbrdf import adapters, fit, models
from labbrdf.bsdf_export import write_bsdf
from labbrdf.bsdf_geometry import scatter_to_angles

AL = {"n": 1.55, "k": 7.71}
RADIAL = np.array([0, 5, 10, 15, 20, 30, 40, 50, 60, 70, 80.0])
AZIMUTH = np.arange(0.0, 181.0, 10.0)


def _synthetic(tmp_path, truth, incidences, rays):
    gen = models.get("layered", seed=12345, rays=rays, grid="3x6", **AL)
    ti = np.asarray(incidences, float)
    tr, pr, up = scatter_to_angles(ti[:, None, None], RADIAL[None, None, :], AZIMUTH[None, :, None])
    tib = np.broadcast_to(ti[:, None, None], tr.shape)
    f = gen.evaluate(np.radians(tib[up]), np.radians(tr[up]), np.radians(pr[up]), params=truth)
    vals = np.zeros(tr.shape)
    vals[up] = f * (1 + 0.02 * np.random.default_rng(7).standard_normal(f.size))
    path = write_bsdf(
        tmp_path / "synthetic.bsdf",
        theta_i_deg=ti,
        radial_deg=RADIAL,
        azimuth_deg=AZIMUTH,
        values=vals[None, None],
        symmetry="PlaneSymmetrical",
    )
    df = adapters.read(path).data
    df = df[df["value"] != 0].copy()
    df["sigma"] = 0.02 * df["value"]  # the noise the file was written with
    return df


def _check(res, truth):
    assert res.success, res.message
    assert "Monte Carlo variance" in res.weighting
    for k, v in truth.items():
        p = res.params[k]
        assert p.stderr is not None and p.stderr > 0
        assert abs(p.value - v) < 3 * p.stderr, (k, p.value, v, p.stderr)


def test_layered_fit_recovers_both_roughnesses_at_one_incidence(tmp_path):
    """alpha_top 0.2 and alpha_sub 0.35 at 45 deg, 4000 rays, a local fit from the guess."""
    truth = {"alpha_top": 0.2, "alpha_sub": 0.35}
    df = _synthetic(tmp_path, truth, [45.0], 4000)
    model = models.get("layered", rays=4000, grid="3x6", **AL)
    _check(fit(model, df, method="LN_BOBYQA"), truth)


@pytest.mark.slow
@pytest.mark.parametrize(
    "truth",
    [{"alpha_top": 0.15, "alpha_sub": 0.3}, {"alpha_top": 0.3, "alpha_sub": 0.12}],
)
def test_layered_fit_recovers_the_roughnesses_at_three_incidences(tmp_path, truth):
    """The default global + local fit at 15, 45 and 75 deg with 2e4 rays."""
    df = _synthetic(tmp_path, truth, [15.0, 45.0, 75.0], 20_000)
    model = models.get("layered", rays=20_000, grid="3x6", **AL)
    _check(fit(model, df), truth)
