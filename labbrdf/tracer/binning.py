"""The hemisphere grid of exit directions and the binning of exiting rays.

Bins are centred on multiples of the steps, as the oracle tables and the paper's
91 x 360 grid are: polar bin i covers ``[(i - 1/2) h, (i + 1/2) h)`` clipped to [0, 90] deg
(so the first and last rows are half-width), azimuth bin j covers
``[(j - 1/2) g, (j + 1/2) g)`` modulo 360 deg. With h = g = 1 deg this is 91 x 360 bins
with centres 0..90 and 0..359 deg; the specular direction (theta_i, 180) is a bin centre.

Normalisation (derivation): the BRDF is ``f = dL_r / dE_i``; for a collimated beam the
power fraction scattered into a solid angle ``dOmega`` is ``f cos(theta_r) dOmega``. With
``N`` rays of unit power, the bin's summed exit weights ``W`` estimate
``N * integral_bin f cos(theta_r) dOmega``, hence the bin-average BRDF

    f_bin = W / (N * Omega_cos),   Omega_cos = integral_bin cos(theta) dOmega
          = dphi (sin^2 theta_hi - sin^2 theta_lo) / 2          [sr].

This is the cos-weighted average of f over the bin (pitfall 13 of the oracles README:
compare bin averages, not point values, where f curves strongly).

Each exiting ray's Stokes frame is rotated to ``s = phi_hat(phi) = (-sin phi, cos phi, 0)``
of the ray's own azimuth (LB convention), so a bin holds the average of the point Mueller
matrices in their own frames; near the pole the azimuth sectors keep the frames apart
(pitfall 6). An exit exactly along the normal (only a smooth surface at normal incidence)
has no azimuth; it is given phi = 180 deg, the specular half-plane, and that frame.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

__all__ = ["Grid", "bin_exits"]


@dataclass(frozen=True)
class Grid:
    """Regular (theta, phi) grid of exit directions.

    Parameters
    ----------
    theta_step_deg, phi_step_deg : float
        Bin widths [deg]; must divide 90 and 360.
    """

    theta_step_deg: float = 1.0
    phi_step_deg: float = 1.0

    @property
    def n_theta(self) -> int:
        """Number of polar bins (91 for 1-degree steps)."""
        return int(round(90.0 / self.theta_step_deg)) + 1

    @property
    def n_phi(self) -> int:
        """Number of azimuth bins (360 for 1-degree steps)."""
        return int(round(360.0 / self.phi_step_deg))

    @property
    def n_bins(self) -> int:
        """Total number of bins."""
        return self.n_theta * self.n_phi

    @property
    def theta_centres_deg(self) -> NDArray[np.float64]:
        """Nominal polar centres [deg]: 0, h, ..., 90."""
        return np.arange(self.n_theta, dtype=np.float64) * self.theta_step_deg

    @property
    def phi_centres_deg(self) -> NDArray[np.float64]:
        """Azimuth centres [deg]: 0, g, ..., 360 - g."""
        return np.arange(self.n_phi, dtype=np.float64) * self.phi_step_deg

    @property
    def theta_edges_deg(self) -> NDArray[np.float64]:
        """Polar edges [deg], length n_theta + 1: 0, h/2, 3h/2, ..., 90 - h/2, 90."""
        h = self.theta_step_deg
        inner = (np.arange(1, self.n_theta) - 0.5) * h
        return np.concatenate([[0.0], inner, [90.0]])

    @property
    def phi_edges_deg(self) -> NDArray[np.float64]:
        """Azimuth edges [deg], length n_phi + 1: -g/2, g/2, ..., 360 - g/2."""
        return (np.arange(self.n_phi + 1, dtype=np.float64) - 0.5) * self.phi_step_deg

    @property
    def solid_angle_sr(self) -> NDArray[np.float64]:
        """Solid angle of each bin, shape (n_theta, n_phi) [sr]."""
        t = np.radians(self.theta_edges_deg)
        band = np.cos(t[:-1]) - np.cos(t[1:])
        return np.repeat((band * np.radians(self.phi_step_deg))[:, None], self.n_phi, axis=1)

    @property
    def cos_solid_angle_sr(self) -> NDArray[np.float64]:
        """Cos-weighted solid angle of each bin, shape (n_theta, n_phi) [sr]."""
        t = np.radians(self.theta_edges_deg)
        band = 0.5 * (np.sin(t[1:]) ** 2 - np.sin(t[:-1]) ** 2)
        return np.repeat((band * np.radians(self.phi_step_deg))[:, None], self.n_phi, axis=1)

    def index(self, k: NDArray[np.float64]) -> tuple[NDArray[np.intp], NDArray[np.float64]]:
        """Flat bin index and azimuth [rad] of upward unit directions ``k`` (3, n)."""
        kz = np.clip(k[2], -1.0, 1.0)
        theta = np.degrees(np.arccos(kz))
        # exactly polar exits (smooth surface at normal incidence) have no azimuth:
        # give them the specular half-plane, phi = 180 deg (pitfall 7: never atan2(0, 0))
        pole = (k[0] == 0) & (k[1] == 0)
        phi = np.where(pole, np.pi, np.arctan2(k[1], k[0]))
        phi_deg = np.degrees(phi) % 360.0
        i = np.minimum(np.floor(theta / self.theta_step_deg + 0.5), self.n_theta - 1)
        j = np.floor(phi_deg / self.phi_step_deg + 0.5) % self.n_phi
        return (i * self.n_phi + j).astype(np.intp), phi


def bin_exits(
    grid: Grid, idx: NDArray[np.intp], rows: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.int64]]:
    """Sum Mueller elements, their squares and counts per bin with ``np.bincount``.

    Parameters
    ----------
    grid : Grid
    idx : ndarray of int, shape (n,)
        Flat bin indices.
    rows : ndarray, shape (16, n)
        Row-major Mueller elements of each exiting ray in its exit frame.

    Returns
    -------
    sums, sumsq : ndarray, shape (n_bins, 16)
    counts : ndarray of int, shape (n_bins,)
    """
    nb = grid.n_bins
    sums = np.empty((nb, 16))
    sumsq = np.empty((nb, 16))
    for e in range(16):
        sums[:, e] = np.bincount(idx, weights=rows[e], minlength=nb)
        sumsq[:, e] = np.bincount(idx, weights=rows[e] * rows[e], minlength=nb)
    counts = np.bincount(idx, minlength=nb).astype(np.int64)
    return sums, sumsq, counts
