"""Fixtures of the roughness tests: seeded periodic random surfaces with a prescribed PSD.

White noise filtered by sqrt(PSD).

For unit white noise ``w`` and ``z = ifft(fft(w) H)``, the periodogram of ``z`` (the
normalisation of :mod:`labbrdf.roughness.psd`) has expectation ``dx dy H^2`` at each grid
frequency: ``H = sqrt(PSD2(f) / (dx dy))`` makes it the model PSD exactly (the surface is
periodic, so there is no leakage; no power above the Nyquist frequency).
"""

from __future__ import annotations

import types

import numpy as np
import pytest

from labbrdf.roughness import psd_models as pm


def surface(name: str, params: tuple[float, ...], n: int, dx: float, seed: int) -> np.ndarray:
    """An ``n x n`` map [m] with pixel ``dx`` [m] whose 2-D PSD is the model's."""
    rng = np.random.default_rng(seed)
    fx = np.fft.fftfreq(n, dx)
    f = np.hypot(fx[:, None], fx[None, :])
    f[0, 0] = 1.0
    h = np.sqrt(pm.PSD_MODELS[name].psd_2d(f, *params) / (dx * dx))
    h[0, 0] = 0.0
    return np.fft.ifft2(np.fft.fft2(rng.standard_normal((n, n))) * h).real


def profile(name: str, params: tuple[float, ...], n: int, dx: float, seed: int) -> np.ndarray:
    """A profile of ``n`` points [m] whose two-sided PSD is the model's profile form."""
    rng = np.random.default_rng(seed)
    f = np.abs(np.fft.fftfreq(n, dx))
    f[0] = 1.0
    h = np.sqrt(pm.PSD_MODELS[name].psd_1d(f, *params) / dx)
    h[0] = 0.0
    return np.fft.ifft(np.fft.fft(rng.standard_normal(n)) * h).real


@pytest.fixture(scope="session")
def synth() -> types.SimpleNamespace:
    """``synth.surface(name, params, n, dx, seed)`` and ``synth.profile(...)``."""
    return types.SimpleNamespace(surface=surface, profile=profile)
