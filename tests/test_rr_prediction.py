"""Rayleigh-Rice prediction inputs: a height map's PSD, the common band, refusals."""

from __future__ import annotations

import math

import numpy as np
import pytest

from labbrdf.adapters.topography import HeightMap
from labbrdf.prediction import PredictionError
from labbrdf.roughness import psd_models
from labbrdf.rr_prediction import bragg_band, map_psd, psd_agreement

pytest.importorskip("SurfaceTopography")

A, B, C = 1e-29, 5e-6, 1.6  # SI K-correlation (psd_models' form)
N, SIZE = 128, 64e-6


def _surface(seed: int) -> np.ndarray:
    f = np.fft.fftfreq(N, d=SIZE / N)
    psd = psd_models.k_correlation_2d(np.hypot(f[:, None], f[None, :]), A, B, C)
    psd[0, 0] = 0.0
    w = np.random.default_rng(seed).standard_normal((N, N))
    return np.fft.ifft2(np.fft.fft2(w) * np.sqrt(psd) * N / SIZE).real


def _map(z: np.ndarray) -> HeightMap:
    return HeightMap(z, (SIZE / N, SIZE / N), "synthetic.nc", "height")


def test_map_psd_follows_the_generating_psd():
    """Mid-band bins (away from the first few, which hold few Fourier modes, and from
    Nyquist, where the window leaks): median ratio within 15 % of 1 (each log bin averages
    tens to hundreds of exponentially distributed periodogram values)."""
    p = map_psd(_map(_surface(1)))
    assert p.f_min == pytest.approx(1 / SIZE) and p.f_max == pytest.approx(N / (2 * SIZE))
    mid = (p.f > 5 / SIZE) & (p.f < 0.5 * p.f_max)
    r = p.psd[mid] / psd_models.k_correlation_2d(p.f[mid], A, B, C)
    assert abs(np.median(r) - 1.0) < 0.15
    # 0 outside the band, the map's values inside
    assert p.psd2d(np.array([0.5 * p.f_min, 2 * p.f_max]), np.zeros(2)).tolist() == [0, 0]
    assert p.psd2d(p.f[mid], 0 * p.f[mid]) == pytest.approx(p.psd[mid], rel=1e-9)


def test_agreement_of_the_generating_psd_with_the_map():
    p = map_psd(_map(_surface(2)))

    def truth(fx, fy):
        return psd_models.k_correlation_2d(np.hypot(fx, fy), A, B, C)

    band = bragg_band([30.0, 30.0], [40.0, 80.0], [180.0, 0.0], 600.0)
    ag = psd_agreement(truth, "k-correlation", p, band)
    lo, med, hi = ag.ratio_quantiles()
    assert ag.f_lo >= p.f_min and ag.f_hi <= p.f_max and ag.f.size > 5
    assert 0.7 < med < 1.4 and lo < med < hi
    assert "times the height map's" in ag.sentence()
    fig = ag.plot()
    assert fig.axes[0].get_xscale() == "log"


def test_refusals():
    with pytest.raises(PredictionError, match="profile"):
        map_psd(HeightMap(np.zeros(64), (1e-6,), "line.opdx", "height"))
    z = _surface(3)
    z[3, 4] = np.nan
    with pytest.raises(PredictionError, match="1 undefined points"):
        map_psd(_map(z))
    with pytest.raises(PredictionError, match="off the specular"):
        bragg_band([30.0], [30.0], [180.0], 600.0)
    assert math.isnan(
        psd_agreement(
            lambda fx, fy: fx, "k-correlation", map_psd(_map(_surface(4))), (1e9, 2e9)
        ).ratio_quantiles()[1]
    )
