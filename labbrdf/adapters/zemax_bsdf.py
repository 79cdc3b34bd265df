"""Zemax / Radiant "BSDF Data Interchange" tabular text files (``.bsdf``): the reader.

The format (Radiant Imaging, "BSDF Data Interchange File Format Specification", 2008; the
"Zemax Tabular BSDF data file format" article of the Zemax knowledge base) is a header::

    #<comment lines anywhere>
    Source  Measured
    Symmetry  PlaneSymmetrical | Asymmetrical | Asymmetrical4D
    SpectralContent  Monochrome | XYZ
    ScatterType  BRDF | BTDF
    SampleRotation  <n>         then n rotations [deg]
    AngleOfIncidence  <n>       then n angles [deg]
    ScatterAzimuth  <n>         then n azimuths [deg]
    ScatterRadial  <n>          then n radial angles [deg]

followed, per spectral channel (``Monochrome``, or ``TristimulusX``, ``TristimulusY``,
``TristimulusZ``), by the channel's name, ``DataBegin``, then for every sample rotation and
every angle of incidence (rotation outermost) a ``TIS <value>`` line and one row per azimuth
with one value per radial angle, and an optional ``DataEnd``. Cells are separated by tabs or
spaces.

Geometry (see ``docs/bsdf.md``; the functions are in :mod:`labbrdf.bsdf_geometry`): the
scatter angles are given about the specular direction (the direction of direct transmission
for BTDF): radial 0 is the specular direction, azimuth 0 points from the specular direction
towards the sample normal, azimuths increase counter-clockwise. The specification does not
say from which side "counter-clockwise" is seen; labbrdf takes it as seen by an observer
looking back at the sample along the specular direction, so azimuth 90 is the +y side when
the source is at phi_i = 0. Every point is converted exactly (unit vectors, no small-angle
approximation) to the dataset's ``theta_i_deg``, ``theta_r_deg``, ``phi_r_deg``.
The file's text is read into a :class:`BsdfTable` on its own grid by
:mod:`labbrdf.adapters.zemax_bsdf_table`; this module turns the table into dataset rows,
mirrors a PlaneSymmetrical half and integrates a table on its grid. The writer is
:mod:`labbrdf.writers.zemax`; the grid quadrature is :func:`labbrdf.integrate.grid_integral`.
"""

from __future__ import annotations

import math
import os
import re
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from ..bsdf_geometry import (
    angles_to_scatter,
    azimuth_weights,
    scatter_to_angles,
    scatter_to_direction,
)
from ..dataset import Measurement
from ._base import AdapterError, Format
from ._frame import build_frame
from .zemax_bsdf_table import (
    HEADER_LISTS,
    SCATTER_TYPES,
    SPECTRAL,
    WAVELENGTH_COMMENT,
    BsdfTable,
    read_table,
    stated_wavelength,
)

__all__ = [
    "FORMATS",
    "HEADER_LISTS",
    "SCATTER_TYPES",
    "SPECTRAL",
    "WAVELENGTH_COMMENT",
    "BsdfTable",
    "angles_to_scatter",
    "grid_integral",
    "mirror_plane_symmetric",
    "read_table",
    "read_zemax_bsdf",
    "scatter_to_angles",
    "scatter_to_direction",
    "stated_wavelength",
]

INSTRUMENT = "zemax-bsdf"
#: channel column value per section name (Monochrome files have no channel column)
_CHANNEL = {"Monochrome": "", "TristimulusX": "X", "TristimulusY": "Y", "TristimulusZ": "Z"}

#: Wavelength written in the dataset when the file states none [nm]: the photopic peak.
#: The format has no wavelength field; Monochrome data of the imaging sphere are luminance
#: (photopic) data and XYZ data are tristimulus values, so 555 nm is a label, not a
#: measurement. ``meta["wavelength_stated"]`` is False; pass ``wavelength_nm=`` to override.
DEFAULT_WAVELENGTH_NM = 555.0

_SNIFF = re.compile(rb"^\s*(Source|Symmetry|SpectralContent|ScatterType)\s", re.MULTILINE)


# ------------------------------------------------------------------------------ reader


def _pole_repeats(shape: tuple[int, ...], radial_deg: NDArray[np.float64]) -> NDArray[np.bool_]:
    """The grid points that repeat the pole: radial 0 at every azimuth but the first.

    At radial angle 0 every azimuth names the same direction (the specular one, or that of
    direct transmission), so the file writes that one point once per azimuth.
    """
    rep = np.zeros(shape, dtype=bool)
    if radial_deg.size and radial_deg[0] == 0.0:
        rep[..., 1:, 0] = True
    return rep


def _table_frame(
    t: BsdfTable, path: str | os.PathLike[str], wavelength_nm: float
) -> tuple[pd.DataFrame, int, int]:
    """Rows above the horizon in the dataset schema, and the counts left out.

    Returns the frame, the number of points below the horizon, and the number of repeated
    pole points (the pole is one row per block).
    """
    nrot, nch, naoi, naz, nrad = t.values.shape
    full = t.values.shape
    theta_r, phi_r, above_f = (
        np.broadcast_to(x, full).reshape(-1)
        for x in scatter_to_angles(
            t.theta_i_deg[:, None, None], t.radial_deg[None, None, :], t.azimuth_deg[None, :, None]
        )
    )
    above = np.asarray(above_f, dtype=bool)
    repeat = _pole_repeats(full, t.radial_deg).reshape(-1)
    keep = np.flatnonzero(above & ~repeat)
    values = t.values.copy()
    if repeat.any():
        # one value for the one direction: the file's, or, where the azimuths of a block
        # disagree, their mean weighted by the azimuth cells (the average over the polar
        # cap, so grid_integral is unchanged; meta["pole"] reports the largest spread)
        pole = values[..., 0]
        w = azimuth_weights(t.azimuth_deg, t.symmetry)
        values[..., 0, 0] = np.where(
            np.all(pole == pole[..., :1], axis=-1), pole[..., 0], (pole @ w) / w.sum()
        )
    ti = np.broadcast_to(t.theta_i_deg[:, None, None], full).reshape(-1)
    optional: dict[str, Any] = {}
    if nrot > 1 or t.rotation_deg[0] != 0:
        optional["sample_rotation_deg"] = np.repeat(t.rotation_deg, nch * naoi * naz * nrad)[keep]
    if t.spectral == "XYZ":
        codes = np.repeat(np.tile(np.arange(nch, dtype=np.int8), nrot), naoi * naz * nrad)
        optional["channel"] = pd.Categorical.from_codes(codes[keep], categories=["X", "Y", "Z"])
    frame = build_frame(
        sample=Path(path).stem,
        instrument=INSTRUMENT,
        source=os.path.basename(os.fspath(path)),
        quantity=SCATTER_TYPES[t.scatter_type],
        value=values.reshape(-1)[keep],
        unit="sr-1",
        wavelength_nm=wavelength_nm,
        theta_i_deg=ti[keep],
        theta_r_deg=theta_r[keep],
        phi_r_deg=phi_r[keep],
        **optional,
    )
    return frame, int((~above).sum()), int((above & repeat).sum())


def _pole_meta(t: BsdfTable, repeats: int) -> dict[str, Any]:
    """What became of the pole (radial 0) points: one row kept per block."""
    if not repeats:
        return {"repeats_left_out": 0}
    pole = t.values[..., 0]
    spread = np.max(np.abs(pole - pole[..., :1]))
    return {
        "repeats_left_out": repeats,
        "rule": "radial 0 is one direction at every azimuth: one row per incidence (and "
        "rotation, channel), with the file's value, or, where the azimuths' values differ, "
        "their mean weighted by the azimuth cell widths",
        "max_spread_sr-1": float(spread),
    }


def _tis_meta(t: BsdfTable) -> list[dict[str, Any]]:
    out = []
    for r, rot in enumerate(t.rotation_deg):
        for c, name in enumerate(t.channels):
            for a, ti in enumerate(t.theta_i_deg):
                out.append(
                    {
                        "theta_i_deg": float(ti),
                        "rotation_deg": float(rot),
                        "channel": _CHANNEL[name],
                        "tis": float(t.tis[r, c, a]),
                    }
                )
    return out


def read_zemax_bsdf(
    path: str | os.PathLike[str], *, wavelength_nm: float | None = None
) -> Measurement:
    """Read a Zemax / Radiant ``.bsdf`` tabular file into a :class:`Measurement`.

    Parameters
    ----------
    path : str or path-like
        The file.
    wavelength_nm : float, optional
        Wavelength to record [nm]. The format has no wavelength field: by default the one a
        comment states (:func:`stated_wavelength`), else :data:`DEFAULT_WAVELENGTH_NM`
        (555 nm, a photopic label) with ``meta["wavelength_stated"]`` False.

    Returns
    -------
    Measurement
        One row per grid point above the horizon, the pole (radial 0, the same direction
        at every azimuth) once per incidence: quantity ``brdf`` or ``btdf`` [sr-1],
        ``theta_i_deg``, ``theta_r_deg``, ``phi_r_deg`` from the exact conversion of the
        scatter angles; ``channel`` ``X``/``Y``/``Z`` for tristimulus files;
        ``sample_rotation_deg`` when the file has a rotation other than 0. PlaneSymmetrical
        files keep the measured half only (azimuths 0..180, i.e. phi_r in [0, 180] or 180..,
        see :func:`mirror_plane_symmetric`). ``meta`` holds the header, ``tis`` (one entry
        per block), ``grid`` (the file's lists), ``dropped_below_horizon`` and
        ``zero_values_kept`` (zeros above the horizon, kept as data), ``pole`` (the
        repeated pole points left out) and ``wavelength_stated`` (False when no comment
        states the wavelength: then the 555 nm label is written, see
        :data:`DEFAULT_WAVELENGTH_NM`).

    Raises
    ------
    AdapterError
        See :func:`read_table`.
    """
    t = read_table(path)
    if wavelength_nm is None:
        wavelength_nm = t.wavelength_nm
    stated = wavelength_nm is not None
    wl = float(wavelength_nm) if wavelength_nm is not None else DEFAULT_WAVELENGTH_NM
    if not (math.isfinite(wl) and wl > 0):
        raise AdapterError(path, f"wavelength_nm={wavelength_nm!r}: expected a finite number > 0")
    frame, dropped, repeats = _table_frame(t, path, wl)
    meta: dict[str, Any] = {
        "format": "zemax-bsdf",
        "source_keyword": t.source,
        "symmetry": t.symmetry,
        "spectral_content": t.spectral,
        "scatter_type": t.scatter_type,
        "wavelength_stated": stated,
        "wavelength_nm": wl,
        "grid": {
            "rotation_deg": t.rotation_deg.tolist(),
            "theta_i_deg": t.theta_i_deg.tolist(),
            "azimuth_deg": t.azimuth_deg.tolist(),
            "radial_deg": t.radial_deg.tolist(),
            "channels": [_CHANNEL[c] for c in t.channels],
        },
        "tis": _tis_meta(t),
        "dropped_below_horizon": dropped,
        "pole": _pole_meta(t, repeats),
        "zero_values_kept": int((frame["value"].to_numpy() == 0).sum()),
        "comments": t.comments,
    }
    if t.symmetry == "PlaneSymmetrical":
        meta["mirror"] = (
            "the other half of the scatter hemisphere is the mirror image of the rows given, "
            "phi_r -> 360 - phi_r (see mirror_plane_symmetric)"
        )
    try:
        return Measurement(frame, meta)
    except ValueError as exc:
        raise AdapterError(path, f"invalid data: {exc}") from None


def mirror_plane_symmetric(m: Measurement) -> Measurement:
    """The full hemisphere of a PlaneSymmetrical measurement: rows plus their mirror images.

    Rows off the plane of incidence (0 < phi_r < 180 or 180 < phi_r < 360, and theta_r > 0)
    are copied with ``phi_r -> 360 - phi_r``; rows in the plane are their own mirror image
    and are not duplicated. ``meta["mirrored"]`` is set to the number of rows added.

    Raises
    ------
    ValueError
        ``meta["symmetry"]`` is not ``PlaneSymmetrical`` or the data are already mirrored.
    """
    if m.meta.get("symmetry") != "PlaneSymmetrical":
        raise ValueError("mirror_plane_symmetric needs meta['symmetry'] == 'PlaneSymmetrical'")
    if "mirrored" in m.meta:
        raise ValueError("the measurement is already mirrored")
    d = m.data
    phi = d["phi_r_deg"].to_numpy()
    tol = 1e-9
    in_plane = (
        (np.abs(phi) < tol)
        | (np.abs(phi - 180.0) < tol)
        | (np.abs(phi - 360.0) < tol)
        | (d["theta_r_deg"].to_numpy() < tol)
    )
    extra = d[~in_plane].copy()
    extra["phi_r_deg"] = np.mod(360.0 - extra["phi_r_deg"].to_numpy(), 360.0)
    data = pd.concat(
        [
            d.assign(quantity=d["quantity"].astype(str)),
            extra.assign(quantity=extra["quantity"].astype(str)),
        ],
        ignore_index=True,
    )
    meta = dict(m.meta)
    meta["mirrored"] = int(len(extra))
    return Measurement(data, meta)


# ------------------------------------------------------------------------------ quadrature


def _table_of(obj: BsdfTable | Measurement | Mapping[str, Any]) -> BsdfTable:
    if isinstance(obj, BsdfTable):
        return obj
    if isinstance(obj, Measurement):
        return _table_from_measurement(obj)
    v = np.asarray(obj["values"], dtype=float)
    theta_i = np.atleast_1d(np.asarray(obj["theta_i_deg"], float))
    az = np.atleast_1d(np.asarray(obj["azimuth_deg"], float))
    rad = np.atleast_1d(np.asarray(obj["radial_deg"], float))
    v = v.reshape((-1, v.shape[-4] if v.ndim >= 4 else 1, theta_i.size, az.size, rad.size))
    spectral = "XYZ" if v.shape[1] == 3 else "Monochrome"
    return BsdfTable(
        symmetry=obj.get("symmetry", "Asymmetrical"),
        spectral=spectral,
        scatter_type=obj.get("scatter_type", "BRDF"),
        rotation_deg=np.arange(v.shape[0], dtype=float),
        theta_i_deg=theta_i,
        azimuth_deg=az,
        radial_deg=rad,
        values=v,
        tis=np.full(v.shape[:3], np.nan),
    )


def _table_from_measurement(m: Measurement) -> BsdfTable:
    """Put the rows of a reader's Measurement back on the file's grid (0 below the horizon).

    The reader writes the rows in the file's order (rotation, channel, incidence, azimuth,
    radial), skipping the points below the horizon and the pole's repeats (its one row is
    copied back to every azimuth); this checks that the rows are still
    those (same count, same angles to 1e-9 deg) and refuses a filtered or mirrored table.
    """
    g = m.meta.get("grid")
    if not g:
        raise ValueError("the measurement has no meta['grid'] (not read from a .bsdf file)")
    rot, aoi = np.array(g["rotation_deg"], float), np.array(g["theta_i_deg"], float)
    az, rad = np.array(g["azimuth_deg"], float), np.array(g["radial_deg"], float)
    nch = len(g["channels"])
    shape = (rot.size, nch, aoi.size, az.size, rad.size)
    _, _, ai, zi, qi = np.indices(shape).reshape(5, -1)
    theta_r, phi_r, above = scatter_to_angles(aoi[ai], rad[qi], az[zi])
    repeat = _pole_repeats(shape, rad).reshape(-1)
    if not (m.meta.get("pole") or {}).get("repeats_left_out"):
        repeat[:] = False  # read before the pole was kept once
    kept = above & ~repeat
    d = m.data
    same = len(d) == int(kept.sum()) and "mirrored" not in m.meta
    if same:
        dphi = np.abs(d["phi_r_deg"].to_numpy() - phi_r[kept])
        same = bool(
            np.all(np.abs(d["theta_r_deg"].to_numpy() - theta_r[kept]) < 1e-9)
            and np.all(np.minimum(dphi, 360.0 - dphi) < 1e-9)
            and np.all(d["theta_i_deg"].to_numpy() == aoi[ai[kept]])
        )
    if not same:
        raise ValueError(
            "the rows are not those read from the file (filtered, mirrored or reordered); "
            "pass the BsdfTable of read_table() instead"
        )
    v = np.zeros(shape)
    v.reshape(-1)[kept] = d["value"].to_numpy()
    if repeat.any():
        v[..., 1:, 0] = v[..., :1, 0]  # the pole, at every azimuth of the grid
    return BsdfTable(
        symmetry=m.meta.get("symmetry", "Asymmetrical"),
        spectral=m.meta.get("spectral_content", "Monochrome"),
        scatter_type=m.meta.get("scatter_type", "BRDF"),
        rotation_deg=rot,
        theta_i_deg=aoi,
        azimuth_deg=az,
        radial_deg=rad,
        values=v,
        tis=np.array([e["tis"] for e in m.meta.get("tis", [])] or np.nan, float).reshape(shape[:3])
        if m.meta.get("tis")
        else np.full(shape[:3], np.nan),
    )


def grid_integral(obj: BsdfTable | Measurement | Mapping[str, Any]) -> dict[str, Any]:
    """Hemispherical integral ``int f cos(theta_r) d omega`` of each block on its own grid.

    The ``.bsdf`` face of :func:`labbrdf.integrate.grid_integral`, which holds the
    quadrature rule and its limits.

    Parameters
    ----------
    obj : BsdfTable, Measurement or mapping
        A table from :func:`read_table`, a Measurement from :func:`read_zemax_bsdf`, or a
        mapping with ``values`` ``(rotation, channel, aoi, azimuth, radial)`` [sr^-1],
        ``theta_i_deg``, ``azimuth_deg``, ``radial_deg`` [deg] and optional ``symmetry``.

    Returns
    -------
    dict
        ``integral`` ``(rotation, channel, aoi)`` [1]; ``uncovered_fraction`` ``(aoi,)``: the
        fraction of the projected solid angle of the hemisphere (pi sr) that the grid does
        not cover; ``tis`` (the file's values, NaN when unknown) and ``ratio`` = tis /
        integral.
    """
    from ..bsdf_geometry import grid_integral as quadrature

    t = _table_of(obj)
    return quadrature(
        t.values,
        t.theta_i_deg,
        t.azimuth_deg,
        t.radial_deg,
        symmetry=t.symmetry,
        tis=t.tis,
    )


# ------------------------------------------------------------------------------ registry


def _sniff(head: bytes) -> bool:
    """Two of the header keywords at line starts within the first bytes; never raises."""
    try:
        found = {m.group(1) for m in _SNIFF.finditer(head[:4096])}
        return len(found) >= 3 or (len(found) >= 2 and b"AngleOfIncidence" in head)
    except Exception:  # pragma: no cover - defensive: a sniffer must not raise
        return False


FORMATS = (
    Format(
        "zemax-bsdf",
        "Zemax / Radiant BSDF Data Interchange tabular text (.bsdf): BRDF/BTDF on a "
        "specular-centred grid",
        (".bsdf",),
        _sniff,
        read_zemax_bsdf,
        ("brdf", "btdf"),
        keywords=(b"AngleOfIncidence", b"ScatterAzimuth", b"ScatterRadial"),
    ),
)
