"""Export to Zemax / Radiant ``.bsdf`` files: arrays, fitted models and tracer results.

Workflow layer: evaluates a :class:`labbrdf.models.Model` or takes a tracer's binned S0,
puts it on a scatter grid about the specular direction (the geometry of
:mod:`labbrdf.bsdf_geometry`, the reader's) and writes the file atomically in the layout
that :mod:`labbrdf.adapters.zemax_bsdf` reads (the format is described there and in
``docs/bsdf.md``). The TIS of each block is, unless given, the grid quadrature
:func:`labbrdf.integrate.grid_integral` of the values written.
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..adapters.zemax_bsdf import HEADER_LISTS, SCATTER_TYPES, SPECTRAL, WAVELENGTH_COMMENT
from ..bsdf_geometry import SYMMETRIES, scatter_to_angles
from ..dataset import atomic_output
from ..integrate import grid_integral
from ..outputs import check_file_output

__all__ = ["angle_grid", "binned_to_bsdf", "model_to_bsdf", "write_bsdf"]


def _fmt(v: float, digits: int) -> str:
    return f"{v:.{digits - 1}E}"


def _check_grid(name: str, a: NDArray[np.float64], lo: float, hi: float) -> None:
    if a.ndim != 1 or a.size == 0 or not np.isfinite(a).all():
        raise ValueError(f"{name}: expected a non-empty 1-D list of finite angles [deg]")
    if a.min() < lo or a.max() > hi or (a.size > 1 and not np.all(np.diff(a) > 0)):
        raise ValueError(f"{name}: expected strictly increasing values in [{lo:g}, {hi:g}] deg")


def _check_keywords(symmetry: str, scatter_type: str, digits: int) -> None:
    """The header keywords and the number of digits, else ValueError."""
    if symmetry not in SYMMETRIES:
        raise ValueError(f"symmetry {symmetry!r}: expected one of {list(SYMMETRIES)}")
    if scatter_type not in SCATTER_TYPES:
        raise ValueError(f"scatter_type {scatter_type!r}: expected one of {list(SCATTER_TYPES)}")
    if not (isinstance(digits, int) and 1 <= digits <= 17):
        raise ValueError(f"digits={digits!r}: expected an integer in 1..17")


def _grid_lists(
    symmetry: str,
    rotation_deg: ArrayLike,
    theta_i_deg: ArrayLike,
    azimuth_deg: ArrayLike,
    radial_deg: ArrayLike,
) -> tuple[NDArray[np.float64], ...]:
    """The four header lists ``(rotation, aoi, azimuth, radial)`` [deg], checked."""
    ti = np.atleast_1d(np.asarray(theta_i_deg, float))
    rad = np.atleast_1d(np.asarray(radial_deg, float))
    az = np.atleast_1d(np.asarray(azimuth_deg, float))
    rot = np.atleast_1d(np.asarray(rotation_deg, float))
    _check_grid("theta_i_deg", ti, 0.0, 90.0)
    _check_grid("radial_deg", rad, 0.0, 180.0)
    _check_grid("azimuth_deg", az, 0.0, 180.0 if symmetry == SYMMETRIES[0] else 360.0)
    _check_grid("rotation_deg", rot, -360.0, 360.0)
    return rot, ti, az, rad


def _spectral_of(
    spectral: str | None, channels: Sequence[str] | None, n_channels: int
) -> tuple[str, tuple[str, ...]]:
    """The ``SpectralContent`` keyword and its channel names, from what the caller gave."""
    if spectral is None:
        if channels is not None:
            spectral = "XYZ" if tuple(channels) == ("X", "Y", "Z") else "Monochrome"
        else:
            spectral = "XYZ" if n_channels == 3 else "Monochrome"
    if spectral not in SPECTRAL:
        raise ValueError(f"spectral {spectral!r}: expected one of {list(SPECTRAL)}")
    want_ch = ("X", "Y", "Z") if spectral == "XYZ" else ("",)
    if channels is not None and tuple(channels) not in (want_ch, ("Monochrome",)):
        raise ValueError(f"channels {tuple(channels)} do not fit spectral {spectral!r}")
    return spectral, want_ch


def _checked_values(values: ArrayLike, shape: tuple[int, ...]) -> NDArray[np.float64]:
    v = np.asarray(values, float)
    if v.shape != shape:
        raise ValueError(f"values: expected shape {shape}, got {v.shape}")
    if not np.isfinite(v).all():
        raise ValueError("values: expected finite numbers (no NaN or inf)")
    return v


def _block_tis(
    tis: ArrayLike | None,
    v: NDArray[np.float64],
    lists: tuple[NDArray[np.float64], ...],
    symmetry: str,
) -> NDArray[np.float64]:
    """The TIS of each block: the caller's (checked) or the grid quadrature of ``v``."""
    _, ti, az, rad = lists
    if tis is None:
        return grid_integral(v, ti, az, rad, symmetry=symmetry)["integral"]
    tis_a = np.asarray(tis, float)
    if tis_a.shape != v.shape[:3] or not np.isfinite(tis_a).all():
        raise ValueError(f"tis: expected finite numbers of shape {v.shape[:3]}")
    return tis_a


def _header_text(
    comments: Iterable[str],
    symmetry: str,
    spectral: str,
    scatter_type: str,
    lists: tuple[NDArray[np.float64], ...],
) -> str:
    """Comment lines, the four keywords and the four lists (rotation outermost)."""
    head = [f"#{c}" for c in comments]
    head += [
        "Source  Measured",
        f"Symmetry  {symmetry}",
        f"SpectralContent  {spectral}",
        f"ScatterType  {scatter_type}",
    ]
    for key, arr in zip(HEADER_LISTS, lists, strict=True):
        head += [f"{key}  {arr.size}", "\t".join(f"{x:.15g}" for x in arr)]
    head.append("")
    return "\n".join(head)


def _section_text(name: str, v: NDArray[np.float64], tis: NDArray[np.float64], digits: int) -> str:
    """One channel's section: ``(rotation, aoi, azimuth, radial)`` values ``v``, ``tis``."""
    sec = [name, "DataBegin"]
    for r in range(v.shape[0]):
        for a in range(v.shape[1]):
            sec.append(f"TIS {_fmt(tis[r, a], digits)}")
            sec += ["\t".join(_fmt(x, digits) for x in row) for row in v[r, a].tolist()]
    sec.append("DataEnd")
    return "\n".join(sec)


def write_bsdf(
    path: str | os.PathLike[str],
    *,
    theta_i_deg: ArrayLike,
    radial_deg: ArrayLike,
    azimuth_deg: ArrayLike,
    values: ArrayLike,
    tis: ArrayLike | None = None,
    symmetry: str = "Asymmetrical",
    spectral: str | None = None,
    scatter_type: str = "BRDF",
    rotation_deg: ArrayLike = (0,),
    channels: Sequence[str] | None = None,
    comments: Iterable[str] = (),
    digits: int = 6,
    overwrite: bool = False,
) -> Path:
    """Write a Zemax / Radiant ``.bsdf`` tabular file, atomically.

    Parameters
    ----------
    path : str or path-like
        Output file; an existing file is refused unless ``overwrite``.
    theta_i_deg, radial_deg, azimuth_deg : array_like
        The grid [deg]: angles of incidence (specular angles), scatter radial and azimuth
        angles (strictly increasing; azimuths within [0, 180] for PlaneSymmetrical).
    values : array_like
        ``(rotation, channel, aoi, azimuth, radial)`` BSDF [sr^-1], finite.
    tis : array_like, optional
        ``(rotation, channel, aoi)`` total integrated scatter; by default computed with
        :func:`labbrdf.integrate.grid_integral`.
    symmetry : {"PlaneSymmetrical", "Asymmetrical", "Asymmetrical4D"}
    spectral : {"Monochrome", "XYZ"}, optional
        By default from ``channels`` or from the channel axis of ``values`` (1 or 3).
    scatter_type : {"BRDF", "BTDF"}
    rotation_deg : array_like
        Sample rotations [deg].
    channels : sequence of str, optional
        ``("X", "Y", "Z")`` for tristimulus data, ``("",)`` or None for monochrome.
    comments : iterable of str
        Written as ``#`` lines at the top.
    digits : int
        Significant digits of each value (and TIS), 1..17.
    overwrite : bool
        Replace an existing file (never an input of the :func:`labbrdf.outputs.write_policy`
        in force).

    Returns
    -------
    pathlib.Path
        The file written.

    Raises
    ------
    labbrdf.outputs.OutputError
        The output is refused (:func:`labbrdf.outputs.check_file_output`): an existing file
        without ``overwrite``, an input, a folder, a non-regular file.
    """
    target = check_file_output(path, overwrite=overwrite)  # the one rule of every output
    _check_keywords(symmetry, scatter_type, digits)
    lists = _grid_lists(symmetry, rotation_deg, theta_i_deg, azimuth_deg, radial_deg)
    v = np.asarray(values, float)
    if v.ndim != 5:
        raise ValueError(
            f"values: expected 5 axes (rotation, channel, aoi, azimuth, radial), got {v.ndim}"
        )
    spectral, want_ch = _spectral_of(spectral, channels, v.shape[1])
    rot, ti, az, rad = lists
    v = _checked_values(v, (rot.size, len(want_ch), ti.size, az.size, rad.size))
    tis_a = _block_tis(tis, v, lists, symmetry)
    parts = [_header_text(comments, symmetry, spectral, scatter_type, lists)]
    for c, name in enumerate(SPECTRAL[spectral]):
        parts.append(_section_text(name, v[:, c], tis_a[:, c], digits))
    with atomic_output(target) as tmp, open(tmp, "w", encoding="ascii", newline="\n") as fh:
        fh.write("\n".join(parts) + "\n")
    return target


def model_to_bsdf(
    model: Any,
    params: Mapping[str, float] | Any,
    path: str | os.PathLike[str],
    *,
    theta_i_deg: ArrayLike,
    radial_deg: ArrayLike,
    azimuth_deg: ArrayLike,
    wavelength_nm: float | None = None,
    symmetry: str = "PlaneSymmetrical",
    digits: int = 6,
    comments: Iterable[str] = (),
    overwrite: bool = False,
) -> Path:
    """Evaluate a labbrdf model on a scatter grid and write it as a ``.bsdf`` file.

    Each grid point (specular angle, radial, azimuth) is converted to (theta_i, theta_r,
    phi_r) by :func:`scatter_to_angles` (the reader's geometry); below-horizon points get
    0; the TIS of each block is the :func:`labbrdf.integrate.grid_integral` of the values
    written.

    Parameters
    ----------
    model : labbrdf.models.Model
        E.g. ``labbrdf.models.get("smooth3")``.
    params : mapping or Parameters
        Parameter values (None: the model's current values).
    path : str or path-like
        Output file (see :func:`write_bsdf`).
    theta_i_deg, radial_deg, azimuth_deg : array_like
        The grid [deg].
    wavelength_nm : float, optional
        Passed to the model's ``evaluate`` [nm].
    symmetry : str
        ``PlaneSymmetrical`` (azimuths 0..180) for an isotropic model, else
        ``Asymmetrical``.
    digits, comments, overwrite
        As in :func:`write_bsdf`.
    """
    ti = np.atleast_1d(np.asarray(theta_i_deg, float))
    rad = np.atleast_1d(np.asarray(radial_deg, float))
    az = np.atleast_1d(np.asarray(azimuth_deg, float))
    tr, pr, above = scatter_to_angles(ti[:, None, None], rad[None, None, :], az[None, :, None])
    tib = np.broadcast_to(ti[:, None, None], tr.shape)
    f = model.evaluate(
        np.radians(tib),
        np.radians(np.where(above, tr, 0.0)),
        np.radians(pr),
        wavelength=wavelength_nm,
        params=params,
    )
    vals = np.where(above, np.asarray(f, float), 0.0)[None, None]
    name = getattr(model, "name", type(model).__name__)
    return write_bsdf(
        path,
        theta_i_deg=ti,
        radial_deg=rad,
        azimuth_deg=az,
        values=vals,
        symmetry=symmetry,
        comments=(
            f"labbrdf model {name}",
            *([f"{WAVELENGTH_COMMENT}{float(wavelength_nm):.17g}"] if wavelength_nm else []),
            *comments,
        ),
        digits=digits,
        overwrite=overwrite,
    )


def binned_to_bsdf(
    path: str | os.PathLike[str],
    *,
    theta_i_deg: float,
    values: ArrayLike,
    theta_edges_deg: ArrayLike,
    phi_edges_deg: ArrayLike,
    radial_deg: ArrayLike,
    azimuth_deg: ArrayLike,
    wavelength_nm: float | None = None,
    symmetry: str = "PlaneSymmetrical",
    comments: Iterable[str] = (),
    digits: int = 6,
    overwrite: bool = False,
) -> Path:
    """Write a BRDF binned on a (theta_r, phi_r) grid (a tracer's S0) as a ``.bsdf`` file.

    Each scatter grid point (radial, azimuth about the specular direction of
    ``theta_i_deg``) is converted to (theta_r, phi_r) by :func:`scatter_to_angles` and takes
    the value of the bin it falls in; below the horizon it is 0.

    Parameters
    ----------
    path : str or path-like
        Output file; an existing file is refused unless ``overwrite``.
    theta_i_deg : float
        Angle of incidence of the binned data [deg].
    values : array_like, shape (n_theta, n_phi)
        Bin-averaged BRDF [sr^-1], e.g. :meth:`labbrdf.TraceResult.s0`.
    theta_edges_deg, phi_edges_deg : array_like
        Bin edges [deg], ``n_theta + 1`` in [0, 90] and ``n_phi + 1`` in [0, 360]
        (outward azimuth, source at 0).
    radial_deg, azimuth_deg : array_like
        The scatter grid to write [deg].
    wavelength_nm : float, optional
        Written as a ``#labbrdf wavelength_nm`` comment, read back by
        :func:`labbrdf.adapters.zemax_bsdf.read_zemax_bsdf`.
    symmetry, comments, digits, overwrite :
        As in :func:`write_bsdf`.

    Returns
    -------
    pathlib.Path

    Notes
    -----
    The file holds bin averages at the grid points, not point values: features narrower
    than a bin (a near-specular spike of a smooth surface) are smeared over the bin width,
    as in the binned data themselves. Choose a scatter grid no finer than the bins.
    """
    v = np.asarray(values, float)
    te = np.asarray(theta_edges_deg, float)
    pe = np.asarray(phi_edges_deg, float)
    if v.ndim != 2 or v.shape != (te.size - 1, pe.size - 1):
        raise ValueError(
            f"values: expected shape ({te.size - 1}, {pe.size - 1}) from the edges, got {v.shape}"
        )
    v = np.where(np.isfinite(v), v, 0.0)
    rad = np.atleast_1d(np.asarray(radial_deg, float))
    az = np.atleast_1d(np.asarray(azimuth_deg, float))
    tr, pr, above = scatter_to_angles(float(theta_i_deg), rad[None, :], az[:, None])
    i = np.clip(np.searchsorted(te, tr, side="right") - 1, 0, v.shape[0] - 1)
    phi = pe[0] + np.mod(pr - pe[0], 360.0)  # into the edges' period (they may start at -0.5)
    j = np.clip(np.searchsorted(pe, phi, side="right") - 1, 0, v.shape[1] - 1)
    grid = np.where(above, v[i, j], 0.0)
    return write_bsdf(
        path,
        theta_i_deg=[float(theta_i_deg)],
        radial_deg=rad,
        azimuth_deg=az,
        values=grid[None, None, None],
        symmetry=symmetry,
        comments=(
            *([f"{WAVELENGTH_COMMENT}{float(wavelength_nm):.17g}"] if wavelength_nm else []),
            *comments,
        ),
        digits=digits,
        overwrite=overwrite,
    )


def angle_grid(text: str) -> NDArray[np.float64]:
    """The angles [deg] of ``START:STOP:STEP`` (STOP included) or of ``A,B,...``.

    The text form of a scatter grid's radial or azimuth angles (``labbrdf export
    --radial 0:80:2``), for :func:`model_to_bsdf` and :func:`binned_to_bsdf`.

    Raises
    ------
    ValueError
        Not numbers in one of the two forms, a step that is not positive or STOP < START.
    """
    try:
        if ":" in text:
            a, b, c = (float(x) for x in text.split(":"))
            if not c > 0 or b < a:
                raise ValueError
            return np.round(np.arange(a, b + c / 2, c), 9)
        return np.array([float(x) for x in text.split(",")], float)
    except ValueError:
        raise ValueError("expected START:STOP:STEP or a comma-separated list") from None
