"""PSD model fits: recovery of known parameters from seeded surfaces, intervals, band."""

from __future__ import annotations

import math

import numpy as np
import pytest

from labbrdf.roughness import psd as P
from labbrdf.roughness.psd_fit import fit_psd
from labbrdf.roughness.psd_models import band_sigma

DX = 1.0e-7
CASES = {
    # surfaces whose PSD is measurable over the whole band (the Gaussian one at the
    # Nyquist frequency still exp(-(pi l f)^2) ~ 1e-7 of its plateau)
    "k-correlation": (2.0e-28, 3.0e-6, 2.4),
    "gaussian": (1.0e-9, 4.0e-7),
    "exponential": (1.0e-9, 1.0e-6),
}


@pytest.mark.parametrize("name", list(CASES))
def test_map_fit_recovers_parameters_within_three_standard_errors(synth, name):
    params = CASES[name]
    z = synth.surface(name, params, 128, DX, seed=11)
    s = P.map_psd(z, DX, window="none", degree=0)
    fit = fit_psd(s, name)
    assert fit.success and fit.kind == "2d"
    assert fit.band == (s.f[0], s.f[-1])
    assert 0.5 < fit.redchi < 2.0
    for (k, v), true in zip(fit.values.items(), params, strict=True):
        assert abs(v - true) < 3 * fit.stderr[k], (k, v, true, fit.stderr[k])
        lo, hi = fit.interval[k]
        assert lo < v < hi


@pytest.mark.parametrize("name", list(CASES))
def test_profile_fit_recovers_parameters(synth, name):
    params = CASES[name]
    z = synth.profile(name, params, 8192, DX / 4, seed=5)
    # a Gaussian profile's PSD is below the synthesis' rounding beyond (pi l f)^2 ~ 30
    f_max = 5.5 / (math.pi * params[1]) if name == "gaussian" else None
    fit = fit_psd(P.profile_psd(z, DX / 4, window="none", degree=0), name, f_max=f_max)
    assert fit.kind == "1d"
    for (k, v), true in zip(fit.values.items(), params, strict=True):
        assert abs(v - true) < 3 * fit.stderr[k], (k, v, true, fit.stderr[k])


def test_fit_band_is_stated_and_respected(synth):
    z = synth.surface("k-correlation", CASES["k-correlation"], 128, DX, seed=2)
    s = P.map_psd(z, DX, window="none", degree=0)
    fit = fit_psd(s, "k-correlation", f_min=2e5, f_max=2e6)
    assert 2e5 <= fit.band[0] < fit.band[1] <= 2e6
    assert fit.ndata == int(np.count_nonzero((s.f >= 2e5) & (s.f <= 2e6)))
    expected = band_sigma("k-correlation", tuple(fit.values.values()), *fit.band)
    assert fit.sigma_band == pytest.approx(expected, rel=1e-12, abs=0)
    assert "over 2" in str(fit) and "K-corr" not in str(fit)
    d = fit.to_dict()
    assert set(d["interval_95"]) == {"A", "B", "C"} and d["units"]["A"] == "m^4"


def test_a_model_of_the_wrong_shape_says_its_parameters_are_a_compromise(synth):
    z = synth.surface("k-correlation", CASES["k-correlation"], 128, DX, seed=11)
    s = P.map_psd(z, DX, window="none", degree=0)
    right, wrong = fit_psd(s, "k-correlation"), fit_psd(s, "gaussian")
    assert not any("does not describe" in n for n in right.notes)
    assert wrong.redchi > 2 and any("does not describe this spectrum" in n for n in wrong.notes)
    assert "does not describe" in str(wrong)


def test_fit_is_reproducible(synth):
    z = synth.surface("exponential", CASES["exponential"], 64, DX, seed=4)
    s = P.map_psd(z, DX, window="none", degree=0)
    a, b = fit_psd(s, "exponential", seed=3), fit_psd(s, "exponential", seed=3)
    assert a.values == b.values


def test_too_few_bins_and_unknown_model(synth):
    z = synth.surface("exponential", CASES["exponential"], 64, DX, seed=4)
    s = P.map_psd(z, DX)
    with pytest.raises(ValueError, match="needs at least 5"):
        fit_psd(s, "k-correlation", f_min=1e6, f_max=1.2e6)
    with pytest.raises(KeyError, match="unknown PSD model"):
        fit_psd(s, "abc")
    assert math.isfinite(fit_psd(s, "fractal").values["n"])
