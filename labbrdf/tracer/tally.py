"""What a block of the walk adds up: the exits binned, the energy ledger, the deposits.

:class:`Ledger` is a block's running account while its rays walk (the exits kept for the
binning, the absorbed and terminated weight, and the evaluated estimator's deposits);
:func:`block_tally` turns it into the block's :class:`BlockTally`, which the driver
(:func:`labbrdf.tracer.walk.trace_group`) folds in block order.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from .binning import Grid, bin_exits
from .config import TraceConfig
from .interfaces import rotate_frame

__all__ = ["BlockTally", "Ledger", "block_tally"]


@dataclass
class BlockTally:
    """What one block contributes (folded by the driver in block order)."""

    block: int
    rays: int
    sums: NDArray[np.float64]  # (n_bins, 16) summed exit Mueller elements
    sumsq: NDArray[np.float64]  # (n_bins, 16) summed squares (per-ray variance)
    counts: NDArray[np.int64]  # (n_bins,) exiting rays
    exited: float
    absorbed: float
    terminated: float
    hemi: NDArray[np.float64]  # (16,) summed exit Mueller over the hemisphere
    events: int
    # estimator="evaluated": Mueller sums of the rays reaching the top interface from
    # below, per (batch, internal cell), flat key batch * n_bins + cell; rays per batch
    cell_keys: NDArray[np.int64] | None = None
    cell_sums: NDArray[np.float64] | None = None  # (len(cell_keys), 16)
    batch_rays: NDArray[np.int64] | None = None  # (batches,)


@dataclass
class Ledger:
    """A block's running sums: the energy ledger, the exiting rays and the deposits."""

    booked: float = 0.0  # evaluated: the sampled weight of the branches not followed
    absorbed: float = 0.0
    terminated: float = 0.0
    events: int = 0
    ex_k: list[NDArray] = field(default_factory=list)
    ex_s: list[NDArray] = field(default_factory=list)
    ex_M: list[NDArray] = field(default_factory=list)
    dep_key: list[NDArray] = field(default_factory=list)
    dep_rows: list[NDArray] = field(default_factory=list)

    def exit(self, k: NDArray, s: NDArray, M: NDArray) -> None:
        """Keep exiting rays for the binning."""
        self.ex_k.append(k)
        self.ex_s.append(s)
        self.ex_M.append(M)


def block_tally(
    cfg: TraceConfig,
    grid: Grid,
    block: int,
    n: int,
    led: Ledger,
    evaluated: bool,
    channels: int = 2,
) -> BlockTally:
    """Bin the exits (and fold the deposits of the evaluated walk) into the block's tally.

    ``channels``: the evaluated walk's deposit channels (``WalkSetup.channels``).
    """
    cell_keys = cell_sums = batch_rays = None
    if evaluated:
        cell_keys, cell_sums, batch_rays = cell_tally(
            cfg, grid, block, n, led.dep_key, led.dep_rows, channels
        )
    sums, sumsq, counts, hemi = bin_exit_rays(grid, led.ex_k, led.ex_s, led.ex_M)
    return BlockTally(
        block=block,
        rays=n,
        sums=sums,
        sumsq=sumsq,
        counts=counts,
        exited=float(hemi[0]) + led.booked,
        absorbed=led.absorbed,
        terminated=led.terminated,
        hemi=hemi,
        events=led.events,
        cell_keys=cell_keys,
        cell_sums=cell_sums,
        batch_rays=batch_rays,
    )


def cell_tally(
    cfg: TraceConfig,
    grid: Grid,
    block: int,
    n: int,
    dep_key: list[NDArray],
    dep_rows: list[NDArray],
    channels: int = 2,
) -> tuple[NDArray[np.int64], NDArray[np.float64], NDArray[np.int64]]:
    """Evaluated estimator: the recorded up-going rays summed per (batch, cell).

    Keys are ``(channel * batches + batch) * n_bins + cell``. Returns the occupied keys,
    their (n_keys, 16) Mueller sums and the rays per batch.
    """
    batch_rays = np.bincount(
        (cfg.block_rays * block + np.arange(n)) % cfg.batches, minlength=cfg.batches
    ).astype(np.int64)
    if not dep_key:
        return np.zeros(0, dtype=np.int64), np.zeros((0, 16)), batch_rays
    key = np.concatenate(dep_key)
    rows_d = np.concatenate(dep_rows, axis=1)
    # the occupied keys only (the channels of multiple scattering make the dense key
    # range large); bincount adds each key's rows in deposit order either way
    cell_keys, inv = np.unique(key, return_inverse=True)
    assert cell_keys[-1] < channels * cfg.batches * grid.n_bins
    sums = np.empty((16, cell_keys.size))
    for e in range(16):
        sums[e] = np.bincount(inv, weights=rows_d[e], minlength=cell_keys.size)
    return cell_keys, sums.T.copy(), batch_rays


def bin_exit_rays(
    grid: Grid, ex_k: list[NDArray], ex_s: list[NDArray], ex_M: list[NDArray]
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.int64], NDArray[np.float64]]:
    """Bin the exited rays in the LB exit frames ``phi_hat(phi)``.

    Returns the per-bin sums and sums of squares (n_bins, 16), the counts and the
    hemispherical sum (16,).
    """
    if not ex_k:
        nb = grid.n_bins
        return np.zeros((nb, 16)), np.zeros((nb, 16)), np.zeros(nb, dtype=np.int64), np.zeros(16)
    ke = np.concatenate(ex_k, axis=1)
    se = np.concatenate(ex_s, axis=1)
    Me = np.concatenate(ex_M, axis=2)
    idx, phi = grid.index(ke)
    s_det = np.stack([-np.sin(phi), np.cos(phi), np.zeros_like(phi)])
    rotate_frame(Me, ke, se, s_det)
    rows = Me.reshape(16, -1)
    sums, sumsq, counts = bin_exits(grid, idx, rows)
    return sums, sumsq, counts, rows.sum(axis=1)
