"""The instrument's aperture: the cone average against brute force, and the bias it removes."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate

from labbrdf import models
from labbrdf.fitting import FitData
from labbrdf.fitting.aperture import fit_with_aperture
from labbrdf.models import ModelError
from labbrdf.models.aperture import Apertured, cap_nodes

SMOOTH = {"A": 2e-5, "B": 1e-4, "g": 2.0}  # shoulder B^(1/g) = 0.01 rad = 0.57 deg


def _brute(tr: float, pr: float, ti: float, a_deg: float) -> float:
    """Mean of the ABg over a cone of half-angle a about (tr, pr), by adaptive quadrature.

    The cone's directions are built here from a rotation matrix (independent of
    :func:`labbrdf.models.aperture.cone_directions`).
    """
    m = models.get("abg")
    n = np.array([math.sin(tr) * math.cos(pr), math.sin(tr) * math.sin(pr), math.cos(tr)])
    e1 = np.cross([0.0, 0.0, 1.0], n) if tr > 0 else np.array([0.0, 1.0, 0.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(n, e1)
    a = math.radians(a_deg)

    def f(t: float, psi: float) -> float:
        d = math.cos(t) * n + math.sin(t) * (math.cos(psi) * e1 + math.sin(psi) * e2)
        th, ph = math.atan2(math.hypot(d[0], d[1]), d[2]), math.atan2(d[1], d[0])
        return float(m.evaluate(ti, th, ph, params=SMOOTH)) * math.sin(t)

    v, _ = integrate.dblquad(f, 0, 2 * math.pi, 0, a, epsabs=0, epsrel=1e-9)
    return v / (2 * math.pi * (1 - math.cos(a)))


@pytest.mark.parametrize("offset_deg", [0.0, 0.8, 1.5])
def test_cone_average_against_brute_force(offset_deg: float) -> None:
    ti = math.radians(20.0)
    tr = math.radians(20.0 + offset_deg)
    ap = Apertured(models.get("abg"), detector_deg=1.0)
    got = float(ap.evaluate(ti, tr, math.pi, params=SMOOTH))
    assert got == pytest.approx(_brute(tr, math.pi, ti, 1.0), rel=1e-5)


def test_cap_weights_are_a_mean() -> None:
    t, psi, w = cap_nodes(2.0, 5, 7)
    assert w.sum() == pytest.approx(1.0, 1e-14)
    a = math.radians(2.0)  # mean of cos t over the cap: (1 + cos a) / 2
    assert np.dot(w, np.cos(t)) == pytest.approx(0.5 * (1 + math.cos(a)), 1e-14)


def test_beam_and_detector_alike_at_normal_incidence() -> None:
    """At theta_i = theta_r = 0 the ABg depends on |beta_s + beta_i|: a cone on either side
    averages the same values."""
    det = Apertured(models.get("abg"), detector_deg=1.0)
    beam = Apertured(models.get("abg"), beam_deg=1.0)
    assert float(beam.evaluate(0.0, 0.0, math.pi, params=SMOOTH)) == pytest.approx(
        float(det.evaluate(0.0, 0.0, math.pi, params=SMOOTH)), rel=1e-12
    )


def test_linear_components_are_averaged_alike() -> None:
    ap = Apertured(models.get("abg", diffuse=True), detector_deg=1.0)
    p = dict(SMOOTH, kd=0.1)
    ti, tr, pr = np.radians([10.0, 30.0]), np.radians([10.5, 35.0]), np.array([np.pi, 3.0])
    comps = ap.linear_components(p, ti, tr, pr, None)
    assert comps is not None and set(comps) == {"A", "kd"}
    np.testing.assert_allclose(
        p["A"] * comps["A"] + p["kd"] * comps["kd"], ap.evaluate(ti, tr, pr, params=p)
    )


def _smooth_sample() -> FitData:
    """In-plane scan of a smooth sample through a 1 deg detector cone, 2 % noise."""
    off = np.array([-30, -15, -8, -5, -3, -2, -1.5, -1, -0.75, -0.5, -0.25, 0.0])
    off = np.concatenate([off, -off[-2::-1]])
    ti = np.repeat([10.0, 30.0], off.size)
    sc = np.tile(off, 2) + ti
    tr, pr = np.abs(sc), np.where(sc >= 0, 180.0, 0.0)
    truth = Apertured(models.get("abg"), detector_deg=1.0, nodes=(32, 96))
    y = truth.evaluate(np.radians(ti), np.radians(tr), np.radians(pr), params=SMOOTH)
    y = y * (1 + 0.02 * np.random.default_rng(5).standard_normal(y.size))
    return FitData(ti, tr, y, sigma=0.02 * y, phi_r_deg=pr)


def test_fit_with_aperture_removes_the_bias() -> None:
    cmp = fit_with_aperture("abg", _smooth_sample(), detector_deg=1.0)
    tab = cmp.table()
    for k, v in SMOOTH.items():  # with the aperture: the sample's values
        assert abs(tab.loc[k, "with"] - v) < 3 * tab.loc[k, "stderr_with"], k
    # without: the instrument's width read as the sample's shoulder (B +61 %)
    assert tab.loc["B", "shift_rel"] > 0.3 and tab.loc["B", "shift_sigma"] > 10
    assert cmp.plain.redchi > 5 > 1.5 > cmp.apertured.redchi
    assert "detector 1 deg" in str(cmp)


@pytest.mark.parametrize(
    ("kw", "match"),
    [
        ({"detector_deg": -1.0}, "detector_deg=-1.0: expected a half-angle"),
        ({"beam_deg": 30.0}, r"beam_deg=30.0: expected a half-angle in \[0, 20\]"),
        ({"nodes": (0, 4)}, "nodes=.0, 4.: expected"),
    ],
)
def test_bad_aperture_refused(kw: dict, match: str) -> None:
    with pytest.raises(ModelError, match=match):
        Apertured(models.get("abg"), **kw)
    with pytest.raises(ModelError, match="expected a Model"):
        Apertured("abg")  # type: ignore[arg-type]
