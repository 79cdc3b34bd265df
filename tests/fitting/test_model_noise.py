"""A model's own variance (Model.point_variance) in the residual weights of a fit."""

from __future__ import annotations

import math

import numpy as np
import pytest

from labbrdf.fitting import FitData, fit
from labbrdf.models import Model, Parameters


class _NoisyLine(Model):
    """f = a x (x = theta_r [rad]) with a constant model variance ``var`` [sr^-2]."""

    name = "noisy_line"

    def __init__(self, var: float | None = 0.0) -> None:
        self.var = var
        super().__init__()

    def default_params(self) -> Parameters:
        p = Parameters()
        p.add("a", 1.0, 0.0, 10.0)
        return p

    def _evaluate(self, p, theta_i, theta_r, phi_r, wavelength):
        return p["a"] * theta_r

    def point_variance(self, p, theta_i, theta_r, phi_r, wavelength):
        if self.var is None:
            return None
        return np.full(np.shape(theta_r), self.var)


def _data(sigma: float) -> FitData:
    x_deg = np.linspace(5.0, 60.0, 12)
    y = 2.0 * np.radians(x_deg) + sigma * np.where(np.arange(12) % 2, 1.0, -1.0)
    return FitData(
        theta_i_deg=np.full(12, 30.0),
        theta_r_deg=x_deg,
        value=y,
        sigma=np.full(12, sigma),
    )


def test_model_variance_adds_to_sigma_squared_in_chisqr_and_stderr():
    """Linear model, exact: stderr(a) = sqrt((sigma^2 + var) / sum x^2), chi2 scaled."""
    sigma, var = 0.01, 3e-4
    d = _data(sigma)
    x = np.radians(np.asarray(d.theta_r_deg))
    plain = fit(_NoisyLine(None), d, method="LN_BOBYQA")
    noisy = fit(_NoisyLine(var), d, method="LN_BOBYQA")
    assert plain.params["a"].value == pytest.approx(noisy.params["a"].value, rel=1e-8)
    assert plain.chisqr / noisy.chisqr == pytest.approx((sigma**2 + var) / sigma**2, rel=1e-6)
    se = math.sqrt((sigma**2 + var) / float(x @ x))
    assert noisy.params["a"].stderr == pytest.approx(se, rel=1e-4)
    assert plain.params["a"].stderr == pytest.approx(math.sqrt(sigma**2 / float(x @ x)), rel=1e-4)
    assert "Monte Carlo variance" in noisy.weighting
    assert "Monte Carlo" not in plain.weighting


def test_model_variance_is_not_added_without_the_data_sigma():
    """Uniform weights have no absolute scale: the variance would be in other units."""
    d = _data(0.01)
    res = fit(_NoisyLine(3e-4), d, method="LN_BOBYQA", weighting="uniform")
    assert res.weighting.startswith("uniform; the model's Monte Carlo error (median ")
    ref = fit(_NoisyLine(None), d, method="LN_BOBYQA", weighting="uniform")
    assert res.chisqr == pytest.approx(ref.chisqr, rel=1e-10)


class _OffsetNoiseLine(_NoisyLine):
    """f = a x with one fully correlated noise component: a common offset of size ``s``."""

    def point_noise(self, p, theta_i, theta_r, phi_r, wavelength):
        return np.full((1, *np.shape(theta_r)), math.sqrt(self.var))

    def point_variance(self, p, theta_i, theta_r, phi_r, wavelength):
        return np.sum(self.point_noise(p, theta_i, theta_r, phi_r, wavelength) ** 2, axis=0)


def test_correlated_model_noise_enters_through_the_sandwich_covariance():
    """A common offset s on every point: var(a) = sigma^2 / Sx2 + s^2 (Sx)^2 / Sx2^2.

    The least-squares slope through the origin moves by Sx delta / Sx2 for an offset
    delta; treating the offset as independent per point (quadrature only) would give
    (sigma^2 + s^2) / Sx2 instead, several times smaller here.
    """
    sigma, var = 0.01, 3e-4
    d = _data(sigma)
    x = np.radians(np.asarray(d.theta_r_deg))
    sx, sx2 = float(x.sum()), float(x @ x)
    res = fit(_OffsetNoiseLine(var), d, method="LN_BOBYQA")
    expected = math.sqrt(sigma**2 / sx2 + var * sx**2 / sx2**2)
    assert res.params["a"].stderr == pytest.approx(expected, rel=1e-4)
    assert expected > 2 * math.sqrt((sigma**2 + var) / sx2)
