"""Partial sums of a polynomial levelling: what a jackknife replicate's levelling needs.

The least-squares polynomial of :func:`labbrdf.roughness.levelling.level` is fixed by a
few sums over the valid points (their count, the sum of heights, and the monomials' normal
equations).
Sums over disjoint regions add, so the sums of a map less one tile are the whole map's less
the tile's: each leave-one-tile-out replicate is levelled without a pass over the map to
form them (:func:`labbrdf.roughness.topography.roughness_statistics`' jackknife).

Physics layer: numpy only.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = ["NormalSums", "region_design"]


@dataclass(frozen=True)
class NormalSums:
    """The sums a polynomial levelling needs over a set of points, which add and subtract.

    ``n`` points, ``sz = sum z``, ``ata = sum a a^T``, ``sa = sum a``, ``saz = sum a z`` with
    ``a`` the monomials of the levelling (:func:`region_design`, coordinates scaled to
    [-1, 1) over the whole grid). A jackknife replicate's are the whole map's less its
    tile's (partial sums), so the replicate is levelled without a pass to form them.
    """

    n: float
    sz: float
    ata: NDArray
    sa: NDArray
    saz: NDArray

    @classmethod
    def of(
        cls, z: NDArray, valid: NDArray, exps: list[tuple[int, ...]], regions: Any
    ) -> NormalSums:
        """The sums over the valid points of ``regions`` (disjoint tuples of slices)."""
        k = len(exps)
        n, sz, ata, sa, saz = 0.0, 0.0, np.zeros((k, k)), np.zeros(k), np.zeros(k)
        for reg in regions:
            reg = tuple(reg) + (slice(None),) * (z.ndim - len(tuple(reg)))
            v = valid[reg]
            a = region_design(z.shape, reg, exps, v)
            zz = z[reg][v]
            n += zz.size
            sz += float(np.sum(zz))
            ata += a.T @ a
            sa += a.sum(axis=0)
            saz += a.T @ zz
        return cls(n, sz, ata, sa, saz)

    def __sub__(self, o: NormalSums) -> NormalSums:
        return NormalSums(
            self.n - o.n, self.sz - o.sz, self.ata - o.ata, self.sa - o.sa, self.saz - o.saz
        )

    def levelled(self, z: NDArray, valid: NDArray, exps: list[tuple[int, ...]]) -> NDArray:
        """``_level(z, valid, degree)`` from these sums (those of ``valid``'s points)."""
        if self.n <= len(exps):
            raise ValueError(f"{int(self.n)} valid points cannot fix the levelling polynomial")
        zmean = self.sz / self.n
        coef = np.linalg.lstsq(self.ata, self.saz - zmean * self.sa, rcond=None)[0]
        axes = [2.0 * np.arange(m) / m - 1.0 for m in z.shape]
        poly = np.zeros(z.shape)
        for c, e in zip(coef, exps, strict=True):
            term = axes[0] ** e[0]
            for ax, p in zip(axes[1:], e[1:], strict=True):
                term = np.multiply.outer(term, ax**p)
            poly += c * term
        out = np.full(z.shape, np.nan)
        np.subtract(z - zmean, poly, out=out, where=valid)
        return out


def region_design(
    shape: tuple[int, ...], reg: tuple[slice, ...], exps: list[tuple[int, ...]], v: NDArray
) -> NDArray:
    """The levelling's monomials at the valid points ``v`` of the region ``reg`` of the grid.

    Coordinates scaled to [-1, 1) over the whole grid per axis, as the levelling of
    :func:`labbrdf.roughness.levelling.level` scales them; ``exps`` the monomials' exponents.
    """
    coords = [2.0 * np.arange(*sl.indices(m)) / m - 1.0 for sl, m in zip(reg, shape, strict=True)]
    grids = np.meshgrid(*coords, indexing="ij") if len(coords) > 1 else coords
    pts = [g[v] for g in grids]
    cols = []
    for e in exps:
        col = pts[0] ** e[0]
        for p, q in zip(pts[1:], e[1:], strict=True):
            col = col * p**q
        cols.append(col)
    return np.column_stack(cols)
