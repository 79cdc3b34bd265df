"""PSDs of height maps: SurfaceTopography's normalisation, Parseval against ``labbrdf surface``,
bins and their uncertainty, the composite.

SI values are tiny: every ``pytest.approx`` has ``abs=0``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from labbrdf.roughness import psd as P
from labbrdf.roughness.topography import level, roughness_statistics

KC = (2.0e-28, 3.0e-6, 2.4)  # K-correlation A [m^4], B [m], C: sigma ~ 10 nm
DX = 1.0e-7


@pytest.fixture(scope="module")
def kc_map(synth):
    return synth.surface("k-correlation", KC, 128, DX, seed=3)


def test_profile_periodograms_are_surface_topography_s(kc_map):
    """Our per-row periodograms average to SurfaceTopography's profile PSD (its arithmetic)."""
    lz = level(kc_map, 1)
    h = P._st_windowed(lz, (DX, DX), "hann", "x")
    f, c, _ = P._row_periodograms(h, DX)
    st = P._st_profile_mean(lz, (DX, DX), "hann")
    np.testing.assert_allclose(c.mean(axis=1)[: st.size], st, rtol=1e-11, atol=0)
    assert f[1] == pytest.approx(1 / (128 * DX), rel=1e-14, abs=0)


@pytest.mark.parametrize("degree", [0, 1, 2])
def test_parseval_map_equals_labbrdf_surface_sigma(kc_map, degree):
    """No window, all frequencies: the 2-D PSD sums to the RMS of the detrended heights."""
    s = P.map_psd(kc_map, DX, window="none", degree=degree)
    st = roughness_statistics(kc_map, DX, degree=degree, blocks=0)
    assert s.band_sigma(0.0, math.inf) == pytest.approx(st.sigma, rel=1e-10, abs=0)


def test_parseval_profile_and_rows(kc_map):
    z = kc_map[:, 5]
    s = P.profile_psd(z, DX, window="none")
    st = roughness_statistics(z, DX, blocks=0)
    assert s.band_sigma(0.0, math.inf) == pytest.approx(st.sigma, rel=1e-10, abs=0)
    # rows of a map (the map detrended as a whole): f > 0 carries each profile's variance
    # about its own mean, averaged over the profiles
    rows = P.profile_psd(kc_map, DX, window="none", degree=0)
    assert rows.band_sigma(0.0, math.inf) ** 2 == pytest.approx(
        np.mean(np.var(kc_map, axis=0)), rel=1e-10, abs=0
    )


def _annulus_filter(z, dx, f1, f2):
    fx = np.fft.fftfreq(z.shape[0], dx)
    fy = np.fft.fftfreq(z.shape[1], dx)
    f = np.hypot(fx[:, None], fy[None, :])
    keep = (f >= f1) & (f <= f2)
    return np.fft.ifft2(np.fft.fft2(z) * keep).real


def test_band_sigma_and_slope_equal_labbrdf_surface_on_the_band_limited_map(kc_map):
    """Parseval over a band: the map filtered to the same annulus, its statistics in real space."""
    f1, f2 = 2.0 / (128 * DX), 0.25 / DX
    s = P.map_psd(kc_map, DX, window="none", degree=0)
    zb = _annulus_filter(kc_map, DX, f1, f2)
    st = roughness_statistics(zb, DX, degree=0, blocks=0)
    assert s.band_sigma(f1, f2) == pytest.approx(st.sigma, rel=1e-9, abs=0)
    # periodic forward differences: exactly the PSD's difference-weighted sum
    gx = (np.roll(zb, -1, 0) - zb) / DX
    gy = (np.roll(zb, -1, 1) - zb) / DX
    g2 = gx**2 + gy**2
    assert s.band_slope(f1, f2, difference=True) == pytest.approx(
        math.sqrt(g2.mean()), rel=1e-9, abs=0
    )
    # labbrdf surface pairs the differences at the (M-1)(N-1) corners without wrapping:
    # the mean over that subset differs from the full mean by at most k max|g2 - mean| / |S|
    sub = g2[:-1, :-1]
    k = g2.size - sub.size
    bound = k * np.max(np.abs(g2 - g2.mean())) / sub.size
    assert abs(st.slope_rms**2 - g2.mean()) <= bound
    # the continuum slope exceeds the difference one by at most 1 / sinc(pi f2 dx)
    ratio = s.band_slope(f1, f2) / s.band_slope(f1, f2, difference=True)
    assert 1.0 < ratio <= 1.0 / np.sinc(f2 * DX) ** 1


def test_bins_are_the_expected_psd_within_their_errors(synth):
    """z statistics of every bin (small ones included) against the model the maps were drawn from.

    A bin mean of ``n`` independent exponential periodogram values has standard deviation
    ``mean / sqrt(n)``: with the expected mean this checks the values (no bias) and the
    count ``n`` (a wrong count of independent values changes the spread of z).
    """
    from labbrdf.roughness.psd_models import k_correlation_2d

    zs, ratio = [], []
    for seed in range(4):
        m = synth.surface("k-correlation", KC, 128, DX, seed)
        s = P.map_psd(m, DX, window="none", degree=0)
        fq, w, ib = s.bin_points()
        expect = np.bincount(ib, weights=k_correlation_2d(fq, *KC) * w)
        zs.append((s.psd - expect) / (expect / np.sqrt(s.n)))
        big = s.n >= 50
        ratio.append(s.u[big] / (expect[big] / np.sqrt(s.n[big])))
    z = np.concatenate(zs)
    # the mean of N unit z lies within 4 / sqrt(N) (4 sigma); their variance is 1 within
    # 4 sqrt(2 / N) (the sampling sd of a variance of N normal values)
    assert abs(z.mean()) < 4 / math.sqrt(z.size)
    assert abs(z.var() - 1) < 4 * math.sqrt(2 / z.size)
    # the sample-spread uncertainty of well-filled bins matches the expected one
    r = np.concatenate(ratio)
    assert abs(r.mean() - 1) < 0.1


def test_band_and_bins(kc_map):
    s = P.map_psd(kc_map[:, :100], DX)
    assert s.band == pytest.approx((1 / (128 * DX), 1 / (2 * DX)), rel=1e-14, abs=0)
    assert s.kind == "2d" and s.unit == "m^4" and "hann" in s.window
    assert np.all(np.diff(s.f) > 0) and np.all(s.u > 0) and np.all(s.n >= 1)
    assert s.f[0] >= s.band[0] and s.f[-1] <= s.band[1]
    p = P.profile_psd(kc_map, DX, axis="y")
    assert p.kind == "1d" and p.unit == "m^3" and p.direction == "y"


@pytest.mark.parametrize(
    ("heights", "match"),
    [
        (np.zeros((10, 40)), "too small"),
        (np.r_[np.ones(40), np.nan, np.ones(40)], "1 undefined height points"),
        (np.zeros((4, 4, 4)), "1-D"),
    ],
)
def test_bad_heights(heights, match):
    with pytest.raises(ValueError, match=match):
        P.profile_psd(heights, DX)


def test_composite_of_two_magnifications_agrees_and_spans_the_union(synth):
    """A coarse and a fine map of one surface model: the overlap agrees, the band is the union."""
    coarse = P.map_psd(
        synth.surface("k-correlation", KC, 128, 4 * DX, 1),
        4 * DX,
        window="none",
        degree=0,
        label="coarse",
    )
    fine = P.map_psd(
        synth.surface("k-correlation", KC, 128, DX, 2), DX, window="none", degree=0, label="fine"
    )
    comp, overlaps = P.composite([coarse, fine])
    assert comp.band == (coarse.band[0], fine.band[1])
    assert len(overlaps) == 1 and overlaps[0].agree, overlaps[0].sentence()
    assert 0.8 < overlaps[0].median_ratio < 1.25
    # a miscalibrated instrument (heights x 2: PSD x 4) is caught
    bad = P.map_psd(
        synth.surface("k-correlation", KC, 128, DX, 2) * 2,
        DX,
        window="none",
        degree=0,
        label="bad",
    )
    _, ov = P.composite([coarse, bad])
    assert not ov[0].agree and "DISAGREE" in ov[0].sentence()


def test_composite_refuses_mixed_kinds(kc_map):
    with pytest.raises(ValueError, match="m\\^3 and m\\^4"):
        P.composite([P.map_psd(kc_map, DX), P.profile_psd(kc_map, DX)])


def test_profile_of_generated_profile_matches_model(synth):
    from labbrdf.roughness.psd_models import k_correlation_1d

    z = synth.profile("k-correlation", KC, 8192, DX / 4, 0)
    s = P.profile_psd(z, DX / 4, window="none", degree=0)
    fq, w, ib = s.bin_points()
    expect = np.bincount(ib, weights=k_correlation_1d(fq, *KC) * w)
    z = (s.psd - expect) / s.u
    assert abs(z.mean()) < 4 / math.sqrt(z.size) + 0.1


def test_composite_band_sigma_matches_its_members_and_skips_gaps(synth):
    """The composite's trapezoid sigma over one map's band is that map's Parseval sigma."""
    fine = P.map_psd(
        synth.surface("k-correlation", KC, 128, DX, 2), DX, window="none", degree=0, label="f"
    )
    far = P.map_psd(
        synth.surface("k-correlation", KC, 64, 100 * DX, 1),
        100 * DX,
        window="none",
        degree=0,
        label="far",
    )
    comp, overlaps = P.composite([far, fine])
    assert overlaps == [] and any("no map covers" in n for n in comp.notes)
    lo, hi = fine.f[0], fine.f[-1]
    # bins of 1/10 decade against the exact sum: within the trapezoid error (a few %)
    assert comp.band_sigma(lo, hi) == pytest.approx(fine.band_sigma(lo, hi), rel=0.05, abs=0)
    # across the gap nothing is added
    both = comp.band_sigma(far.f[0], hi) ** 2
    parts = comp.band_sigma(far.f[0], far.f[-1]) ** 2 + comp.band_sigma(lo, hi) ** 2
    assert both == pytest.approx(parts, rel=1e-12, abs=0)
