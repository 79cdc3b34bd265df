"""What the evaluated walk records at the top interface from below: cells or exits.

Rays reaching the top interface from below are recorded either in internal direction
cells, for the exit operator (:func:`deposit_cells`, :mod:`.operator`), or, through a
nearly smooth top, as exits in output bins (:func:`deposit_exit`); :func:`record_up`
chooses by :func:`exit_is_sampled`, and with the operator can also send the rays of the
first :data:`POLE_ROWS` polar rows of cells to the exit bins (off by default).

The exit operator (:mod:`.operator`) evaluates the closed-form BTDF from each internal
cell's centroid at about one node per degree of each output bin. Through a GGX interface of
roughness ``alpha`` from a coating of index ``n_1`` into ``n_2`` the exit lobe of one
internal direction is about ``|n_1 - n_2| alpha`` rad wide (0.6 deg for ``alpha = 0.02``
and ``n_1 = 1.5``): where it is narrower than a node spacing the node rule samples the
peak by chance (a cell's hemispherical transmittance came out up to 15 % off, creating or
losing energy), and where it is narrower than a cell all rays of the cell land where the
centroid's would (the cell's image in the air is ``n_1`` times wider than the cell).

For such lobes the evaluated walk exits through the facet it has already sampled at the
top interface from below (a visible normal, Heitz 2018): the transmitted branch, which
the walk does not follow, is carried through the facet with its Fresnel transmission
Mueller matrix (beam factor included) and Smith ``G1`` of its direction, rotated to the
meridional frame of that direction and summed into its bin, per batch. This is the
counting walk's exit without its random reflect/refract choice (both branches are kept,
with their weights), so it is unbiased at every roughness and needs no operator; its extra
noise is that of where a ray lands inside a lobe narrower than a bin: little.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..microfacet.interface import Facets
from .binning import Grid
from .interfaces import apply_fresnel, rotate_frame

__all__ = [
    "MIN_LOBE_NODES",
    "deposit_cells",
    "deposit_branch",
    "deposit_exit",
    "exit_is_sampled",
    "lobe_width_rad",
    "record_up",
]

#: the operator is used where the exit lobe spans at least this many of its output nodes
#: (one per degree of bin width); below it the exit is sampled. Measured on the
#: 3 x 6 degree grid (n = 1.5): a cell's hemispherical transmittance through the operator
#: is off by 3.9 / 1.7 / 0.7 / 0.15 / 0.10 % at lobe / node = 0.86 / 1.15 / 1.43 / 2.0 /
#: 2.9 (alpha 0.03 / 0.04 / 0.05 / 0.07 / 0.1)
MIN_LOBE_NODES = 2.0

#: with the operator, rays in this many polar rows of cells around the pole may exit
#: through their own facet. Off (0): the operator averages those cells instead
#: (:func:`.operator.cell_rule`); on the paper's case (1-degree grid, 60 deg) 4 rows made
#: the tiny polar bins so noisy that the lobe's RMS relative error rose from 0.93 % to
#: 11.7 % (docs/tracer.md)
POLE_ROWS = 0


F64 = NDArray[np.float64]


def lobe_width_rad(n_below: float, n_above: float, alpha: float) -> float:
    """Angular scale of the exit lobe of one internal direction [rad]: ``|n1 - n2| alpha``."""
    return abs(n_below - n_above) * alpha


def exit_is_sampled(grid: Grid, n_below: float, alpha: float, n_above: float = 1.0) -> bool:
    """True where the exit lobe is too narrow for the operator (module docstring).

    The operator evaluates ``ceil(step)`` nodes per bin axis (about one per degree,
    :func:`.estimator.exit_map`); the lobe must span :data:`MIN_LOBE_NODES` of them.
    """
    steps = (grid.theta_step_deg, grid.phi_step_deg)
    node = max(s / np.ceil(s - 1e-9) for s in steps)
    return bool(lobe_width_rad(n_below, n_above, alpha) < MIN_LOBE_NODES * np.radians(node))


def deposit_exit(
    grid: Grid,
    batches: int,
    k: F64,
    s_loc: F64,
    m: F64,
    M: F64,
    transmission: tuple[tuple, F64, F64],
    face: Facets,
    scalar: bool,
    sel: NDArray[np.bool_],
    rid: NDArray[np.int64],
    keys: list[NDArray],
    rows: list[NDArray],
) -> None:
    """Sum the transmitted branch of the selected top-from-below events into exit bins.

    Parameters
    ----------
    k, s_loc, m : ndarray, shape (3, n)
        Ray directions (up-going, below the interface), their Stokes frames' x axis (the
        facet's s axis, to which ``M`` is already rotated) and the sampled facet normals.
    M : ndarray, shape (4, 4, n)
        The rays' Mueller matrices in the frame ``s_loc``, before the facet's Fresnel
        matrix (not changed).
    transmission : ((A, B, C, S), cos_t, eta)
        The facet's Fresnel transmission numbers (beam factor included; zero under total
        internal reflection), the cosine of refraction and ``n_below / n_above``.
    face : Facets
        The interface's distribution (Smith ``G1`` of the exit direction, seen from
        above).
    scalar : bool
        Keep the intensity row only (scalar mode).
    sel : ndarray of bool, shape (n,)
        The events to deposit.
    rid : ndarray of int, shape (n,)
        Global ray indices (batch = index modulo ``batches``).
    keys, rows : list
        Receive the flat keys ``(batches + batch) * n_bins + bin`` (after the operator's
        cells) and the Mueller rows (16, n_sel) in the exit frames ``phi_hat(phi_o)``.
    """
    tr, cos_t, eta = transmission
    idx = np.flatnonzero(sel)
    ks, ms = k[:, idx], m[:, idx]
    cos_i = np.clip(-(ks * ms).sum(axis=0), 0.0, 1.0)
    e = eta[idx] if np.ndim(eta) else eta
    ct = cos_t[idx]
    kt = e * ks + (e * cos_i - ct) * ms
    kt = kt / np.sqrt((kt * kt).sum(axis=0))
    ok = (kt[2] > 0) & (tr[0][idx] > 0)
    if not ok.any():
        return
    idx, kt = idx[ok], kt[:, ok]
    Mt = M[:, :, idx].copy()
    apply_fresnel(Mt, *(t[idx] for t in tr))
    if scalar:
        Mt[1:] = 0.0
    Mt *= face.smith_g1(kt)
    bin_, phi = grid.index(kt)
    s_out = np.stack([-np.sin(phi), np.cos(phi), np.zeros_like(phi)])
    rotate_frame(Mt, kt, s_loc[:, idx], s_out)
    # after the operator's cells (record_up): keys from batches * n_bins on
    keys.append((batches + rid[idx] % batches) * grid.n_bins + bin_)
    rows.append(Mt.reshape(16, -1))


def deposit_branch(
    grid: Grid,
    batches: int,
    k_out: F64,
    s_loc: F64,
    M: F64,
    abcs: tuple[F64, F64, F64, F64],
    weight: F64,
    rid: NDArray[np.int64],
    into: tuple[list[NDArray], list[NDArray]],
    scalar: bool,
) -> None:
    """Sum one branch of facet events, leaving into the air, into exit bins per batch.

    The branch's Mueller weight is ``weight F M``: ``F`` the facet's Fresnel matrix
    (``abcs``), ``weight`` its probability of leaving the microsurface at once (the
    evaluated multiple-scattering walk, :mod:`.walk`). Keyed as :func:`deposit_exit`'s,
    after the operator's cells.

    Parameters
    ----------
    k_out : ndarray, shape (3, n)
        The branch's directions, up into the air.
    s_loc : ndarray, shape (3, n)
        The facets' s axes, the frame of ``M``.
    M : ndarray, shape (4, 4, n)
        The rays' Mueller matrices before the facet (not changed).
    abcs : (A, B, C, S)
        The branch's Fresnel numbers, one per ray.
    weight : ndarray, shape (n,)
        Leave probability [1].
    rid : ndarray of int, shape (n,)
        Global ray indices (batch = index modulo ``batches``).
    into : (keys, rows)
        Lists that receive the flat keys and the Mueller rows (16, n).
    """
    keep = weight > 0
    if not keep.any():
        return
    Mt = M[:, :, keep].copy()
    apply_fresnel(Mt, *(a[keep] for a in abcs))
    if scalar:
        Mt[1:] = 0.0
    Mt *= weight[keep]
    k = k_out[:, keep]
    bin_, phi = grid.index(k)
    s_out = np.stack([-np.sin(phi), np.cos(phi), np.zeros_like(phi)])
    rotate_frame(Mt, k, s_loc[:, keep], s_out)
    into[0].append((batches + rid[keep] % batches) * grid.n_bins + bin_)
    into[1].append(Mt.reshape(16, -1))


def deposit_cells(
    grid: Grid,
    batches: int,
    k: F64,
    s: F64,
    M: F64,
    sel: NDArray[np.bool_],
    rid: NDArray[np.int64],
    keys: list[NDArray],
    rows: list[NDArray],
    raw: list[tuple[NDArray, NDArray, NDArray]] | None = None,
) -> None:
    """Record the selected up-going rays just below the top interface, for the operator.

    Each ray's Mueller matrix is expressed in the meridional frame ``phi_hat(phi_u)`` of
    its direction (the frame call of the exit binning) and keyed by its batch
    (global ray index modulo ``batches``) and its direction cell.
    """
    ks = k[:, sel]
    Mc = M[:, :, sel].copy()
    idx, phi = grid.index(ks)
    s_det = np.stack([-np.sin(phi), np.cos(phi), np.zeros_like(phi)])
    rotate_frame(Mc, ks, s[:, sel], s_det)
    keys.append((rid[sel] % batches) * grid.n_bins + idx)
    rows.append(Mc.reshape(16, -1))
    if raw is not None:
        raw.append((rid[sel], ks, Mc.reshape(16, -1)))


def record_up(
    grid: Grid,
    batches: int,
    rid: NDArray[np.int64],
    rays: tuple[F64, F64, F64],
    M: F64,
    transmission: tuple[tuple, F64, F64],
    sel: NDArray[np.bool_],
    how: tuple[bool, Facets, bool],
    into: tuple[list[NDArray], list[NDArray], list | None],
) -> None:
    """Record the top-from-below events ``sel``: exits (sampled) or cells (operator).

    ``rays`` = (directions, frames' x axes, facet normals); ``how`` = (sampled exit,
    the top's distribution, scalar mode); ``into`` = (keys, rows, raw list or None).
    """
    k, s_loc, m = rays
    sampled, face, scalar = how
    keys, rows, raw = into
    if not sampled:
        # near the pole the operator's centroid rule moves a lobe centred on the pole off
        # it: the rays of the first POLE_ROWS rows of cells may exit through their facet
        cut = np.cos(np.radians(grid.theta_edges_deg[min(POLE_ROWS, grid.n_theta)]))
        near = sel & (k[2] > cut)
        deposit_cells(grid, batches, k, s_loc, M, sel & ~near, rid, keys, rows, raw)
        sel = near
        if not sel.any():
            return
    deposit_exit(grid, batches, k, s_loc, m, M, transmission, face, scalar, sel, rid, keys, rows)
