"""Specular DOP for unpolarized light from psi (and depolarization), checked by hand."""

from __future__ import annotations

import numpy as np
import pytest

from labbrdf import optics
from labbrdf.specular_dop import specular_dop

UNPOL = np.array([1.0, 0.0, 0.0, 0.0])
P45 = np.array([1.0, 0.0, 1.0, 0.0])  # the RCE's incident state, linear at 45 deg


def woollam_mueller(psi_deg: float, delta_deg: float) -> np.ndarray:
    """The normalized Mueller matrix [[1,-N,0,0],[-N,1,0,0],[0,0,C,S],[0,0,-S,C]]."""
    p, d = np.radians(psi_deg), np.radians(delta_deg)
    n, c, s = np.cos(2 * p), np.sin(2 * p) * np.cos(d), np.sin(2 * p) * np.sin(d)
    return np.array([[1, -n, 0, 0], [-n, 1, 0, 0], [0, 0, c, s], [0, 0, -s, c]], float)


def dop_of(stokes: np.ndarray) -> float:
    return float(np.sqrt(np.sum(stokes[1:] ** 2)) / stokes[0])


@pytest.mark.parametrize(("psi", "want"), [(45.0, 0.0), (0.0, 1.0), (90.0, 1.0), (30.0, 0.5)])
def test_limits(psi: float, want: float) -> None:
    assert float(specular_dop(psi).dop) == pytest.approx(want, abs=1e-15)


@pytest.mark.parametrize("psi", [3.0, 17.0, 38.0, 44.9, 52.0, 81.0])
@pytest.mark.parametrize("delta", [0.0, 95.0, 171.0, 300.0])
def test_equals_the_mueller_product_by_hand(psi: float, delta: float) -> None:
    m = woollam_mueller(psi, delta)
    assert float(specular_dop(psi).dop) == pytest.approx(dop_of(m @ UNPOL), abs=1e-14)
    # a non-depolarizing matrix: the 45-deg input leaves fully polarized
    assert dop_of(m @ P45) == pytest.approx(1.0, abs=1e-14)


@pytest.mark.parametrize("nk", [1.5 + 0j, 0.96 + 6.69j, 3.9 + 0.02j, 1.55 + 7.71j])
@pytest.mark.parametrize("theta", [10.0, 45.0, 56.3, 70.0, 85.0])
def test_equals_fresnel_mueller_of_a_known_index(nk: complex, theta: float) -> None:
    rs, rp, _, _ = optics.fresnel(1.0, nk, theta)
    out = optics.mueller_reflection(rs, rp) @ UNPOL
    psi, _ = optics.psi_delta(nk, theta)
    assert float(specular_dop(psi).dop) == pytest.approx(float(optics.dop(out)), abs=1e-12)


@pytest.mark.parametrize("d", [0.0, 0.03, 0.4, 1.0])
def test_mixed_depolarizer_weight_is_the_files_depolarization(d: float) -> None:
    psi, delta = 27.0, 120.0
    m = (1 - d) * woollam_mueller(psi, delta) + d * np.diag([1.0, 0.0, 0.0, 0.0])
    # what the instrument reports: 1 - P for its 45-deg input
    assert 1.0 - dop_of(m @ P45) == pytest.approx(d, abs=1e-14)
    assert m[0, 1] == pytest.approx(-(1 - d) * np.cos(np.radians(2 * psi)), abs=1e-15)
    got = specular_dop(psi, depolarization=d).dop
    assert float(got) == pytest.approx(dop_of(m @ UNPOL), abs=1e-14)


def test_retardance_spread_keeps_m12_and_the_dop() -> None:
    psi = 33.0
    deltas = np.linspace(100.0, 160.0, 61)  # a thickness spread: Delta varies, psi does not
    m = np.mean([woollam_mueller(psi, dl) for dl in deltas], axis=0)
    d = 1.0 - dop_of(m @ P45)
    assert d > 0.02  # the spread depolarizes the 45-deg input ...
    got = specular_dop(psi, depolarization=d, depolarizer="retardance").dop
    assert float(got) == pytest.approx(dop_of(m @ UNPOL), abs=1e-14)  # ... but not m12
    mixed = specular_dop(psi, depolarization=d).dop
    assert float(mixed) < float(got)  # the two models bracket the DOP


@pytest.mark.parametrize("depolarizer", ["mixed", "retardance"])
def test_sigma_is_the_first_order_propagation(depolarizer: str) -> None:
    psi, s_psi, d, s_d = 31.0, 0.05, 0.08, 0.01
    r = specular_dop(
        psi,
        psi_sigma_deg=s_psi,
        depolarization=d,
        depolarization_sigma=s_d,
        depolarizer=depolarizer,  # type: ignore[arg-type]
    )

    def f(p: float, dd: float) -> float:
        return float(specular_dop(p, depolarization=dd, depolarizer=depolarizer).dop)  # type: ignore[arg-type]

    h = 1e-6
    dpsi = (f(psi + h, d) - f(psi - h, d)) / (2 * h)
    dd = (f(psi, d + h) - f(psi, d - h)) / (2 * h)
    want = np.hypot(dpsi * s_psi, dd * s_d)
    assert float(r.sigma) == pytest.approx(want, rel=1e-6)
    if depolarizer == "retardance":
        assert dd == 0.0


def test_broadcasts() -> None:
    r = specular_dop(np.array([[10.0], [40.0]]), depolarization=np.array([0.0, 0.5, 1.0]))
    assert r.dop.shape == r.sigma.shape == (2, 3)
    assert np.all(r.dop[:, 2] == 0.0)


@pytest.mark.parametrize(
    ("kw", "match"),
    [
        ({"psi_deg": 91.0}, r"psi_deg: expected finite values in \[0, 90\] deg, got \[91"),
        ({"psi_deg": np.nan}, r"psi_deg: expected finite"),
        ({"psi_deg": 10.0, "psi_sigma_deg": -0.1}, r"psi_sigma_deg"),
        ({"psi_deg": 10.0, "depolarization": 1.2}, r"depolarization: expected .* \[0, 1\]"),
        ({"psi_deg": 10.0, "depolarization_sigma": -1.0}, r"depolarization_sigma"),
        ({"psi_deg": 10.0, "depolarizer": "lambert"}, r"depolarizer 'lambert': expected one of"),
    ],
)
def test_bad_input_is_named(kw: dict, match: str) -> None:
    psi = kw.pop("psi_deg")
    with pytest.raises(ValueError, match=match):
        specular_dop(psi, **kw)
