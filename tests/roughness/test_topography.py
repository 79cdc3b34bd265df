"""Roughness statistics (labbrdf.roughness.topography) and the topography file reader."""

from __future__ import annotations

import io
import json
import sys

import numpy as np
import pytest
from scipy import stats

from labbrdf.adapters._base import AdapterError
from labbrdf.roughness.synthetic import gaussian_surface
from labbrdf.roughness.topography import (
    KS_WARN,
    autocorrelation,
    fit_slope_distribution,
    level,
    roughness_statistics,
)

TOPO = "topography"


# ------------------------------------------------------------------ synthetic surfaces
def _fd_slope_rms(sigma, c, d):
    """Expected RMS forward-difference slope of a Gaussian-ACF surface on spacing d:
    E[(h(x+d)-h(x))^2]/d^2 = 2 sigma^2 (1 - exp(-d^2/c^2)) / d^2 (-> 2 sigma^2/c^2)."""
    return np.sqrt(2 * sigma**2 * (1 - np.exp(-(d**2) / c**2))) / d


CASES = [
    # (sigma [m], (c_x, c_y) [m], seed base): isotropic and anisotropic, several sigma/c
    (1e-7, (4e-6, 4e-6), 1000),
    (2e-8, (6e-6, 2.6667e-6), 2000),
    (5e-7, (3e-6, 3e-6), 3000),
]


def test_sigma_c_and_rms_slope_come_back_within_their_uncertainties():
    """20 seeded 128 x 128 maps per case (L/c = 21..48). The jackknife standard uncertainty u
    (B = 9 tiles) gives the 95 % interval +- t_{0.975, B-1} u; the truth must fall inside it
    in >= 90 % of the replicates, per quantity over all cases (60 replicates)."""
    d, n, reps = 1e-6, 128, 20
    hits: dict[str, list[bool]] = {}
    for sigma, (cx, cy), base in CASES:
        truth = {
            "sigma": sigma,
            "c_x": cx,
            "c_y": cy,
            "slope_rms_x": _fd_slope_rms(sigma, cx, d),
            "slope_rms_y": _fd_slope_rms(sigma, cy, d),
        }
        for r in range(reps):
            s = gaussian_surface(n, n * d, sigma, (cx, cy), rng=base + r)
            st = roughness_statistics(s.z, d, blocks=3)
            k = stats.t.ppf(0.975, st.n_blocks - 1)
            for q, v in truth.items():
                hits.setdefault(q, []).append(abs(getattr(st, q) - v) <= k * st.uncertainty[q])
    rates = {q: float(np.mean(h)) for q, h in hits.items()}
    print("coverage of the 95 % intervals:", rates)
    assert all(r >= 0.9 for r in rates.values()), rates


def test_anisotropy_ratio_and_direction():
    s = gaussian_surface(256, 256e-6, 1e-7, (12e-6, 4e-6), rng=7)
    st = roughness_statistics(s.z, 1e-6, blocks=0)
    assert abs(st.anisotropy_ratio - 3) < 0.3
    assert abs(st.anisotropy_angle_deg) < 5  # the long axis is x
    t = roughness_statistics(s.z.T, 1e-6, blocks=0)
    assert abs(abs(t.anisotropy_angle_deg) - 90) < 5
    iso = roughness_statistics(gaussian_surface(256, 256e-6, 1e-7, 6e-6, rng=8).z, 1e-6, blocks=0)
    assert iso.anisotropy_ratio < 1.15
    assert iso.acf_model == "gaussian"
    assert abs(iso.alpha_gaussian_acf - np.sqrt(2) * iso.sigma / iso.c) < 1e-15


def test_exponential_acf_is_recognised():
    rng = np.random.default_rng(4)
    n, d, c = 256, 1.0, 5.0
    k = 2 * np.pi * np.fft.fftfreq(n, d)
    kk = np.hypot(k[:, None], k[None, :])
    psd = (1 + (kk * c) ** 2) ** -1.5  # 2-D spectrum of exp(-r/c)
    z = np.fft.ifft2(np.fft.fft2(rng.standard_normal((n, n))) * np.sqrt(psd)).real
    st = roughness_statistics(z, d, blocks=0)
    assert st.acf_model == "exponential"
    assert abs(st.c_fit_x / c - 1) < 0.2


def test_masked_points_are_ignored_and_acf_is_mask_normalised():
    s = gaussian_surface(128, 128e-6, 1e-7, 5e-6, rng=3)
    rng = np.random.default_rng(0)
    holes = rng.random(s.z.shape) < 0.1
    z = s.z.copy()
    z[holes] = np.nan
    full = roughness_statistics(s.z, 1e-6, blocks=0)
    part = roughness_statistics(z, 1e-6, blocks=0)
    assert part.n_valid == (~holes).sum()
    assert abs(part.sigma / full.sigma - 1) < 0.02
    assert abs(part.c / full.c - 1) < 0.02
    # the same with a boolean mask or a masked array
    m1 = roughness_statistics(s.z, 1e-6, mask=holes, blocks=0)
    m2 = roughness_statistics(np.ma.masked_array(s.z, holes), 1e-6, blocks=0)
    assert m1.sigma == part.sigma == m2.sigma
    rho = autocorrelation(level(z), max_lag=(3, 3))
    assert rho[3, 3] == 1.0


def test_profile_gives_1d_quantities_and_says_alpha_assumes_isotropy():
    s = gaussian_surface(512, 512e-6, 1e-7, 5e-6, rng=9)
    st = roughness_statistics(s.z[:, 0], 1e-6)
    assert st.kind == "profile"
    assert np.isnan(st.slope_rms_y) and np.isnan(st.anisotropy_ratio)
    assert st.c == st.c_x and st.slope_rms == st.slope_rms_x
    assert any("isotropic" in n for n in st.notes)
    json.dumps(st.to_dict())


def test_levelling_removes_polynomials_of_the_given_degree():
    x, y = np.meshgrid(np.arange(40.0), np.arange(30.0), indexing="ij")
    plane = 3 + 0.2 * x - 0.1 * y
    assert np.abs(level(plane)).max() < 1e-12
    quad = plane + 0.01 * x * y - 0.02 * y**2
    assert np.abs(level(quad, 2)).max() < 1e-11
    assert np.abs(level(quad, 1)).max() > 1e-2
    assert abs(np.nanmean(level(np.arange(50.0) ** 2, 0))) < 1e-9


def test_to_dict_is_json_safe_and_frozen():
    st = roughness_statistics(gaussian_surface(64, 64e-6, 1e-7, 4e-6, rng=1).z, 1e-6)
    d = json.loads(json.dumps(st.to_dict(), allow_nan=False))
    assert d["kind"] == "areal" and set(d["uncertainty"]) >= {
        "sigma",
        "c",
        "alpha_gaussian_acf",
        "alpha_ggx_ml",
    }
    assert d["slope_fits"]["best"] in ("ggx", "beckmann")
    with pytest.raises(AttributeError):
        st.sigma = 1.0  # type: ignore[misc]


@pytest.mark.parametrize(
    ("heights", "kw", "match"),
    [
        (np.full((32, 32), np.nan), {}, "no valid"),
        (np.zeros((3, 3)), {}, "at least 8"),
        (np.zeros((4, 4, 4)), {}, "1-D"),
        (np.ones((16, 16)), {"pixel_size": -1.0}, "pixel_size"),
        (np.ones((16, 16)), {"mask": np.zeros((3, 3), bool)}, "mask shape"),
    ],
)
def test_bad_arrays_raise_value_error(heights, kw, match):
    kw.setdefault("pixel_size", 1e-6)
    with pytest.raises(ValueError, match=match):
        roughness_statistics(heights, **kw)


# ------------------------------------------------------------------------ slope fits
def _ggx_slopes(alpha, n, rng):
    u = rng.random(n)
    r = alpha * np.sqrt(u / (1 - u))  # radial CDF r^2 / (a^2 + r^2)
    p = 2 * np.pi * rng.random(n)
    return r * np.cos(p), r * np.sin(p)


def test_ml_alpha_of_ggx_slopes_matches_the_truth_within_its_uncertainty():
    """20 seeded samples of 5000 independent GGX slopes, 2-D and x-marginal (profile) fits:
    every |z| < 3.5 (1 % chance for one of 20 standard normals to exceed it) and the mean
    z^2 inside the 99.8 % chi^2_20 interval."""
    alpha = 0.2
    for dim in (2, 1):
        z = []
        for r in range(20):
            x, y = _ggx_slopes(alpha, 5000, np.random.default_rng(500 + r))
            f = fit_slope_distribution(x, y if dim == 2 else None)
            z.append((f.ggx.alpha - alpha) / f.ggx.alpha_u)
            assert f.best == "ggx"
            assert f.ggx.ks < KS_WARN
        z = np.array(z)
        assert np.all(np.abs(z) < 3.5), z
        lo, hi = stats.chi2.ppf([0.001, 0.999], 20) / 20
        assert lo < np.mean(z**2) < hi, z


def test_ml_alpha_of_beckmann_slopes_and_warning_for_neither():
    rng = np.random.default_rng(3)
    a = 0.15
    x, y = rng.normal(0, a / np.sqrt(2), (2, 20000))  # Beckmann: per-axis variance a^2/2
    f = fit_slope_distribution(x, y)
    assert f.best == "beckmann" and f.warning is None
    assert abs(f.beckmann.alpha - a) < 4 * f.beckmann.alpha_u
    assert f.beckmann.aic < f.ggx.aic
    u = rng.uniform(-1, 1, (2, 20000))  # flat slopes: neither model
    g = fit_slope_distribution(u[0], u[1])
    assert g.warning is not None and str(KS_WARN) in g.warning


# -------------------------------------------------------------------------- real files
pytest.importorskip("SurfaceTopography")


@pytest.fixture(scope="module")
def topo_dir(real_exports):
    d = real_exports / TOPO
    if not d.is_dir():
        pytest.skip(f"{d} absent")
    return d


@pytest.mark.shared
@pytest.mark.parametrize("name", ["metropro-1.dat", "di-1.di", "opdx-3.opdx"])
@pytest.mark.parametrize(("degree", "mode"), [(1, "height"), (2, "curvature")])
def test_real_files_agree_with_surface_topography(topo_dir, name, degree, mode):
    """sigma and RMS slopes equal SurfaceTopography's own functions on the same levelling
    (detrend "height" = mean plane, "curvature" = quadric) to 1e-9 relative, in metres."""
    from SurfaceTopography import read_topography

    from labbrdf.adapters.topography import read_height_map

    path = topo_dir / name
    hm = read_height_map(path)
    ref = read_topography(str(path)).to_unit("m")
    if ref.dim == 1 and degree == 2:
        ref = ref.detrend("curvature")
    else:
        ref = ref.detrend(mode)
    np.testing.assert_allclose(hm.physical_sizes, np.atleast_1d(ref.physical_sizes), rtol=1e-12)
    st = roughness_statistics(hm.heights, hm.pixel_size, degree=degree, blocks=0)
    # SurfaceTopography's ISO names (Sq, Rq, Rdq); the long names are deprecated aliases
    if ref.dim == 2:
        np.testing.assert_allclose(st.sigma, ref.Sq(), rtol=1e-9)
        np.testing.assert_allclose(st.slope_rms, ref.rms_gradient(), rtol=1e-9)
        np.testing.assert_allclose(st.slope_rms_x, ref.Rdq(), rtol=1e-9)
    else:
        np.testing.assert_allclose(st.sigma, ref.Rq(), rtol=1e-9)
        np.testing.assert_allclose(st.slope_rms, ref.Rdq(), rtol=1e-9)


@pytest.mark.shared
def test_real_files_units_and_channels(topo_dir):
    from labbrdf.adapters.topography import read_height_map, topography_statistics

    mp = read_height_map(topo_dir / "metropro-1.dat")
    assert mp.heights.shape == (640, 480)
    np.testing.assert_allclose(mp.physical_sizes, (0.70288e-3, 0.52716e-3), rtol=1e-4)
    di = read_height_map(topo_dir / "di-1.di")
    assert di.channels[:2] == ("Height", "Height") and len(di.channels) == 4
    np.testing.assert_allclose(di.physical_sizes, (500e-9, 500e-9), rtol=1e-12)
    st = topography_statistics(topo_dir / "di-1.di")
    assert 1e-9 < st.sigma < 1e-7  # nanometre-scale AFM roughness, in metres
    assert 1e-8 < st.c < 5e-7
    pr = read_height_map(topo_dir / "opdx-3.opdx")
    assert pr.is_profile and abs(pr.physical_sizes[0] - 49.98e-6) < 0.01e-6
    with pytest.raises(AdapterError, match="opdx-3.opdx.*areal"):
        topography_statistics(topo_dir / "opdx-3.opdx", require_areal=True)
    with pytest.raises(AdapterError, match="di-1.di.*channel"):
        read_height_map(topo_dir / "di-1.di", channel="Nope")


def test_corrupt_unsupported_and_missing_files_name_the_file(tmp_path, real_exports):
    from labbrdf.adapters.topography import read_height_map

    trunc = tmp_path / "cut.di"
    trunc.write_bytes((real_exports / TOPO / "di-1.di").read_bytes()[:30000])
    with pytest.raises(AdapterError, match="cut.di"):
        read_height_map(trunc)
    junk = tmp_path / "junk.bin"
    junk.write_bytes(bytes(range(256)) * 50)
    with pytest.raises(AdapterError, match="junk.bin"):
        read_height_map(junk)
    with pytest.raises(AdapterError, match="nope.dat.*no such file"):
        read_height_map(tmp_path / "nope.dat")
    nan = tmp_path / "nan.txt"
    nan.write_text("\n".join(" ".join(["nan"] * 10) for _ in range(10)))
    with pytest.raises(AdapterError, match="nan.txt"):
        read_height_map(nan, physical_sizes=(1.0, 1.0), unit="um")


def test_matrix_ascii_needs_sizes_and_reads_in_metres(tmp_path):
    from labbrdf.adapters.topography import read_height_map

    z = np.random.default_rng(0).standard_normal((20, 16))
    p = tmp_path / "m.asc"
    np.savetxt(p, z)
    with pytest.raises(AdapterError, match="m.asc.*no lateral size.*--pixel-size"):
        read_height_map(p)
    hm = read_height_map(p, physical_sizes=(16.0, 20.0), unit="um")
    np.testing.assert_allclose(hm.pixel_size, (1e-6, 1e-6))
    np.testing.assert_allclose(np.sort(hm.heights.ravel()), np.sort(z.ravel() * 1e-6))


def test_missing_surface_topography_names_the_extra(monkeypatch, tmp_path):
    from labbrdf.adapters import topography as at

    monkeypatch.setitem(sys.modules, "SurfaceTopography", None)
    with pytest.raises(ImportError, match=r"labbrdf\[topography\]"):
        at.read_height_map(tmp_path / "x.dat")


# ------------------------------------------------------------- bandwidth, dropouts, notes
def test_s_filter_transmits_half_at_the_cutoff_as_iso_16610_61():
    """ISO 16610-61 Gaussian: transmission exp(-pi (a lambda_s / lambda)^2), a = sqrt(ln2/pi):
    0.5 at lambda = lambda_s and 2^(-1/4) = 0.841 at 2 lambda_s (interior of the map, away
    from the border, where the truncated normal kernel is exact to 1e-4)."""
    from labbrdf.roughness.topography import s_filter

    n, d, lam_s = 512, 1e-7, 3.2e-6
    x = np.arange(n) * d
    for lam, want in ((lam_s, 0.5), (2 * lam_s, 2**-0.25), (lam_s / 2, 2.0**-4)):
        z = np.sin(2 * np.pi * x / lam)[:, None] * np.ones(64)[None, :]
        f = s_filter(z, d, lam_s)
        inner = slice(100, n - 100)
        xi = 2 * np.pi * x[inner] / lam
        coef = np.linalg.lstsq(np.column_stack([np.sin(xi), np.cos(xi)]), f[inner, 32])[0]
        assert np.hypot(*coef) == pytest.approx(want, abs=1e-3)


def test_short_cutoff_removes_pixel_noise_and_states_the_bandwidth():
    """AFM-like: a smooth surface (c = 40 px) plus white pixel noise. Without a bandwidth
    the slopes are the noise's; with lambda_s = 8 px they are those of the filtered surface
    plus the little noise left in the band."""
    from labbrdf.roughness.topography import s_filter

    d = 1e-9
    s = gaussian_surface(256, 256 * d, 2e-9, 40 * d, rng=5)
    noise = np.random.default_rng(6).normal(0, 0.5e-9, s.z.shape)
    raw = roughness_statistics(s.z + noise, d, blocks=0)
    cut = roughness_statistics(s.z + noise, d, blocks=0, short_cutoff=8 * d)
    clean = roughness_statistics(s_filter(s.z, d, 8 * d), d, blocks=0)
    rest = roughness_statistics(s_filter(noise, d, 8 * d), d, blocks=0)
    assert raw.slope_rms > 5 * cut.slope_rms
    # the filter is linear and the noise independent: slope variances add (to a few %,
    # the sample cross term)
    assert cut.slope_rms**2 == pytest.approx(clean.slope_rms**2 + rest.slope_rms**2, rel=0.05)
    assert cut.short_cutoff == 8 * d
    assert "short-wavelength cut-off 8 nm" in cut.bandwidth and "ISO 16610-61" in cut.bandwidth
    assert "no S-filter: down to the pixel, 1 nm" in raw.bandwidth
    assert np.isnan(raw.short_cutoff)
    with pytest.raises(ValueError, match="cut-off must be positive"):
        roughness_statistics(s.z, d, short_cutoff=-1.0)


def _dropout_map():
    """Smooth Gaussian surface (sigma 10 nm, c 8 px) with dropouts whose rims carry spikes,
    as an optical profiler's map at edges it cannot follow."""
    d = 1e-6
    s = gaussian_surface(256, 256 * d, 1e-8, 8 * d, rng=9)
    z = np.array(s.z)
    rng = np.random.default_rng(10)
    holes = np.zeros(z.shape, bool)
    for i, j in rng.integers(10, 246, size=(40, 2)):
        holes[i - 2 : i + 3, j - 2 : j + 3] = True
    from scipy import ndimage

    rim = ndimage.binary_dilation(holes) & ~holes
    z[rim] += rng.choice([-1, 1], rim.sum()) * 3e-6  # 300 sigma spikes
    z[holes] = np.nan
    return z, d, s


def test_dropout_rims_are_flagged_and_eroding_the_mask_recovers_the_surface():
    from labbrdf.roughness.topography import C_MIN_PIXELS, erode_mask

    z, d, s = _dropout_map()
    st = roughness_statistics(z, d, blocks=0)
    text = " ".join(st.notes)
    assert "carry" in text and "next to a dropout" in text and "--erode-mask" in text
    assert st.c < C_MIN_PIXELS * d and "pixels (< 2)" in text
    er = roughness_statistics(z, d, blocks=0, erode=1)
    assert not any("carry" in n for n in er.notes) and not any("(< 2)" in n for n in er.notes)
    assert er.n_eroded > 0 and any("eroded by 1 pixels" in n for n in er.notes)
    ref = roughness_statistics(s.z, d, blocks=0)
    assert er.sigma == pytest.approx(ref.sigma, rel=0.05)
    assert er.alpha_ggx_ml == pytest.approx(ref.alpha_ggx_ml, rel=0.05)
    v = np.ones((5, 5), bool)
    v[2, 2] = False
    assert erode_mask(v, 1).sum() == 16 and erode_mask(v, 2).sum() == 0
    assert erode_mask(v, 0).sum() == 24
    full = np.ones((4, 4), bool)
    assert erode_mask(full, 3).all()
    with pytest.raises(ValueError, match="erode pixels"):
        erode_mask(v, -1)


def test_gaussian_map_gets_no_dropout_or_pixel_notes():
    st = roughness_statistics(gaussian_surface(128, 128e-6, 1e-7, 6e-6, rng=2).z, 1e-6, blocks=0)
    assert not any("carry" in n or "(< 2)" in n for n in st.notes)


def test_progress_reports_every_pass_and_chunking_leaves_results_unchanged(monkeypatch):
    from labbrdf.roughness import levelling, slope_fits

    z = gaussian_surface(96, 96e-6, 1e-7, 5e-6, rng=3).z
    calls = []
    a = roughness_statistics(z, 1e-6, blocks=3, progress=lambda i, n: calls.append((i, n)))
    assert calls == [(i, 10) for i in range(1, 11)]
    monkeypatch.setattr(levelling, "_CHUNK", 1000)  # many row blocks in levelling
    monkeypatch.setattr(slope_fits, "_CHUNK", 1000)  # and in the KS distances
    b = roughness_statistics(z, 1e-6, blocks=3)
    for k in ("sigma", "c", "slope_rms", "alpha_ggx_ml", "alpha_gaussian_acf", "height_ks"):
        assert getattr(b, k) == pytest.approx(getattr(a, k), rel=1e-9)
        assert b.uncertainty[k] == pytest.approx(a.uncertainty[k], rel=1e-6)


def test_cli_passes_show_on_the_progress_line_only():
    from labbrdf import progress
    from labbrdf.cli.surface import _report_pass

    tty = _Terminal()
    with progress.shown("labbrdf surface", stream=tty):
        _report_pass(2, 26)
        assert "labbrdf surface: leave-one-block-out passes 2/26" in tty.getvalue()
    assert "\n" not in tty.getvalue()  # one line, redrawn, erased at the end


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_height_map_is_drawn_x_horizontal_y_down_as_gwyddion():
    """An asymmetric map: one raised pixel at x index 2, y index 9 of a 6 x 12 grid with
    dx = 1 um, dy = 0.5 um. Image column = x, row = y, origin top left."""
    from labbrdf.report.figures import height_map_image, surface_figure

    z = np.zeros((6, 12))
    z[2, 9] = 1.0
    img, ext = height_map_image(z, (1e-6, 0.5e-6))
    assert img.shape == (12, 6)
    row, col = np.unravel_index(np.argmax(img), img.shape)
    assert (row, col) == (9, 2)
    assert ext == pytest.approx([0.0, 6.0, 6.0, 0.0])  # x 0..6 um right, y 0..6 um down
    st = roughness_statistics(gaussian_surface(32, 32e-6, 1e-7, 3e-6, rng=1).z, 1e-6, blocks=0)
    assert surface_figure(
        np.random.default_rng(0).normal(size=(32, 16)) * 1e-7, (1e-6, 1e-6), st
    ).startswith("data:image/png")


@pytest.mark.parametrize(
    ("shape", "hole"),
    [
        ((40, 30), (slice(0, 8), slice(0, 6))),
        ((40, 30), (slice(16, 24), slice(12, 18))),
        ((40, 30), (slice(32, 40), slice(24, 30))),
        ((37,), (slice(10, 17),)),
    ],
)
def test_pair_counts_of_a_grid_minus_a_tile_equal_the_fft_counts(shape, hole):
    """The jackknife replicate of a map without dropouts: the interval-overlap counts are
    those the FFT of the indicator gives, so rho is the same to round-off."""
    from scipy import fft as sfft

    from labbrdf.roughness.acf import _correlate_window, _rect_pair_counts

    v = np.ones(shape, bool)
    v[hole] = False
    lag = tuple(n // 2 for n in shape)
    pad = [sfft.next_fast_len(n + m, real=True) for n, m in zip(shape, lag, strict=True)]
    fft_counts = np.round(_correlate_window(v.astype(float), pad, lag))
    np.testing.assert_array_equal(_rect_pair_counts(shape, lag, hole), fft_counts)
    z = np.random.default_rng(1).standard_normal(shape)
    np.testing.assert_allclose(
        autocorrelation(z, v, hole=hole), autocorrelation(z, v), rtol=1e-10, atol=1e-12
    )


# ------------------------------------------------------- non-uniform line scans
def test_non_uniform_profile_statistics_are_those_of_the_measured_points(tmp_path, capsys):
    """A stylus-like scan spaced 0.1-0.2 um: sigma and RMS slope equal SurfaceTopography's
    piecewise-linear values on the measured points after the same detrend. Both sides do
    the same sums on the same parsed numbers (in um there, in m here): 1e-12 relative.
    Before: the grid at the median spacing lost about 13 % of the slope."""
    SurfaceTopography = pytest.importorskip("SurfaceTopography")
    from labbrdf.adapters.topography import read_height_map, topography_statistics
    from labbrdf.cli import main

    rng = np.random.default_rng(7)
    x = np.cumsum(rng.uniform(0.1, 0.2, 3000))  # um
    z = np.cumsum(rng.normal(0.0, 0.004, 3000))  # um, a rough random walk
    p = tmp_path / "dektak.csv"
    p.write_text("\n".join(f"{a:.6f},{b:.6f}" for a, b in zip(x, z, strict=True)) + "\n")
    xs, zs = np.loadtxt(p, delimiter=",", unpack=True)  # the numbers as the file has them
    for degree, mode in ((0, "center"), (1, "height")):
        ref = SurfaceTopography.NonuniformLineScan(xs, zs, unit="um").detrend(detrend_mode=mode)
        st = topography_statistics(p, unit="um", degree=degree, blocks=0)
        assert st.slope_rms_x == pytest.approx(ref.rms_slope_from_profile(), rel=1e-12)
        assert st.slope_rms == st.slope_rms_x
        assert st.sigma == pytest.approx(ref.rms_height_from_profile() * 1e-6, rel=1e-12)
        assert any("measured points" in n for n in st.notes)
    hm = read_height_map(p, unit="um")
    assert hm.pixel_size[0] == pytest.approx(np.min(np.diff(xs)) * 1e-6, rel=1e-9)
    assert main(["surface", str(p), "--unit", "um", "--json", "--blocks", "0"]) == 0
    d = json.loads(capsys.readouterr().out)
    ref = SurfaceTopography.NonuniformLineScan(xs, zs, unit="um").detrend(detrend_mode="height")
    assert d["slope_rms_x"] == pytest.approx(ref.rms_slope_from_profile(), rel=1e-12)


@pytest.mark.parametrize(
    ("degree", "holes", "ndim"), [(1, False, 2), (0, True, 2), (2, True, 2), (1, False, 1)]
)
def test_jackknife_levelling_by_partial_sums_equals_levelling_each_replicate(
    monkeypatch, degree, holes, ndim
):
    """Each replicate's levelling from the whole map's sums less its tile's, against the
    direct levelling of the replicate (the implementation before): the same arithmetic but
    for the order of summation, so the values agree to rounding (a few 1e-12 measured); the
    uncertainties are differences of replicates, 1e-2 of the values, hence rel=1e-6."""
    import labbrdf.roughness.topography as T

    z = gaussian_surface(96, 96e-6, 1e-7, 5e-6, rng=4).z
    z = z + np.linspace(0.0, 3e-7, 96)[:, None]  # a tilt the replicates level differently
    if holes:
        z[10:20, 40:47] = np.nan
    if ndim == 1:
        z = z[5]
    a = roughness_statistics(z, 1e-6, degree=degree, blocks=3)
    direct = lambda self, z, valid, exps: T._level(z, valid, degree)  # noqa: E731
    monkeypatch.setattr(T.NormalSums, "levelled", direct)
    b = roughness_statistics(z, 1e-6, degree=degree, blocks=3)
    assert a.uncertainty.keys() == b.uncertainty.keys() and len(a.uncertainty) > 20
    for k, v in b.uncertainty.items():
        assert a.uncertainty[k] == pytest.approx(v, rel=1e-6, nan_ok=True), k
