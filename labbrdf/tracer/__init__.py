"""Monte Carlo polarization ray tracer for rough (coated) surfaces (Dong et al. 2022).

Done rigorously; see ``docs/models.md`` section 6.

>>> from labbrdf.tracer import TraceConfig, Substrate, trace
>>> res = trace(TraceConfig(rays=2000, substrate=Substrate(alpha=0.2), scattering="single"))
>>> 0.7 < res.albedo() < 0.9
True

Model (Dong 2022 sec. 2.3, done rigorously; the departures, each documented where it is
implemented):

* position-free random walk through laterally infinite layers (:mod:`.walk`); the paper
  reconstructs an FFT surface (sec. 2.1, :mod:`labbrdf.roughness.synthetic`) but its algorithm
  samples facet normals from the distribution D, and so do we;
* GGX normals (eq. (14) corrected) sampled as *visible* normals, Smith masking
  (:mod:`labbrdf.microfacet.ggx`); ``scattering="single"`` = one facet event per interface with the
  separable Smith G1 G1 (the model of the SCATMECH/Mitsuba oracles), ``"multiple"`` = the
  Heitz et al. 2016 random walk on each microsurface (energy conserving; its first order
  carries the height-correlated Smith G2);
* Fresnel Mueller matrices from the complex LB amplitudes of :mod:`labbrdf.optics`
  (eqs. (11), (12) corrected), explicit frames rotated with eq. (17) corrected, all as
  structure-aware row updates (:mod:`.interfaces`);
* reflection or refraction chosen with the ray's reflected fraction (the paper's step 3
  uses (Rs + Rp)/2, the same for an unpolarized ray), Beer-Lambert in the coating, the
  threshold tau or Russian roulette;
* bins centred on the 91 x 360 one-degree grid, bin-averaged BRDF normalised by the
  cos-weighted solid angle (:mod:`.binning`).

Beyond the paper: the substrate may be a Lambertian base instead of the conductor
(:meth:`Substrate.lambertian`; paints and plastics under a clear layer), a depolarizing
diffuse reflector re-emitting with the cosine law (``docs/tracer.md``).

Determinism: the rays are split into blocks of ``config.block_rays``; block b draws from
``numpy.random.SeedSequence([seed, b])``. Consecutive blocks form fold groups of
``config.fold_blocks``; a group's tally is the sum of its blocks' tallies in block order,
computed where the group runs, and :func:`trace` adds the group tallies strictly in group
order (``total = total + tally_g``). Work units hold whole groups, so the result is
bit-for-bit the same whatever the number of blocks per work unit and whatever ``map``
(serial, processes, dask) runs the units. Folding on the worker keeps the transfer to one
(n_bins x 33)-float tally per group: with one tally per 32768-ray block, sending it back
(8.6 MB) cost as much as computing it and two processes were no faster than one.

Coating thickness: in this incoherent ray optics the thickness enters only
through Beer-Lambert absorption, so for the paper's lossless varnish the result does not
depend on it and the paper's lambda/4 maximum (its Fig. 13) cannot appear. The option
``coherent=True`` models coating + substrate as one rough interface whose facets carry a
conformal film of the coating's thickness, reflecting with the coherent Airy amplitudes of
:func:`labbrdf.films.onefilm.film_amplitudes` at the local angle. Its limits: film and substrate
share every facet (the coating's roughness is used for both, the top and bottom
interfaces are perfectly correlated), there is no scattering inside the film, no
refraction-shifted exit direction and no multiple scattering between differently oriented
facets inside the film; it is the SCATMECH ``Facet_BRDF_Model`` with ``stack=`` picture, not
a thick varnish.
"""

from __future__ import annotations

import builtins
import time
from collections.abc import Callable, Iterable
from typing import Any

import numpy as np

from .binning import Grid
from .config import Coating, Substrate, TraceConfig
from .medium import Medium
from .result import TraceResult, trace_summary
from .setup import WalkSetup
from .walk import BlockTally, GroupTally, _unit, run_unit, trace_block, trace_group

__all__ = [
    "BlockTally",
    "Coating",
    "GroupTally",
    "Grid",
    "Medium",
    "Substrate",
    "TraceConfig",
    "TraceResult",
    "run_unit",
    "trace",
    "trace_block",
    "trace_group",
    "trace_summary",
    "work_units",
]


def work_units(config: TraceConfig, blocks_per_unit: int = 1) -> list[tuple[TraceConfig, tuple]]:
    """Split the run into work units ``(config, fold-group indices)`` in group order.

    A unit holds ``ceil(blocks_per_unit / config.fold_blocks)`` whole fold groups, so the
    unit size never changes how the tallies are added up.
    """
    if not isinstance(blocks_per_unit, int) or blocks_per_unit < 1:
        raise ValueError(f"blocks_per_unit must be a positive integer, got {blocks_per_unit!r}")
    per = -(-blocks_per_unit // config.fold_blocks)
    ng = config.n_groups
    return [(config, tuple(range(i, min(i + per, ng)))) for i in range(0, ng, per)]


def trace(
    config: TraceConfig,
    *,
    map: Callable[..., Iterable[Any]] = builtins.map,  # noqa: A002
    blocks_per_unit: int = 1,
) -> TraceResult:
    """Run the Monte Carlo polarization tracer.

    Parameters
    ----------
    config : TraceConfig
        The run (wavelength, incidence, layers, rays, seed, ...).
    map : callable
        ``map(func, items)`` returning results *in item order* (builtins.map, or an ordered
        parallel map such as ``labbrdf.parallel.imap`` with its options bound); each item
        is a work unit ``(config, blocks)``.
    blocks_per_unit : int
        Blocks per work unit, rounded up to whole fold groups (``config.fold_blocks``);
        does not change the result.

    Returns
    -------
    TraceResult

    Raises
    ------
    TypeError
        If ``config`` is not a TraceConfig.
    RuntimeError
        If ``map`` returns the blocks out of order or incompletely.
    """
    if not isinstance(config, TraceConfig):
        raise TypeError(f"config must be a TraceConfig, got {type(config).__name__}")
    t0 = time.perf_counter()
    grid = Grid(config.theta_step_deg, config.phi_step_deg)
    nb = grid.n_bins
    sums = np.zeros((nb, 16))
    sumsq = np.zeros((nb, 16))
    counts = np.zeros(nb, dtype=np.int64)
    hemi = np.zeros(16)
    exited = absorbed = terminated = 0.0
    events = 0
    block_hemi = np.zeros((config.n_blocks, 4, 4))
    block_rays = np.zeros(config.n_blocks, dtype=np.int64)
    evaluated = config.resolved_estimator == "evaluated"
    # evaluated: per batch, the cells for the exit operator, then the sampled exits' bins
    # (multiple scattering: then the later vertices' levels, WalkSetup.channels)
    cells = np.zeros((WalkSetup(config).channels * config.batches * nb, 16)) if evaluated else None
    batch_rays = np.zeros(config.batches, dtype=np.int64)
    expected = 0
    for tallies in map(_unit, work_units(config, blocks_per_unit)):
        for t in tallies:
            if t.group != expected:
                raise RuntimeError(f"map returned fold group {t.group}, expected {expected}")
            # sparse: the bins outside t.bins receive + 0.0, which changes no bit
            sums[t.bins] = sums[t.bins] + t.sums
            sumsq[t.bins] = sumsq[t.bins] + t.sumsq
            counts[t.bins] = counts[t.bins] + t.counts
            hemi = hemi + t.hemi
            exited = exited + t.exited
            absorbed = absorbed + t.absorbed
            terminated = terminated + t.terminated
            events += t.events
            if cells is not None:
                cells[t.cell_keys] = cells[t.cell_keys] + t.cell_sums
                batch_rays = batch_rays + t.batch_rays
            for b, h, r in zip(t.blocks, t.block_hemi, t.block_rays, strict=True):
                block_hemi[b] = h.reshape(4, 4) / r
                block_rays[b] = r
            expected += 1
    if expected != config.n_groups:
        raise RuntimeError(f"map returned {expected} of {config.n_groups} fold groups")
    n = config.rays
    shape = (grid.n_theta, grid.n_phi)
    batch_mueller = stderr = None
    info: dict[str, float] = {}
    if cells is not None:
        first, exit_sums, info = _evaluated(config, grid, cells)
        # f = first + sum_b exit_b / N, f_b = first + exit_b / N_b (plain sums, no BLAS:
        # a bare substrate's batches are then bit-identical and its error exactly 0)
        f = first + exit_sums.sum(axis=0) / n
        per = np.where(batch_rays > 0, 1.0 / np.maximum(batch_rays, 1), 0.0)
        batch_mueller = first + exit_sums * per[:, None, None, None, None]
        omega = grid.cos_solid_angle_sr[:, :, None, None]
        sums = (f * (n * omega)).reshape(nb, 16)
        sumsq = np.zeros_like(sums)
        dev = batch_mueller - f
        bw = batch_rays[:, None, None, None, None].astype(float)
        nbat = config.batches
        stderr = np.sqrt((bw * dev * dev).sum(axis=0) / n / (nbat - 1))
        bh = (batch_mueller * omega).sum(axis=(1, 2))  # (B, 4, 4) per ray
        block_hemi, block_rays = bh, batch_rays
        hemi = (f * omega).sum(axis=(0, 1)).reshape(16) * n
        batch_mueller = batch_mueller.astype(np.float32)
    return TraceResult(
        config=config,
        sums=sums.reshape(*shape, 4, 4),
        sumsq=sumsq.reshape(*shape, 4, 4),
        counts=counts.reshape(shape),
        hemi=hemi.reshape(4, 4) / n,
        ledger={
            "incident": float(n),
            "exited": exited / n,
            "absorbed": absorbed / n,
            "terminated": terminated / n,
        },
        block_hemi=block_hemi,
        block_rays=block_rays,
        seconds=time.perf_counter() - t0,
        events=events,
        stderr=stderr,
        batch_mueller=batch_mueller,
        info=info,
    )


def _evaluated(
    config: TraceConfig, grid: Grid, cells: np.ndarray
) -> tuple[np.ndarray, np.ndarray, dict[str, float]]:
    """First-surface map (n_theta, n_phi, 4, 4) and per-batch exit sums (B, ...) [sr^-1]."""
    from .estimator import exit_map, first_surface_map, masking_of

    t0 = time.perf_counter()
    first = first_surface_map(config, masking=masking_of(config))
    info = {"first_surface_seconds": time.perf_counter() - t0}
    shape = (config.batches, grid.n_theta, grid.n_phi, 4, 4)
    if config.coating is not None and not config.coherent:
        sums, more = exit_map(config, cells.reshape((-1, *shape)))
        info.update(more)
    else:
        sums = np.zeros(shape)
    return first, sums, info
