"""The psi/Delta inversion, its condition number and uncertainties (labbrdf.ellipsometry)."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp
from scipy import optimize

import labbrdf
from labbrdf import ellipsometry as ell
from labbrdf import optics
from labbrdf.films import onefilm

# --------------------------------------------------------------------------------------
# an independent two-phase inversion: forward Fresnel written here, solved numerically
# --------------------------------------------------------------------------------------


def _rho_of_w(w: np.ndarray, theta_deg: np.ndarray) -> np.ndarray:
    """rp/rs of a bare substrate in air as a rational function of ``w = N cos(theta_t)``.

    Born and Wolf 1.5.2 with exp(-i omega t): ``rs = (c - w)/(c + w)``,
    ``rp = (N^2 c - w)/(N^2 c + w)`` and ``N^2 = w^2 + sin^2(theta)`` (Snell). Written in
    ``w`` there is no square root, hence no branch cut for the solver to trip over; the
    two roots ``+-w`` of one ``N^2`` give ``rho`` and ``1/rho``, so exactly one solves.
    """
    t = np.radians(theta_deg)
    c, s = np.cos(t), np.sin(t)
    eps = w * w + s * s
    return ((eps * c - w) / (eps * c + w)) * ((c + w) / (c - w))


def _independent_nk(psi_deg, delta_deg, theta_deg) -> tuple[np.ndarray, np.ndarray]:
    """Solve rho(w) = tan(psi) exp(-i Delta) for w (grid start, secant), then N.

    A bare substrate has ``|r_p| <= |r_s|`` (psi <= 45 deg). A film can give psi > 45 deg;
    no passive substrate has that rho, and the two-phase pseudo-index is defined by the
    closed form, which depends on rho through ((1 - rho)/(1 + rho))^2 only, so it is the
    same for rho and 1/rho. There the solver is given 1/rho, which a substrate does have.
    """
    psi, delta, theta = (np.asarray(a, dtype=float) for a in (psi_deg, delta_deg, theta_deg))
    target = np.tan(np.radians(psi)) * np.exp(-1j * np.radians(delta))
    target = np.where(np.abs(target) > 1.0, 1.0 / target, target)
    radius, phase = np.meshgrid(np.geomspace(0.01, 50.0, 160), np.linspace(0, 2 * np.pi, 120))
    grid = (radius * np.exp(1j * phase)).ravel()  # polar grid: |w| from 0.01 to 50
    start = np.empty(psi.shape, dtype=complex)
    with np.errstate(all="ignore"):
        for th in np.unique(theta):
            idx = np.flatnonzero(theta == th)
            rho_grid = np.nan_to_num(_rho_of_w(grid, np.full(grid.shape, th)), nan=1e300)
            for chunk in np.array_split(idx, max(1, idx.size // 200)):
                dist = np.abs(rho_grid[None, :] - target[chunk, None])
                start[chunk] = grid[np.argmin(dist, axis=1)]
        w = optimize.newton(
            lambda x: _rho_of_w(x, theta) - target, start, tol=1e-14, maxiter=200, disp=False
        )
        residual = np.abs(_rho_of_w(w, theta) - target)
    big_n = np.sqrt(w * w + np.sin(np.radians(theta)) ** 2)
    big_n = np.where(big_n.real + big_n.imag < 0, -big_n, big_n)  # N and -N: same rho
    return big_n, residual < 1e-12 * np.maximum(1.0, np.abs(target))


def _psi_delta_files(real_exports: Path) -> list[Path]:
    out = []
    for p in sorted(real_exports.rglob("*")):
        if p.is_dir() or p.suffix == ".md" or "topography" in p.parts:
            continue
        try:
            m = labbrdf.read(p)
        except Exception:  # noqa: BLE001 - not a supported export
            continue
        if (m.data["quantity"] == "psi").any():
            out.append(p)
    return out


def test_inversion_matches_independent_solver_on_every_real_psi_delta_file(real_exports):
    from labbrdf import nk

    files = _psi_delta_files(real_exports)
    assert len(files) >= 10
    worst = 0.0
    for path in files:
        t = nk.nk_table(labbrdf.read(path), on_ill_conditioned="warn")
        root, converged = _independent_nk(t["psi_deg"], t["delta_deg"], t["theta_i_deg"])
        assert converged.all(), path.name
        ours = t["n"].to_numpy() + 1j * t["k"].to_numpy()
        err = np.abs(root - ours) / np.maximum(1.0, np.abs(ours))
        worst = max(worst, float(err.max()))
        assert err.max() < 1e-9, (path.name, float(err.max()))
    print(f"worst relative difference from the independent solver: {worst:.2e}")


# --------------------------------------------------------------------------------------
# the closed-form inversion: round trips, branches, shapes and error paths
# --------------------------------------------------------------------------------------

EPS = np.finfo(float).eps
N_AL = 1.55 + 7.71j


def test_inversion_with_a_non_unit_ambient():
    psi, delta = optics.psi_delta(2.0 + 0.5j, 65.0, n_ambient=1.33)
    n = ell.nk_from_psi_delta(psi, delta, 65.0, n_ambient=1.33)
    assert abs(n - (2.0 + 0.5j)) <= 1e-13


def test_inversion_accepts_delta_in_any_period():
    psi, delta = optics.psi_delta(N_AL, 70.0)
    a = ell.nk_from_psi_delta(psi, delta, 70.0)
    b = ell.nk_from_psi_delta(psi, delta - 360.0, 70.0)
    assert abs(a - b) <= 1e-13


def test_inversion_of_slightly_negative_im_eps_for_a_metal_keeps_k_positive():
    # n = 0 metal: N^2 = -k^2 is real and psi = 45 deg exactly; psi a hair above 45 deg
    # (noise) gives Im(N^2) = -1.8e-7 < 0. The principal root would return k = -4; the
    # branch rule returns n = -2.3e-8, k = +4.
    psi, delta = optics.psi_delta(4.0j, 60.0)
    n = ell.nk_from_psi_delta(psi + 1e-7, delta, 60.0)
    assert n.imag == pytest.approx(4.0, rel=1e-12)
    assert -1e-7 < n.real < 0


def test_inversion_of_a_noisy_dielectric_reports_negative_k_rather_than_clipping():
    psi, delta = optics.psi_delta(1.5, 45.0)
    n = ell.nk_from_psi_delta(psi, delta + 0.01, 45.0)
    assert n.imag < 0  # docs/models.md 3.2: do not clip silently
    assert n.real == pytest.approx(1.5, abs=1e-3)


def _relative_inversion_error(n: np.ndarray, theta: np.ndarray) -> np.ndarray:
    psi, delta = optics.psi_delta(n, theta)
    # accuracy, not the warning, is checked here (the flags are tested below)
    back = ell.nk_from_psi_delta(psi, delta, theta, on_ill_conditioned="ignore")
    return np.abs(back - n) / np.abs(n)


_SIZE = 100


@st.composite
def _well_conditioned_samples(draw):
    """(N, theta) arrays from the well-conditioned domain of the two-phase inversion.

    * theta in [20, 85] deg: towards 0 deg rho -> -1 and psi, Delta stop depending on N
      (the inversion diverges like 1/theta^2); towards 90 deg every N gives rho -> 1.
    * absorbers: n in [0.05, 10], k in [0.01, 10], |N| >= 0.25. A weak absorber with
      |N| < sin(theta) reflects almost totally (psi -> 45 deg), and N is carried by the
      tiny deviation of psi from 45 deg; the |N| floor keeps that corner out.
    * lossless dielectrics: n in [1.2, 10], k = 0. Close to the ambient (n -> 1) rs and rp
      both vanish and psi loses relative accuracy like eps/|N - 1|.
    Within this domain a random scan of 4e5 points gave a worst relative error of 7e-14.
    """

    # fill=nothing(): every element is drawn (no constant background), 100 points per example
    def arr(dtype, elements):
        return draw(hnp.arrays(dtype, _SIZE, elements=elements, fill=st.nothing()))

    theta = arr(float, st.floats(20.0, 85.0))
    n = arr(float, st.floats(0.05, 10.0))
    k = arr(float, st.floats(0.01, 10.0))
    dielectric = arr(bool, st.booleans())
    big = np.hypot(n, k)
    scale = np.where(big < 0.25, 0.25 / big, 1.0)
    absorber = n * scale + 1j * k * scale
    lossless = np.clip(n, 1.2, 10.0) + 0j
    return np.where(dielectric, lossless, absorber), theta


# vector draws are deliberately large (the health check flags that); derandomize and no
# database make the run reproducible
@settings(
    max_examples=100,
    deadline=None,
    derandomize=True,
    database=None,
    suppress_health_check=[HealthCheck.large_base_example, HealthCheck.too_slow],
)
@given(_well_conditioned_samples())
def test_psi_delta_round_trip_to_1e_12_in_the_well_conditioned_domain(sample):
    n, theta = sample
    err = _relative_inversion_error(n, theta)
    assert np.all(err <= 1e-12), (n[np.argmax(err)], theta[np.argmax(err)], err.max())


def test_psi_delta_round_trip_error_scales_with_the_condition_number():
    # Condition-number-scaled criterion on a seeded wide grid (theta 5..88 deg, metals and
    # dielectrics): |dN|/|N| <= 16 eps K with
    # K = 1 + |dN/drho| |rho| / |N| * (psi/(sin psi cos psi) + |Delta| + 1), the
    # amplification of one rounding of rho, psi and Delta (radians). 16 allows for the
    # ~10 roundings in the forward and inverse chain; the worst ratio seen is 4.6.
    rng = np.random.default_rng(20261122)
    m = 20000
    n = 10 ** rng.uniform(-1, 1.3, m) + 1j * 10 ** rng.uniform(-2, 1.3, m)
    theta = rng.uniform(5.0, 88.0, m)
    keep = np.abs(n) >= 0.5
    n, theta = n[keep], theta[keep]
    err = _relative_inversion_error(n, theta)
    psi, delta = optics.psi_delta(n, theta)
    p, d, t = np.radians(psi), np.radians(delta), np.radians(theta)
    rho = np.tan(p) * np.exp(-1j * d)
    u = (1 - rho) / (1 + rho)
    dn_drho = np.sin(t) ** 2 * np.tan(t) ** 2 * u * (-2 / (1 + rho) ** 2) / n
    cond = 1 + np.abs(dn_drho) * np.abs(rho) / np.abs(n) * (
        p / (np.sin(p) * np.cos(p)) + np.abs(d) + 1
    )
    ratio = err / (EPS * cond)
    assert np.all(ratio <= 16), (n[np.argmax(ratio)], theta[np.argmax(ratio)], ratio.max())
    assert cond.max() > 1e3  # the grid does reach ill-conditioned points


_THETA_GRID = np.array([[[5.0], [30.0], [60.0]], [[0.0], [45.0], [89.0]]])  # (2, 3, 1)
_N_ROW = np.array([1.5, N_AL, 0.7, 2.0 + 0.1j])  # (4,)


def _inverted(n, t):
    t = np.clip(t, 1, 89)
    return (ell.nk_from_psi_delta(*optics.psi_delta(n, t), t, on_ill_conditioned="ignore"),)


def test_inversion_scalar_ndarray_and_broadcast_inputs_agree():
    grid = _inverted(_N_ROW, _THETA_GRID)
    for out in grid:
        assert out.shape[:3] == (2, 3, 4)
    for i, j, k in np.ndindex(2, 3, 4):
        scalar = _inverted(_N_ROW[k], float(_THETA_GRID[i, j, 0]))
        for a, b in zip(grid, scalar, strict=True):
            assert isinstance(b, np.ndarray)
            # numpy's SIMD loops for complex exp and division may round 1 ulp differently
            # from the scalar path; a few eps of the O(1) results allows that, nothing more
            np.testing.assert_allclose(a[i, j, k], b, rtol=4 * EPS, atol=4 * EPS)
    flat = _inverted(_N_ROW, np.full(4, 30.0))
    for a, b in zip(_inverted(_N_ROW, _THETA_GRID), flat, strict=True):
        np.testing.assert_allclose(a[0, 1], b, rtol=4 * EPS, atol=4 * EPS)


def test_inversion_has_no_runtime_warning_at_the_edges_of_the_valid_domain():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        ell.nk_from_psi_delta([0.0, 90.0], [0.0, 180.0], 45.0)


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (
            lambda: ell.nk_from_psi_delta(95.0, 100.0, 60.0),
            r"psi_deg: expected psi in \[0, 90\]",
        ),
        (
            lambda: ell.nk_from_psi_delta(-1.0, 100.0, 60.0),
            r"psi_deg: expected psi in \[0, 90\]",
        ),
        (lambda: ell.nk_from_psi_delta(30.0, np.nan, 60.0), r"delta_deg: expected finite"),
        (
            lambda: ell.nk_from_psi_delta(30.0, 100.0, 0.0),
            r"theta_deg: .*open interval \(0, 90\)",
        ),
        (
            lambda: ell.nk_from_psi_delta(30.0, 100.0, 90.0),
            r"theta_deg: .*open interval \(0, 90\)",
        ),
        (lambda: ell.nk_from_psi_delta(45.0, -180.0, 60.0), r"psi_deg, delta_deg: \(45, 180\)"),
        (lambda: ell.nk_from_psi_delta(30, 100, 60, n_ambient=-1.0), r"n_ambient: expected"),
        (
            lambda: ell.nk_from_psi_delta(30, 100, 60, on_ill_conditioned="loud"),
            r"on_ill_conditioned: expected 'raise', 'warn' or 'ignore'; got 'loud'",
        ),
        (
            lambda: ell.pseudo_nk(30, 100, 60, on_ill_conditioned="loud"),
            r"on_ill_conditioned: expected 'raise', 'warn' or 'ignore'; got 'loud'",
        ),
    ],
)
def test_invalid_inversion_input_raises_value_error_naming_the_argument(call, match):
    with pytest.raises(ValueError, match=match):
        call()


# --------------------------------------------------------------------------------------
# Jacobian and Monte Carlo
# --------------------------------------------------------------------------------------


@pytest.mark.parametrize("big_n", [1.5, 3.88 + 0.02j, 2.0 + 3.0j, 0.2 + 3.5j])
def test_jacobian_matches_central_differences(big_n):
    theta = np.array([45.0, 65.0, 75.0])
    psi, delta = optics.psi_delta(big_n, theta)
    _, d_psi, d_delta, d_theta = ell.nk_jacobian(psi, delta, theta)
    h = 1e-5  # [deg]; truncation O(h^2 N''') ~ 1e-12, round-off 1e-16/h ~ 1e-11

    def fd(dp, dd, dt):
        up = ell.nk_from_psi_delta(psi + h * dp, delta + h * dd, theta + h * dt)
        dn = ell.nk_from_psi_delta(psi - h * dp, delta - h * dd, theta - h * dt)
        return (up - dn) / (2 * h)

    np.testing.assert_allclose(d_psi, fd(1, 0, 0), rtol=1e-6, atol=1e-9)
    np.testing.assert_allclose(d_delta, fd(0, 1, 0), rtol=1e-6, atol=1e-9)
    np.testing.assert_allclose(d_theta, fd(0, 0, 1), rtol=1e-6, atol=1e-9)


def _mc(psi, delta, theta, s_psi, s_delta, s_theta, draws, seed):
    rng = np.random.default_rng(seed)
    p = psi + s_psi * rng.standard_normal(draws)
    d = delta + s_delta * rng.standard_normal(draws)
    t = theta + s_theta * rng.standard_normal(draws)
    big_n = ell.nk_from_psi_delta(p, d, t)
    return big_n.real, big_n.imag


@pytest.mark.parametrize(
    ("big_n", "theta", "s_psi", "s_delta", "s_theta"),
    [
        (2.0 + 3.0j, 70.0, 0.03, 0.05, 0.0),  # Ta-like, file-like sigmas
        (3.88 + 0.02j, 60.0, 0.02, 0.1, 0.0),  # Si, weak absorber
        (0.2 + 3.5j, 75.0, 0.01, 0.03, 0.02),  # Ag-like, with an AOI error
    ],
)
def test_sigmas_match_monte_carlo(big_n, theta, s_psi, s_delta, s_theta):
    draws = 40_000  # standard error of a std estimate: sigma/sqrt(2N) = 0.35 %
    psi, delta = optics.psi_delta(big_n, theta)
    res = ell.pseudo_nk(psi, delta, theta, s_psi, s_delta, theta_sigma_deg=s_theta)
    n, k = _mc(psi, delta, theta, s_psi, s_delta, s_theta, draws, seed=1)
    ratio_n = float(np.std(n, ddof=1) / res.n_sigma)
    ratio_k = float(np.std(k, ddof=1) / res.k_sigma)
    assert abs(ratio_n - 1) < 0.05 and abs(ratio_k - 1) < 0.05, (ratio_n, ratio_k)
    corr_mc = np.corrcoef(n, k)[0, 1]
    corr = float(res.nk_cov / (res.n_sigma * res.k_sigma))
    assert abs(corr_mc - corr) < 0.03  # SE of r is (1 - r^2)/sqrt(N) < 0.005


def test_sigmas_match_monte_carlo_on_real_ta_points(real_exports):
    m = labbrdf.read(real_exports / "woollam-wvase-ascii" / "w2_10102006.dat")
    d = m.data
    psi = d[d["quantity"] == "psi"].iloc[[0, 300, 700, 1500, 2000]]
    delta = d[d["quantity"] == "delta"].iloc[[0, 300, 700, 1500, 2000]]
    ratios = []
    for (_, p), (_, q) in zip(psi.iterrows(), delta.iterrows(), strict=True):
        assert p["wavelength_nm"] == q["wavelength_nm"]
        res = ell.pseudo_nk(p["value"], q["value"], p["theta_i_deg"], p["sigma"], q["sigma"])
        n, k = _mc(p["value"], q["value"], p["theta_i_deg"], p["sigma"], q["sigma"], 0, 40_000, 2)
        ratios += [np.std(n, ddof=1) / res.n_sigma, np.std(k, ddof=1) / res.k_sigma]
    ratios = np.asarray(ratios)
    print(f"MC/analytic sigma ratios on Ta: {ratios.min():.4f} .. {ratios.max():.4f}")
    assert np.all(np.abs(ratios - 1) < 0.05)


def test_no_sigma_gives_nan_sigma():
    psi, delta = optics.psi_delta(2 + 3j, 70.0)
    res = ell.pseudo_nk(psi, delta, 70.0)
    assert np.isnan(res.n_sigma) and np.isnan(res.k_sigma) and np.isfinite(res.n)


# --------------------------------------------------------------------------------------
# conditioning near normal incidence
# --------------------------------------------------------------------------------------


def test_near_normal_incidence_raises_with_condition_number_and_angle():
    psi, delta = optics.psi_delta(3.88 + 0.02j, 3.0)
    with pytest.raises(ValueError, match=r"condition number .* at theta_i = 3 deg"):
        ell.pseudo_nk(psi, delta, 3.0)
    with pytest.warns(ell.IllConditionedWarning):
        res = ell.pseudo_nk(psi, delta, 3.0, on_ill_conditioned="warn")
    assert res.cond > ell.COND_MAX
    np.testing.assert_allclose(res.n + 1j * res.k, 3.88 + 0.02j, rtol=1e-9)


def test_moderate_angle_warns_and_oblique_is_silent():
    big_n = 3.88 + 0.02j
    psi, delta = optics.psi_delta(big_n, 15.0)
    with pytest.warns(ell.IllConditionedWarning, match="15 deg"):
        ell.pseudo_nk(psi, delta, 15.0)
    psi, delta = optics.psi_delta(big_n, 70.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        ell.pseudo_nk(psi, delta, 70.0)


def test_condition_number_grows_as_inverse_square_of_angle():
    big_n = 2.0 + 3.0j
    th = np.array([1.0, 2.0])
    psi, delta = optics.psi_delta(big_n, th)
    cond = ell.condition_number(psi, delta, th)
    assert cond[0] / cond[1] == pytest.approx(4.0, rel=0.01)
    psi, delta = optics.psi_delta(big_n, 70.0)
    assert ell.condition_number(psi, delta, 70.0) < 5


@pytest.mark.parametrize("n", [1.5 + 0j, 3.9 + 0.02j, 2.3 + 3.0j])
@pytest.mark.parametrize("theta", [2.0, 10.0, 45.0, 75.0])
def test_condition_number_is_the_spectral_norm_of_the_finite_difference_jacobian(n, theta):
    # Independent of the closed form: the real 2x2 Jacobian of (n, k) with respect to
    # (psi, Delta) [per rad] by central differences of the inversion, its largest singular
    # value over |N| (this also checks ||J||_2 = |dN/dpsi|). Step 1e-5 deg = 1.7e-7 rad:
    # truncation ~ (h kappa)^2 <= 5e-8 for kappa <= 1.3e3 (glass at 2 deg), round-off
    # ~ eps / h = 1.3e-9 relative; rtol 1e-6.
    psi, delta = optics.psi_delta(n, theta)
    h = 1e-5

    def column(dp, dd):
        up = ell.nk_from_psi_delta(
            psi + h * dp, delta + h * dd, theta, on_ill_conditioned="ignore"
        )
        dn = ell.nk_from_psi_delta(
            psi - h * dp, delta - h * dd, theta, on_ill_conditioned="ignore"
        )
        d = (up - dn) / (2 * np.radians(h))
        return [d.real, d.imag]

    jac = np.array([column(1, 0), column(0, 1)]).T
    big_n = ell.nk_from_psi_delta(psi, delta, theta, on_ill_conditioned="ignore")
    kappa_fd = np.linalg.norm(jac, 2) / abs(big_n)
    assert ell.condition_number(psi, delta, theta) == pytest.approx(kappa_fd, rel=1e-6)


def test_inversion_near_normal_incidence_warns_with_the_condition_number():
    psi, delta = optics.psi_delta(1.5 + 0j, 1e-6)
    with pytest.warns(ell.IllConditionedWarning, match=r"condition number up to 2\.54e\+15"):
        got = ell.nk_from_psi_delta(psi, delta, 1e-6)
    assert abs(got - 1.5) > 0.1  # what the warning is about: the index is lost


def test_well_conditioned_inversion_is_silent_and_exact():
    psi, delta = optics.psi_delta(1.5 + 0j, 45.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        got = ell.nk_from_psi_delta(psi, delta, 45.0)
    assert got == pytest.approx(1.5, rel=1e-12)


@pytest.mark.parametrize(
    ("big_n", "warn_between", "max_between"),
    [(1.5 + 0j, (11.0, 13.0), (3.0, 5.0)), (3.88 + 0.02j, (19.0, 21.0), (6.0, 7.0))],
)
def test_thresholds_are_crossed_where_the_documented_angles_say(big_n, warn_between, max_between):
    # COND_WARN = 30 about 12 deg for glass, 20 deg for Si; COND_MAX = 300 about 4 deg for
    # glass, 6 deg for Si (the condition number grows as 1/theta^2)
    for limit, (lo, hi) in ((ell.COND_WARN, warn_between), (ell.COND_MAX, max_between)):
        th = np.array([lo, hi])
        psi, delta = optics.psi_delta(big_n, th)
        cond = ell.condition_number(psi, delta, th)
        assert cond[0] > limit > cond[1]


def _flags(call, mode):
    """(raised, warned) of ``call(mode)``."""
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        try:
            call(mode)
        except ValueError:
            return True, False
    return False, any(issubclass(w.category, ell.IllConditionedWarning) for w in rec)


def test_every_inversion_entry_point_flags_the_same_points_with_the_one_threshold_set():
    # the one condition number: pseudo_nk's cond is condition_number, bit for bit, and the
    # closed-form inversion, pseudo_nk and the microfacet model's psi_delta option warn and
    # refuse at the same points
    big_n = 3.88 + 0.02j
    th = np.array([3.0, 5.0, 8.0, 15.0, 25.0, 70.0])
    psi, delta = optics.psi_delta(big_n, th)
    cond = ell.condition_number(psi, delta, th)
    np.testing.assert_array_equal(
        ell.pseudo_nk(psi, delta, th, on_ill_conditioned="ignore").cond, cond
    )
    assert cond.max() > ell.COND_MAX and cond.min() < ell.COND_WARN
    assert np.any((cond > ell.COND_WARN) & (cond < ell.COND_MAX))
    for p, d, t, c in zip(psi, delta, th, cond, strict=True):
        calls = [
            lambda mode, p=p, d=d, t=t: ell.nk_from_psi_delta(p, d, t, on_ill_conditioned=mode),
            lambda mode, p=p, d=d, t=t: ell.pseudo_nk(p, d, t, on_ill_conditioned=mode),
        ]
        for call in calls:
            assert _flags(call, "warn") == (False, bool(c > ell.COND_WARN)), t
            assert _flags(call, "raise") == (
                bool(c > ell.COND_MAX),
                bool(ell.COND_WARN < c <= ell.COND_MAX),
            ), t
            assert _flags(call, "ignore") == (False, False), t
        model = _flags(
            lambda _, p=p, d=d, t=t: labbrdf.models.get("microfacet", psi_delta=(p, d, t)), None
        )
        assert model == (False, bool(c > ell.COND_WARN)), t


def test_a_non_finite_condition_number_counts_as_ill_conditioned():
    cond = np.array([2.0, np.nan, 50.0])
    with pytest.raises(ValueError, match=r"condition number nan > 300 at theta_i = 4 deg"):
        ell._check_conditioning(cond, np.array([70.0, 4.0, 15.0]), "raise")
    with pytest.warns(ell.IllConditionedWarning, match=r"at 2 point\(s\)"):
        ell._check_conditioning(cond, np.array([70.0, 4.0, 15.0]), "warn")


# --------------------------------------------------------------------------------------
# combining angles
# --------------------------------------------------------------------------------------


def _film_psi_delta(n_film, n_sub, d_nm, wl_nm, theta):
    rs, rp = onefilm.film_amplitudes(1.0, n_film, n_sub, d_nm, wl_nm, theta)
    psi = np.degrees(np.arctan2(np.abs(rp), np.abs(rs)))
    delta = np.mod(np.degrees(np.angle(rs * np.conj(rp))), 360.0)
    return psi, delta


def _combined(d_nm, s_psi, s_delta, rng=None):
    theta = np.array([65.0, 70.0, 75.0])
    psi, delta = _film_psi_delta(1.46, 3.88 + 0.02j, d_nm, 633.0, theta)  # SiO2 on Si
    if rng is not None:
        psi = psi + s_psi * rng.standard_normal(3)
        delta = delta + s_delta * rng.standard_normal(3)
    r = ell.pseudo_nk(psi, delta, theta, s_psi, s_delta)
    return ell.combine_angles(r.n, r.k, theta, r.covariance())


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_bare_substrate_is_not_angle_dependent(seed):
    c = _combined(0.0, 0.02, 0.05, np.random.default_rng(seed))
    assert c.dof == 4 and c.method == "sigma" and not c.angle_dependent
    assert abs(c.n - 3.88) < 4 * c.n_sigma and abs(c.k - 0.02) < 4 * c.k_sigma


def test_thin_oxide_shifts_pseudo_constants_but_hardly_their_angle_dependence():
    # 5 nm SiO2 on Si at 633 nm, 65/70/75 deg: <k> moves from 0.02 to 0.37 (> 100 sigma),
    # yet the angle-to-angle spread is 0.0014, so with sigma(psi, Delta) = 0.02, 0.05 deg
    # the noise-free chi2 is 0.19: the consistency test does not see a thin film.
    c = _combined(5.0, 0.02, 0.05)
    assert c.k - 0.02 > 100 * c.k_sigma
    assert c.chi2 < 1 and not c.angle_dependent
    # twenty times smaller sigmas (a repeatability-limited instrument) see it
    fine = _combined(5.0, 0.001, 0.0025, np.random.default_rng(0))
    assert fine.angle_dependent, fine
    # and a 100 nm film is flagged at the ordinary sigmas
    thick = _combined(100.0, 0.02, 0.05, np.random.default_rng(0))
    assert thick.angle_dependent and thick.p_value < 1e-6


def test_combination_is_the_weighted_mean_with_chi2():
    n = np.array([2.0, 2.1])
    k = np.array([3.0, 3.0])
    cov = np.array([np.diag([0.01, 0.01]), np.diag([0.04, 0.04])]) ** 1
    c = ell.combine_angles(n, k, [60.0, 70.0], cov)
    # 1-d weighted mean of n with weights 100 and 25
    assert c.n == pytest.approx((2.0 * 100 + 2.1 * 25) / 125)
    assert c.n_sigma == pytest.approx(125**-0.5)
    assert c.chi2 == pytest.approx(100 * (2.0 - c.n) ** 2 + 25 * (2.1 - c.n) ** 2)
    assert c.dof == 2


def test_scatter_rule_without_sigma():
    theta = np.array([55.0, 60.0, 65.0, 70.0, 75.0])
    rng = np.random.default_rng(3)
    flat = ell.combine_angles(2 + 0.01 * rng.standard_normal(5), np.full(5, 3.0), theta)
    assert flat.method == "scatter" and np.isnan(flat.chi2) and flat.dof == 3
    assert not flat.angle_dependent
    trend = ell.combine_angles(2 + 0.01 * (theta - 65) + 1e-4 * rng.standard_normal(5),
                               np.full(5, 3.0), theta)  # fmt: skip
    assert trend.angle_dependent
    one = ell.combine_angles([2.0], [3.0], [70.0])
    assert one.method == "single" and one.dof == 0 and np.isnan(one.p_value)


# --------------------------------------------------------------------------------------
# Fresnel predictions
# --------------------------------------------------------------------------------------


@pytest.mark.parametrize(("n", "k"), [(1.5, 0.0), (3.88, 0.02), (2.0, 3.0), (0.2, 3.5)])
def test_normal_incidence_reflectance_formula(n, k):
    expected = ((n - 1) ** 2 + k**2) / ((n + 1) ** 2 + k**2)
    r, _ = ell.normal_reflectance(n, k)
    assert r == pytest.approx(expected, rel=1e-13)
    res = ell.fresnel_reflectances(n, k, 0.0)
    assert res.rs == pytest.approx(expected, rel=1e-13)
    assert res.rp == pytest.approx(expected, rel=1e-13)


@pytest.mark.parametrize(("n", "k"), [(1.5, 0.0), (3.88, 0.02), (2.0, 3.0), (0.2, 3.5)])
def test_reflectance_sigma_matches_finite_differences(n, k):
    theta = np.array([0.0, 30.0, 60.0, 80.0])
    s_n, s_k, cov = 0.01, 0.02, 0.5 * 0.01 * 0.02
    res = ell.fresnel_reflectances(n, k, theta, n_sigma=s_n, k_sigma=s_k, nk_cov=cov)
    rs0, rp0 = optics.reflectance(1.0, n + 1j * k, theta)
    np.testing.assert_allclose(res.rs, rs0, rtol=1e-14)
    np.testing.assert_allclose(res.rp, rp0, rtol=1e-14)
    h = 1e-6
    k_lo = max(k - h, 0.0)

    def grad(which):
        up = np.asarray(optics.reflectance(1.0, n + h + 1j * k, theta)[which])
        dn = np.asarray(optics.reflectance(1.0, n - h + 1j * k, theta)[which])
        ku = np.asarray(optics.reflectance(1.0, n + 1j * (k + h), theta)[which])
        kd = np.asarray(optics.reflectance(1.0, n + 1j * k_lo, theta)[which])
        return (up - dn) / (2 * h), (ku - kd) / (k + h - k_lo)

    for which, sig in ((0, res.rs_sigma), (1, res.rp_sigma)):
        gn, gk = grad(which)
        expect = np.sqrt((gn * s_n) ** 2 + (gk * s_k) ** 2 + 2 * gn * gk * cov)
        np.testing.assert_allclose(sig, expect, rtol=1e-5, atol=1e-12)
