"""The weights of a fit: the data's sigmas, relative to the data, or uniform.

One rule for every fit (docs/models.md 5.4): ``weighting="auto"`` uses ``1/sigma^2`` where
the points carry sigmas (the maximum-likelihood weights for Gaussian errors) and weights
relative to the data where they do not (BRDF instruments' errors grow with the signal above
a floor: ``sigma_i = max(|y_i|, floor x max|y|)``).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from .data import FitData, FitError

__all__: list[str] = []


def _weights(fd: FitData, use_sigma: bool | None) -> tuple[NDArray, bool]:
    """Weights 1/sigma^2 (or ones) and whether sigma is used."""
    sig = np.asarray(fd.sigma, float)
    has = np.isfinite(sig)
    if use_sigma is None:
        if has.any() and not has.all():
            raise FitError(
                f"data: sigma is given for {int(has.sum())} of {sig.size} points; "
                "give it for all or pass use_sigma=False to ignore it"
            )
        use_sigma = bool(has.all())
    if not use_sigma:
        return np.ones_like(sig), False
    if not has.all() or np.any(sig <= 0):
        raise FitError("data: use_sigma needs a finite sigma > 0 on every point")
    return 1.0 / sig**2, True


def _weighting(
    fd: FitData, use_sigma: bool | None, weighting: str | None, floor: float
) -> tuple[NDArray, bool, str]:
    """Weights, whether sigma is used, and a one-line description of the weighting."""
    if weighting == "auto":  # sigma on some rows only, or sigma <= 0: refused by _weights
        has_sigma = np.isfinite(np.asarray(fd.sigma, float)).any() and use_sigma is not False
        weighting = None if has_sigma else "relative"
    if weighting is None or weighting == "sigma":
        w, used = _weights(fd, True if weighting == "sigma" else use_sigma)
        return w, used, "1/sigma^2 (the data's sigma)" if used else "uniform"
    if weighting == "uniform":
        return np.ones(len(fd)), False, "uniform"
    if weighting == "relative":
        if not (math.isfinite(floor) and 0 < floor < 1):
            raise FitError(f"relative_floor must be in (0, 1), got {floor!r}")
        y = np.abs(np.asarray(fd.value, float))
        ymax = float(y.max())
        if not ymax > 0:
            raise FitError("weighting='relative' needs a value > 0")
        s = np.maximum(y, floor * ymax)
        return 1.0 / s**2, False, f"relative: sigma = max(|y|, {floor:g} x max|y|)"
    raise FitError(
        f"weighting must be 'auto', 'sigma', 'relative', 'uniform' or None, got {weighting!r}"
    )
