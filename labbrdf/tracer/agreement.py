"""Agreement of an evaluated trace with a counting trace over every bin of the hemisphere.

A counting bin with few rays has no usable error estimate (its per-ray spread is not yet
Gaussian; an empty bin has none at all), and leaving such bins out of a comparison hides
exactly the places where an evaluated estimator is most likely wrong: the small bins
around the pole and a grazing lobe. Here no bin is left out: bins are pooled, in
row-major order (along the azimuth, then on to the next polar row), into groups of at
least ``min_count`` counted rays, and both traces are compared on the groups' cos-weighted
averages

    f_g = sum_{b in g} f_b Omega_cos(b) / sum_{b in g} Omega_cos(b),

with the counting error from the per-ray spread (each ray lands in one bin, so the
group's sums are sums over rays) and the evaluated error from its batches.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from .result import TraceResult

__all__ = ["Agreement", "agreement", "pool_bins"]


@dataclass(frozen=True)
class Agreement:
    """z statistics of ``(evaluated - counting) / combined SE`` over pooled bins.

    Attributes
    ----------
    z : ndarray, shape (n,)
        Per group and Mueller element compared (where the combined error is not 0).
    groups : ndarray of int, shape (n_bins,)
        Group of every bin (row-major flat index).
    albedo_z : float
        z of the albedos (evaluated: from its batches; counting: from its blocks).
    albedo_ratio : float
        Evaluated albedo / counting albedo.
    """

    z: NDArray[np.float64]
    groups: NDArray[np.int64]
    albedo_z: float
    albedo_ratio: float

    @property
    def rms(self) -> float:
        """RMS of all z values (1 for estimators that agree and calibrated errors)."""
        return float(np.sqrt(np.mean(self.z**2)))

    @property
    def max_abs(self) -> float:
        """Largest |z|."""
        return float(np.max(np.abs(self.z)))

    def __str__(self) -> str:
        return (
            f"{int(self.groups.max()) + 1} groups, {self.z.size} z: RMS {self.rms:.2f}, "
            f"max |z| {self.max_abs:.1f}; albedo ratio {self.albedo_ratio:.4f} "
            f"(z {self.albedo_z:+.1f})"
        )


def pool_bins(counts: NDArray[np.int64], min_count: int) -> NDArray[np.int64]:
    """Group consecutive bins (row-major) until each group holds ``min_count`` rays.

    The last, short group is merged into the one before it. Returns the group of every
    bin (flat).
    """
    c = np.asarray(counts).ravel()
    groups = np.empty(c.size, dtype=np.int64)
    g = acc = 0
    for i, n in enumerate(c):
        groups[i] = g
        acc += int(n)
        if acc >= min_count:
            g += 1
            acc = 0
    if acc < min_count and g > 0:
        groups[groups == g] = g - 1
    return groups


def _group_sum(x: NDArray[np.float64], groups: NDArray[np.int64], n: int) -> NDArray:
    """Sum ``x`` (..., n_bins, k) over the bins of each group -> (..., n, k)."""
    xt = np.moveaxis(x, -2, 0)
    out = np.zeros((n, *xt.shape[1:]))
    np.add.at(out, groups, xt)
    return np.moveaxis(out, 0, -2)


def agreement(
    evaluated: TraceResult,
    counting: TraceResult,
    *,
    min_count: int = 400,
    elements: str = "all",
) -> Agreement:
    """Compare an evaluated trace with a counting trace of the same configuration.

    Parameters
    ----------
    evaluated, counting : TraceResult
        The same grid; the first with batch maps (``estimator="evaluated"``).
    min_count : int
        Rays per pooled group (400: the per-ray error is then near Gaussian), in the
        trace with fewer rays: counting's counts are scaled by ``evaluated.rays /
        counting.rays`` where the evaluated trace has fewer (where its exit is sampled,
        its bins away from the closed-form first surface hold about as many deposits).
    elements : {"all", "m00"}
        Compare all 16 Mueller elements or M00 only (scalar runs).

    Returns
    -------
    Agreement
    """
    if evaluated.batch_mueller is None:
        raise ValueError("agreement needs an evaluated trace (with batch maps) first")
    grid = counting.grid
    omega = grid.cos_solid_angle_sr.ravel()
    scale = max(1.0, counting.rays / evaluated.rays)
    groups = pool_bins(counting.counts, int(np.ceil(min_count * scale)))
    ng = int(groups.max()) + 1
    sel = slice(0, 1) if elements == "m00" else slice(0, 16)
    om_g = np.bincount(groups, weights=omega, minlength=ng)[:, None]
    # counting: per-ray sums over the group's bins
    n = counting.rays
    s = _group_sum(counting.sums.reshape(-1, 16)[:, sel], groups, ng)
    ss = _group_sum(counting.sumsq.reshape(-1, 16)[:, sel], groups, ng)
    ct = s / (n * om_g)
    ct_var = np.maximum(ss / n - (s / n) ** 2, 0.0) / n / om_g**2
    # evaluated: the same average of the mean map and of each batch map
    f = evaluated.mueller.reshape(-1, 16)[:, sel] * omega[:, None]
    ev = _group_sum(f, groups, ng) / om_g
    bm = np.asarray(evaluated.batch_mueller, float)
    bm = bm.reshape(bm.shape[0], -1, 16)[:, :, sel] * omega[None, :, None]
    evb = _group_sum(bm, groups, ng) / om_g
    nb = np.asarray(evaluated.block_rays, float)[:, None, None]
    ev_var = (nb * (evb - ev) ** 2).sum(axis=0) / nb.sum() / (nb.shape[0] - 1)
    se = np.sqrt(ct_var + ev_var)
    # an element the counted rays do not resolve carries no information: zero but for
    # round-off in both (a depolarizing base's off-diagonal elements), or a rare part (the
    # far tail of the closed-form first surface) that no counted ray of the group brought,
    # whose per-ray error is then 0; an element counts if its error is 1 % of M00's
    ok = se > 1e-2 * se[:, :1]
    z = ((ev - ct) / np.where(ok, se, 1.0))[ok]
    a_e, a_c = evaluated.albedo(), counting.albedo()
    za = (a_e - a_c) / float(np.hypot(evaluated.albedo_stderr(), counting.albedo_stderr()))
    return Agreement(z, groups, float(za), float(a_e / a_c))
