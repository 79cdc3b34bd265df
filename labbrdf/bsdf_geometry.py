"""Scatter angles about the specular direction: the geometry of ``.bsdf`` grids.

Physics layer: numpy only. The Zemax / Radiant "BSDF Data Interchange" format (Radiant
Imaging, "BSDF Data Interchange File Format Specification", 2008) gives scatter directions
by a radial angle and an azimuth about the specular direction (the direction of direct
transmission for BTDF): radial 0 is the specular direction, azimuth 0 points from the
specular direction towards the sample normal, azimuths increase counter-clockwise. The
specification does not say from which side "counter-clockwise" is seen; labbrdf takes it as
seen by an observer looking back at the sample along the specular direction, so azimuth 90
is the +y side when the source is at phi_i = 0. The conversions here are exact (unit
vectors, no small-angle approximation); ``docs/bsdf.md`` has the derivation. The reader
(:mod:`labbrdf.adapters.zemax_bsdf`), the writer (:mod:`labbrdf.writers.zemax`) and the grid
quadrature (:func:`grid_integral`, the total integrated scatter of a grid) share them, and
the cells each grid node owns (:func:`radial_weights`, :func:`azimuth_weights`): the
quadrature's weights, and the reader's average over the polar cap.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "SYMMETRIES",
    "angles_to_scatter",
    "azimuth_weights",
    "grid_integral",
    "radial_weights",
    "scatter_to_angles",
    "scatter_to_direction",
]

#: Symmetry keywords of a scatter grid (those of the ``.bsdf`` format): PlaneSymmetrical
#: grids hold azimuths 0..180 of a mirror-symmetric hemisphere, the others the full circle.
SYMMETRIES = ("PlaneSymmetrical", "Asymmetrical", "Asymmetrical4D")


def _cosd(a: NDArray[np.float64]) -> NDArray[np.float64]:
    """cos of degrees, exact (0, +-1) at multiples of 90 deg."""
    a = np.asarray(a, dtype=float)
    r = np.mod(a, 360.0)
    out = np.cos(np.radians(a))
    out = np.where(r == 90.0, 0.0, out)
    out = np.where(r == 270.0, 0.0, out)
    out = np.where(r == 0.0, 1.0, out)
    return np.where(r == 180.0, -1.0, out)


def _sind(a: NDArray[np.float64]) -> NDArray[np.float64]:
    """sin of degrees, exact (0, +-1) at multiples of 90 deg."""
    return _cosd(np.asarray(a, dtype=float) - 90.0)


def _frame(theta_s_deg: ArrayLike) -> tuple[NDArray[np.float64], ...]:
    """Specular unit vector ``s`` and the azimuth-0 and azimuth-90 unit vectors ``e0``, ``e90``.

    Source at phi_i = 0, so the specular direction is ``s = (-sin ts, 0, cos ts)``;
    ``e0 = (cos ts, 0, sin ts)`` is the tangent at ``s`` pointing towards the normal (spec:
    "azimuth 0 points from the specular direction towards the sample normal") and
    ``e90 = s x e0 = (0, 1, 0)`` (counter-clockwise seen from the specular direction).
    """
    ts = np.asarray(theta_s_deg, dtype=float)
    c, s = _cosd(ts), _sind(ts)
    zero = np.zeros_like(c)
    return (
        np.stack([-s, zero, c]),
        np.stack([c, zero, s]),
        np.stack([zero, zero + 1.0, zero]),
    )


def scatter_to_direction(
    theta_s_deg: ArrayLike, radial_deg: ArrayLike, azimuth_deg: ArrayLike
) -> NDArray[np.float64]:
    """Unit vector of a scatter direction given about the specular direction.

    Parameters
    ----------
    theta_s_deg : array_like
        Polar angle of the specular direction [deg] (the file's "AngleOfIncidence").
    radial_deg, azimuth_deg : array_like
        Scatter radial and azimuth angles [deg]; broadcast with ``theta_s_deg``.

    Returns
    -------
    ndarray
        ``(3, ...)`` Cartesian components (x, y, z), z along the sample normal.

    Notes
    -----
    ``d = cos(r) s + sin(r) (cos(a) e0 + sin(a) e90)``: the specular vector ``s`` rotated by
    the radial angle ``r`` about the axis ``s x (cos a e0 + sin a e90)`` (Rodrigues' formula
    with an axis perpendicular to ``s``), exact for any ``r``.
    """
    # trigonometry on the inputs as given (1-D grids broadcast later), components written out
    ts, r, a = (np.asarray(x, float) for x in (theta_s_deg, radial_deg, azimuth_deg))
    ct, st = _cosd(ts), _sind(ts)
    cr, sr = _cosd(r), _sind(r)
    ca, sa = _cosd(a), _sind(a)
    u = sr * ca  # component along e0 = (cos ts, 0, sin ts)
    x = u * ct - cr * st
    y = sr * sa
    z = cr * ct + u * st
    return np.stack(np.broadcast_arrays(x, y, z))


def _direction_angles(d: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(theta [deg] from +z, phi [deg] in [0, 360)) of unit vectors ``d`` (3, ...)."""
    x, y, z = d
    # rounded to 1e-12 deg (2e-14 rad, below the last bit of a file's angle) so that exact
    # cases come out exact: the specular direction of 20 deg is 20.0, not 20.000000000000007
    theta = np.round(np.degrees(np.arctan2(np.hypot(x, y), z)), 12)
    phi = np.mod(np.round(np.degrees(np.arctan2(y, x)), 12), 360.0)
    phi = np.where(phi >= 360.0, 0.0, phi)
    return theta, phi


def scatter_to_angles(
    theta_s_deg: ArrayLike, radial_deg: ArrayLike, azimuth_deg: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.bool_]]:
    """Dataset angles of scatter directions: ``(theta_r_deg, phi_r_deg, above)``.

    Parameters
    ----------
    theta_s_deg, radial_deg, azimuth_deg : array_like
        As in :func:`scatter_to_direction` [deg].

    Returns
    -------
    theta_r_deg : ndarray
        Polar angle from the normal [deg] (from the back normal for BTDF, whose frame is
        the reflection frame mirrored in the sample plane).
    phi_r_deg : ndarray
        Azimuth of the outward direction [deg] in [0, 360), source at 0, the specular
        direction at 180.
    above : ndarray of bool
        True where the direction is above the horizon (z > 0); elsewhere the point is not
        a scatter direction of this hemisphere.
    """
    d = scatter_to_direction(theta_s_deg, radial_deg, azimuth_deg)
    theta, phi = _direction_angles(d)
    return theta, phi, d[2] > 0


def angles_to_scatter(
    theta_s_deg: ArrayLike, theta_r_deg: ArrayLike, phi_r_deg: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Inverse of :func:`scatter_to_angles`: ``(radial_deg, azimuth_deg in [0, 360))``.

    ``r = atan2(|d x s|, d . s)`` and ``a = atan2(d . e90, d . e0)`` with the frame of
    :func:`scatter_to_direction`; ``a`` is 0 at ``r = 0`` (undefined there).
    """
    ts, tr, pr = np.broadcast_arrays(
        np.asarray(theta_s_deg, float),
        np.asarray(theta_r_deg, float),
        np.asarray(phi_r_deg, float),
    )
    st = _sind(tr)
    d = np.stack([st * _cosd(pr), st * _sind(pr), _cosd(tr)])
    s, e0, e90 = _frame(ts)
    cos_r = np.sum(d * s, axis=0)
    u, v = np.sum(d * e0, axis=0), np.sum(d * e90, axis=0)
    radial = np.degrees(np.arctan2(np.hypot(u, v), cos_r))
    az = np.mod(np.degrees(np.arctan2(v, u)), 360.0)
    return radial, np.where(az >= 360.0, 0.0, az)


# ------------------------------------------------------------------------------ grid cells


def _edges(a: NDArray[np.float64], lo: float, hi: float) -> NDArray[np.float64]:
    """Cell edges around nodes ``a``: midpoints inside, ``lo``/``hi`` clipped at the ends."""
    mid = 0.5 * (a[1:] + a[:-1])
    return np.concatenate([[max(lo, a[0])], mid, [min(hi, a[-1])]])


def radial_weights(radial_deg: ArrayLike) -> NDArray[np.float64]:
    """Solid-angle weights of the radial cells of a scatter grid [sr/rad].

    Each node owns the cell bounded by the midpoints to its neighbours (the end nodes half
    cells, clipped to [0, 180] deg); its weight is ``int sin r dr = cos r_lo - cos r_hi``,
    so a cell's solid angle about the specular direction is this times its azimuth width.

    Parameters
    ----------
    radial_deg : array_like
        Strictly increasing radial angles [deg].

    Returns
    -------
    ndarray
        One weight per radial angle [sr/rad].
    """
    e = np.radians(_edges(np.asarray(radial_deg, float), 0.0, 180.0))
    return np.cos(e[:-1]) - np.cos(e[1:])


def azimuth_weights(azimuth_deg: ArrayLike, symmetry: str) -> NDArray[np.float64]:
    """Azimuth cell widths of a scatter grid [rad].

    Each node owns the cell bounded by the midpoints to its neighbours; a full circle wraps
    (a last node at the first + 360 deg repeats it), a PlaneSymmetrical half (azimuths
    0..180, end nodes owning half cells) counts twice.

    Parameters
    ----------
    azimuth_deg : array_like
        Strictly increasing azimuths [deg].
    symmetry : {"PlaneSymmetrical", "Asymmetrical", "Asymmetrical4D"}
        Grid symmetry (:data:`SYMMETRIES`).

    Returns
    -------
    ndarray
        One width per azimuth [rad]; they sum to 2 pi.
    """
    a = np.asarray(azimuth_deg, float)
    if symmetry == "PlaneSymmetrical":
        return 2.0 * np.radians(np.diff(_edges(a, 0.0, 180.0)))
    if a.size == 1:
        return np.array([2.0 * np.pi])
    if a[-1] - a[0] >= 360.0 - 1e-9:  # the first node is repeated at +360
        return np.radians(np.diff(_edges(a, -np.inf, np.inf)))
    ext = np.concatenate([[a[-1] - 360.0], a, [a[0] + 360.0]])
    mid = 0.5 * (ext[1:] + ext[:-1])
    return np.radians(np.diff(mid))


# ----------------------------------------------------------------------------- scatter grid
def _cos_weights(
    theta_i_deg: NDArray[np.float64],
    azimuth_deg: NDArray[np.float64],
    radial_deg: NDArray[np.float64],
    symmetry: str,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Solid-angle weights and projected cosines of the grid points.

    Returns ``(w, cos_r)``: weights [sr] and cosines (0 below the horizon), each shaped
    ``(aoi, azimuth, radial)``.
    """
    w = azimuth_weights(azimuth_deg, symmetry)[:, None] * radial_weights(radial_deg)
    ti = theta_i_deg[:, None, None]
    d = scatter_to_direction(ti, radial_deg[None, None, :], azimuth_deg[None, :, None])
    return np.broadcast_to(w, d.shape[1:]), np.clip(d[2], 0.0, None)


def _grid_axes(
    values: ArrayLike,
    theta_i_deg: ArrayLike,
    azimuth_deg: ArrayLike,
    radial_deg: ArrayLike,
    symmetry: str,
) -> tuple[NDArray[np.float64], ...]:
    """The arguments of :func:`grid_integral` as float arrays, checked against each other."""
    if symmetry not in SYMMETRIES:
        raise ValueError(f"symmetry {symmetry!r}: expected one of {list(SYMMETRIES)}")
    v = np.asarray(values, dtype=float)
    ti, az, rad = (
        np.atleast_1d(np.asarray(x, float)) for x in (theta_i_deg, azimuth_deg, radial_deg)
    )
    for name, a in (("theta_i_deg", ti), ("azimuth_deg", az), ("radial_deg", rad)):
        if a.ndim != 1 or a.size == 0:
            raise ValueError(f"{name}: expected a non-empty 1-D list of angles [deg]")
    if v.ndim != 5 or v.shape[2:] != (ti.size, az.size, rad.size):
        raise ValueError(
            "values: expected shape (rotation, channel, "
            f"{ti.size}, {az.size}, {rad.size}) from the grid, got {v.shape}"
        )
    return v, ti, az, rad


def grid_integral(
    values: ArrayLike,
    theta_i_deg: ArrayLike,
    azimuth_deg: ArrayLike,
    radial_deg: ArrayLike,
    *,
    symmetry: str = "Asymmetrical",
    tis: ArrayLike | None = None,
) -> dict[str, NDArray[np.float64]]:
    """Hemispherical integral ``int f cos(theta_r) d omega`` of BSDF blocks on a scatter grid.

    Parameters
    ----------
    values : array_like
        ``(rotation, channel, aoi, azimuth, radial)`` BSDF [sr^-1] (0 below the horizon or
        not: points below it do not count).
    theta_i_deg, azimuth_deg, radial_deg : array_like
        The grid [deg]: specular angles, scatter azimuths and radial angles about the
        specular direction (:func:`labbrdf.bsdf_geometry.scatter_to_direction`).
    symmetry : {"PlaneSymmetrical", "Asymmetrical", "Asymmetrical4D"}
        Grid symmetry; a PlaneSymmetrical half (azimuths 0..180) counts twice.
    tis : array_like, optional
        ``(rotation, channel, aoi)`` total integrated scatter to compare with (e.g. a
        file's); NaN when not given.

    Returns
    -------
    dict
        ``integral`` ``(rotation, channel, aoi)`` [1]; ``uncovered_fraction`` ``(aoi,)``: the
        fraction of the projected solid angle of the hemisphere (pi sr) that the grid does
        not cover; ``tis`` (NaN when unknown) and ``ratio`` = tis / integral.

    Raises
    ------
    ValueError
        An unknown symmetry, an empty or multi-dimensional angle list, or values whose
        shape does not fit the grid.

    Notes
    -----
    Each grid node owns a cell bounded by the midpoints to its neighbours (the end nodes
    own half cells; a full azimuth circle wraps; a PlaneSymmetrical half counts twice).
    The solid angle of a cell about the specular direction is exactly
    ``(cos r_lo - cos r_hi) (a_hi - a_lo)``, and the projection factor is ``cos theta_r`` at
    the node, 0 below the horizon (the definition of the hemispherical reflectance, e.g.
    Nicodemus et al., NBS Monograph 160, 1977). This is a first-order rule, so a file's
    TIS (integrated by the instrument on its own, finer native sampling) need not agree:
    on the Radiant imaging-sphere export the TIS is 4-20 % above this integral. Causes:
    coarse radial steps (10 deg beyond 20 deg) across a curved lobe, the part of the
    hemisphere beyond the largest radial angle that the grid does not cover
    (``uncovered_fraction``), the zeros the instrument writes at directions next to the
    horizon, and the cells that straddle the horizon (cut at the node, not at z = 0).
    """
    v, ti, az, rad = _grid_axes(values, theta_i_deg, azimuth_deg, radial_deg, symmetry)
    if tis is None:
        tis_a = np.full(v.shape[:3], np.nan)
    else:
        tis_a = np.asarray(tis, float)
        if tis_a.shape != v.shape[:3]:
            raise ValueError(f"tis: expected shape {v.shape[:3]}, got {tis_a.shape}")
    w, cz = _cos_weights(ti, az, rad, symmetry)
    integral = np.einsum("rcazq,azq->rca", v, w * cz)
    covered = np.sum(w * cz, axis=(1, 2)) / np.pi
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = tis_a / integral
    return {
        "integral": integral,
        "uncovered_fraction": 1.0 - covered,
        "tis": tis_a,
        "ratio": ratio,
    }
