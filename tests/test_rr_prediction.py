"""Rayleigh-Rice prediction inputs: a height map's PSD, the common band, refusals."""

from __future__ import annotations

import math

import numpy as np
import pytest

from labbrdf.adapters.topography import HeightMap
from labbrdf.prediction import PredictionError
from labbrdf.roughness import psd_models
from labbrdf.rr_prediction import bragg_band, group_psd, map_psd, predict_rr_brdf, psd_agreement

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


def _sized(seed: int, size: float) -> HeightMap:
    """A K-correlation map of N x N pixels over ``size`` [m] (the generator scaled)."""
    f = np.fft.fftfreq(N, d=size / N)
    psd = psd_models.k_correlation_2d(np.hypot(f[:, None], f[None, :]), A, B, C)
    psd[0, 0] = 0.0
    w = np.random.default_rng(seed).standard_normal((N, N))
    z = np.fft.ifft2(np.fft.fft2(w) * np.sqrt(psd) * N / size).real
    return HeightMap(z, (size / N, size / N), f"map{seed}.nc", "height")


def test_group_psd_is_the_composite_the_psd_command_gives():
    """The prediction's spectrum is labbrdf.psd's composite, bin for bin, and its sigma."""
    import labbrdf

    maps = [_sized(5, SIZE), _sized(6, SIZE / 8)]
    g = group_psd(maps)
    comp = labbrdf.psd(maps, kind="2d").composite
    ok = comp.psd > 0
    np.testing.assert_array_equal(g.f, comp.f[ok])
    np.testing.assert_array_equal(g.psd, comp.psd[ok])
    assert (g.f_min, g.f_max) == comp.band and g.gaps == ()
    assert g.sigma() == comp.band_sigma() and "map5.nc, map6.nc" == g.source
    # one map: the map's own spectrum, whose band sigma is the unbinned periodogram's
    one = map_psd(maps[0])
    assert one.sigma(1e5, 5e5) == labbrdf.psd(maps[0], kind="2d").composite.band_sigma(1e5, 5e5)


def test_a_gap_between_the_maps_bands_is_not_filled():
    """Bands 1.6e4-1e6 and 2e6-1.3e8 1/m: between them the PSD is 0, not interpolated."""
    g = group_psd([_sized(7, SIZE), _sized(8, SIZE / 128)])
    ((lo, hi),) = g.gaps
    assert lo == pytest.approx(N / (2 * SIZE)) and hi == pytest.approx(128 / SIZE)
    f = np.array([0.5 * (lo + hi), 0.9 * lo, 1.1 * hi])
    assert g.covers(f).tolist() == [False, True, True]
    p = g.psd2d(f, 0 * f)
    assert p[0] == 0 and p[1] > 0 and p[2] > 0


def test_a_coated_sample_is_predicted_through_its_stack(tmp_path):
    """predict_rr_brdf(stack=...) is the correlated stack's Rayleigh-Rice at every point;
    a film of no thickness gives the bare substrate's prediction to rounding."""
    from labbrdf import films, models
    from labbrdf.nk.dispersion import Cauchy, Constant
    from labbrdf.roughness import rr_stack
    from labbrdf.writers.zemax import model_to_bsdf

    sub = Constant(1.55, 7.71)
    stack = films.Stack([films.Layer(Cauchy(A=1.46, B=0.003, C=0.0), 120.0, "coat")], sub)
    bsdf = model_to_bsdf(
        models.get("rayleigh_rice", film=stack),
        {"A": 1e-5, "B": 5.0, "C": 1.6},
        tmp_path / "coated.bsdf",
        theta_i_deg=[10.0, 50.0],
        radial_deg=[0.0, 3.0, 10.0, 30.0],
        azimuth_deg=[0.0, 90.0, 180.0],
        wavelength_nm=633.0,
    )
    psd = map_psd(_map(_surface(9)))
    p = predict_rr_brdf(bsdf, None, psd, stack=stack)
    assert p.coating.startswith("coat 120 nm, 1.4") and (p.n, p.k) == (1.55, 7.71)
    n, d = rr_stack.stack_layers(stack, 633.0)
    a = p.above
    ti = np.broadcast_to(p.theta_i_deg[:, None, None], a.shape)[a]
    want = rr_stack.stack_brdf(
        np.radians(ti),
        np.radians(p.theta_r_deg[a]),
        np.radians(p.phi_r_deg[a]),
        633e-9,
        n,
        d,
        psd.psd2d,
        "correlated",
    )
    np.testing.assert_allclose(p.predicted[a], want, rtol=1e-13)
    bare = predict_rr_brdf(bsdf, None, psd, substrate_index=1.55 + 7.71j)
    assert not np.allclose(bare.predicted, p.predicted)
    thin = predict_rr_brdf(bsdf, None, psd, stack=stack.with_values({"coat.thickness_nm": 0.0}))
    np.testing.assert_allclose(thin.predicted, bare.predicted, rtol=1e-12)
    slab = films.Stack(stack.layers, sub, substrate_thickness_nm=1e6)
    with pytest.raises(PredictionError, match="coated.bsdf: the film stack: .*coherent"):
        predict_rr_brdf(bsdf, None, psd, stack=slab)
    with pytest.raises(PredictionError, match="633 nm lies outside the film fit's wavelengths"):
        predict_rr_brdf(bsdf, None, psd, stack=stack, stack_range=(700.0, 900.0))
