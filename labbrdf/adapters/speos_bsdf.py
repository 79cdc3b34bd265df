"""Ansys Speos anisotropic BSDF text files (``.anisotropicbsdf``, format ``speos-bsdf``).

Layout of the text variant (version 8; the structure of anisotropic BSDF files in the Speos
user guide, as the ``ansys/optical-automation`` BSDF converter writes and reads it), one item
per line::

    OPTIS - Anisotropic BSDF surface file v8.0
    0                               0 = text, 1 = binary (refused)
    <comment>
    <n>                             characters of the measurement description
    <measurement description>       n characters, possibly over several lines
    <ax> <ay> <az>                  anisotropy vector
    <R> <T>                         1/0: reflection tables, transmission tables
    <type>                          1: values proportional to the BSDF (0: to the intensity)
    <nrot>                          for R (then for T): anisotropy angles
    <rot_1> ... <rot_nrot>          [deg]
    <ninc>                          per anisotropy angle: its incidences
    <inc_1> ... <inc_ninc>          [deg]
    <theta> <phi>                   for R (then T): direction of the spectrum measurement
    <spectrum description>
    <nwl>
    <wavelength> <coefficient>      nwl lines: [nm], [%]
    <ntheta> <nphi>                 per (R/T, rotation, incidence): one table
    <phi_1> ... <phi_nphi>          [deg]
    <theta> <v_1> ... <v_nphi>      ntheta rows
    End of file

Geometry. A table is in the *normal* reference: ``theta`` is the polar angle of the scatter
direction from the sample normal and ``phi`` its azimuth, with the specular direction at
``phi = 0`` (the converter maps normal-reference ``(theta, 0)`` to the specular-reference
radial ``theta - theta_i`` on the specular axis). The dataset puts the source at
``phi_r = 0`` and the specular direction at 180, so ``phi_r = phi + 180`` (mod 360): a
rotation by 180 deg about the normal, which keeps the handedness of the two frames
(``phi`` = 90 is the ``-y`` side of the dataset frame, as the converter's
``y_out = y_in`` says). Plane-symmetric data cannot tell the two sides apart.

Units. The tables are proportional to the BSDF (values type 1); Speos scales them so that
the hemispherical integral ``int f cos(theta) d omega`` of the table at the spectrum's
measurement incidence equals the spectrum coefficient (reflectance [%] / 100) at each
wavelength. The reader applies that scale: the values returned are BRDF [sr-1], one row
per grid point and spectrum wavelength, the table's quadrature (trapezoid in theta and phi
on its own grid, cos-weighted) and factor in ``meta["scale"]``.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..dataset import Measurement
from ._base import AdapterError, Example, Format, decode, parse_number, read_bytes, split_lines
from ._frame import build_frame
from ._numblock import parse_rows

__all__ = ["FORMATS", "SpeosTable", "read_speos_bsdf", "read_speos_table"]

INSTRUMENT = "speos-bsdf"
#: first line of every Speos BSDF text file (the version follows)
MAGIC = "OPTIS - Anisotropic BSDF surface file"
#: caps on the counts a header may announce (values per list, values in the file)
MAX_LIST = 100_000
MAX_POINTS = 50_000_000


@dataclass
class SpeosTable:
    """The numbers of a ``.anisotropicbsdf`` file on its own grid (reflection tables).

    Attributes
    ----------
    version : str
        The version after the magic words (``v8.0``).
    anisotropy_vector : ndarray
        ``(3,)`` the anisotropy vector in the global frame.
    rotation_deg, theta_i_deg : ndarray
        Anisotropy angles and incidences [deg].
    theta_deg, phi_deg : ndarray
        The table's polar angles from the normal and azimuths (specular at 0) [deg].
    values : ndarray
        ``(rotation, incidence, theta, phi)`` values proportional to the BRDF.
    spectrum_direction_deg : tuple of float
        ``(theta, phi)`` of the spectrum measurement [deg]; ``theta`` is the incidence
        whose table the spectrum normalises.
    wavelength_nm, coefficient_pct : ndarray
        The spectrum: wavelengths [nm] and reflectance there [%].
    comment, description : str
        The comment line and the measurement description.
    """

    version: str
    anisotropy_vector: NDArray[np.float64]
    rotation_deg: NDArray[np.float64]
    theta_i_deg: NDArray[np.float64]
    theta_deg: NDArray[np.float64]
    phi_deg: NDArray[np.float64]
    values: NDArray[np.float64]
    spectrum_direction_deg: tuple[float, float]
    wavelength_nm: NDArray[np.float64]
    coefficient_pct: NDArray[np.float64]
    comment: str = ""
    description: str = ""


class _Cursor:
    """The file's lines (blank ones included: the spectrum description may be empty)."""

    def __init__(self, path: str | os.PathLike[str], lines: list[str]) -> None:
        self.path, self.lines, self.i = path, lines, 0

    def line(self, what: str) -> tuple[int, str]:
        if self.i >= len(self.lines):
            raise AdapterError(self.path, f"the file ends where {what} was expected", self.i)
        self.i += 1
        return self.i, self.lines[self.i - 1].strip()

    def numbers(self, what: str, n: int | None = None) -> tuple[int, list[float]]:
        ln, s = self.line(what)
        vals = [parse_number(t, self.path, ln, what) for t in s.split()]
        if n is not None and len(vals) != n:
            raise AdapterError(self.path, f"{what}: expected {n} value(s), found {len(vals)}", ln)
        return ln, vals

    def count(self, what: str) -> tuple[int, int]:
        ln, (v,) = self.numbers(what, 1)
        if v != int(v) or not 0 <= v <= MAX_LIST:
            raise AdapterError(
                self.path, f"{what}: expected a count 0..{MAX_LIST}, found {v:g}", ln
            )
        return ln, int(v)


def _flag(cur: _Cursor, what: str, n: int) -> list[int]:
    ln, vals = cur.numbers(what, n)
    if any(v not in (0.0, 1.0) for v in vals):
        raise AdapterError(cur.path, f"{what}: expected 0 or 1, found {vals}", ln)
    return [int(v) for v in vals]


def _preamble(cur: _Cursor) -> tuple[str, str, str]:
    """Magic and version, the text/binary flag, comment and description."""
    ln, first = cur.line("the first line")
    if not first.lstrip("\ufeff").startswith(MAGIC):
        raise AdapterError(cur.path, f"expected a Speos BSDF file starting {MAGIC!r}", ln)
    version = first.lstrip("\ufeff")[len(MAGIC) :].strip()
    ln, mode = cur.line("the text/binary flag")
    if mode != "0":
        raise AdapterError(
            cur.path,
            f"a binary Speos BSDF file (mode {mode!r}, 0 is text): its layout is not "
            "published, so it is not read; save it as text from the Speos BSDF viewer",
            ln,
        )
    _, comment = cur.line("the comment line")
    _, nchar = cur.count("the length of the measurement description")
    lines: list[str] = []
    while sum(len(s) + 1 for s in lines) < nchar + 1:  # n characters, line breaks included
        lines.append(cur.line("the measurement description")[1])
    return version, comment, "\n".join(lines)


def _angles(cur: _Cursor) -> tuple[NDArray[np.float64], NDArray[np.float64], int]:
    """Anisotropy angles and the incidences (the same for every angle)."""
    _, nrot = cur.count("the number of anisotropy angles")
    ln, rot = cur.numbers("the anisotropy angles", nrot)
    incidences: list[float] | None = None
    for _ in range(nrot):
        _, ninc = cur.count("the number of incidences")
        ln, inc = cur.numbers("the incidences", ninc)
        if incidences is not None and inc != incidences:
            raise AdapterError(
                cur.path, "expected the same incidences for every anisotropy angle", ln
            )
        incidences = inc
    if not nrot or not incidences:
        raise AdapterError(cur.path, "expected at least one anisotropy angle and incidence", ln)
    aoi = np.array(incidences)
    if aoi.min() < 0 or aoi.max() >= 90 or np.any(np.diff(aoi) <= 0):
        raise AdapterError(cur.path, "incidences: expected increasing angles in [0, 90) deg", ln)
    return np.array(rot), aoi, ln


def _spectrum(
    cur: _Cursor,
) -> tuple[tuple[float, float], NDArray[np.float64], NDArray[np.float64]]:
    ln, direction = cur.numbers("the direction of the spectrum measurement (theta phi)", 2)
    cur.line("the spectrum description")
    _, nwl = cur.count("the number of spectrum wavelengths")
    rows = [
        cur.numbers("a spectrum line (wavelength [nm], coefficient [%])", 2) for _ in range(nwl)
    ]
    if not rows:
        raise AdapterError(cur.path, "expected at least one spectrum wavelength", ln)
    wl = np.array([r[1][0] for r in rows])
    coef = np.array([r[1][1] for r in rows])
    if wl.min() <= 0 or coef.min() < 0 or coef.max() > 100:
        raise AdapterError(
            cur.path,
            "spectrum: expected wavelengths > 0 nm and coefficients in [0, 100] %",
            rows[0][0],
        )
    return (direction[0], direction[1]), wl, coef


def _table(
    cur: _Cursor, nbytes: int, nblocks: int
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """All the blocks: their grid (the same for every block) and values."""
    theta: NDArray[np.float64] | None = None
    phi: NDArray[np.float64] = np.empty(0)
    values: list[NDArray[np.float64]] = []
    for b in range(nblocks):
        ln, (nth, nph) = cur.numbers("the table size (ntheta nphi)", 2)
        if nth != int(nth) or nph != int(nph) or nth < 1 or nph < 1:
            raise AdapterError(cur.path, f"table {b + 1}: expected two counts >= 1", ln)
        nth, nph = int(nth), int(nph)
        total = nblocks * nth * (nph + 1)
        if total > MAX_POINTS or 2 * total > nbytes:
            raise AdapterError(
                cur.path,
                f"the tables announce {total} values ({nblocks} x {nth} x {nph + 1}), more "
                f"than the file of {nbytes} bytes can hold (or the cap of {MAX_POINTS})",
                ln,
            )
        ln, ph = cur.numbers(f"table {b + 1}: the azimuths", nph)
        rows, lines = [], []
        for _ in range(nth):
            n, s = cur.line(f"table {b + 1}: {nth} rows of theta and {nph} values")
            rows.append(s)
            lines.append(n)
        block = parse_rows(cur.path, rows, lines, nph + 1)
        if theta is None:
            theta, phi = block[:, 0], np.array(ph)
            _check_grid(cur.path, theta, phi, ln)
        elif not (np.array_equal(block[:, 0], theta) and np.array_equal(ph, phi)):
            raise AdapterError(
                cur.path, f"table {b + 1}: expected the grid of the first table", ln
            )
        values.append(block[:, 1:])
    assert theta is not None
    return theta, phi, np.array(values)


def _check_grid(path: str | os.PathLike[str], theta: Any, phi: Any, ln: int) -> None:
    if theta.min() < 0 or theta.max() > 90 or np.any(np.diff(theta) <= 0):
        raise AdapterError(
            path,
            "table: expected increasing theta in [0, 90] deg (transmission tables, theta "
            "90..180, are not read)",
            ln,
        )
    if phi.min() < 0 or phi.max() > 360 or np.any(np.diff(phi) <= 0):
        raise AdapterError(path, "table: expected increasing azimuths in [0, 360] deg", ln)


def read_speos_table(path: str | os.PathLike[str]) -> SpeosTable:
    """Read a ``.anisotropicbsdf`` text file on its own grid.

    Raises
    ------
    AdapterError
        A binary file, transmission tables or intensity values (named, not read), a count
        that does not match its list, a non-number, a table whose grid differs from the
        first, more values announced than the file can hold, or text after ``End of
        file``; the line is named.
    """
    raw = read_bytes(path)
    text, _ = decode(raw, path)
    cur = _Cursor(path, split_lines(text))
    version, comment, description = _preamble(cur)
    _, vector = cur.numbers("the anisotropy vector", 3)
    ln = cur.i + 1
    refl, trans = _flag(cur, "the reflection/transmission flags", 2)
    if trans or not refl:
        raise AdapterError(
            path,
            f"transmission tables (flags R T = {refl} {trans}): only reflection tables are read",
            ln,
        )
    (vtype,) = _flag(cur, "the values type", 1)
    if vtype != 1:
        raise AdapterError(
            path,
            "values type 0 (proportional to the intensity, not to the BSDF): not read",
            cur.i,
        )
    rot, aoi, _ = _angles(cur)
    direction, wl, coef = _spectrum(cur)
    theta, phi, vals = _table(cur, len(raw), rot.size * aoi.size)
    _end(cur)
    return SpeosTable(
        version=version,
        anisotropy_vector=np.array(vector),
        rotation_deg=rot,
        theta_i_deg=aoi,
        theta_deg=theta,
        phi_deg=phi,
        values=vals.reshape(rot.size, aoi.size, theta.size, phi.size),
        spectrum_direction_deg=direction,
        wavelength_nm=wl,
        coefficient_pct=coef,
        comment=comment,
        description=description,
    )


def _end(cur: _Cursor) -> None:
    rest = [(i + 1, s.strip()) for i, s in enumerate(cur.lines[cur.i :], cur.i) if s.strip()]
    if not rest or rest[0][1] != "End of file":
        raise AdapterError(
            cur.path,
            "expected 'End of file' after the last table, found "
            + (repr(rest[0][1][:40]) if rest else "the end of the file"),
            rest[0][0] if rest else len(cur.lines),
        )
    if len(rest) > 1:
        raise AdapterError(cur.path, "expected nothing after 'End of file'", rest[1][0])


def hemispherical_integral(t: SpeosTable) -> NDArray[np.float64]:
    """``int f cos(theta) d omega`` of every table on its own grid [same unit as f x sr].

    Trapezoid rule in theta and in phi over the table's span (cos(theta) sin(theta)
    weighted); a table covering phi 0..360 and theta 0..90 spans the hemisphere.

    Returns
    -------
    ndarray
        ``(rotation, incidence)``.
    """
    th = np.radians(t.theta_deg)
    ph = np.radians(t.phi_deg)
    f = t.values * (np.cos(th) * np.sin(th))[:, None]
    return np.trapezoid(np.trapezoid(f, ph, axis=-1), th, axis=-1)


def _scale(path: str | os.PathLike[str], t: SpeosTable) -> tuple[float, dict[str, Any]]:
    """The factor from table values to BRDF [sr-1] per unit spectrum coefficient."""
    ref = float(t.spectrum_direction_deg[0])
    hit = np.flatnonzero(np.isclose(t.theta_i_deg, ref, atol=1e-9))
    if not hit.size:
        raise AdapterError(
            path,
            f"the spectrum is measured at theta {ref:g} deg, which is not one of the "
            f"incidences {t.theta_i_deg.tolist()}: the tables cannot be scaled",
        )
    integral = float(hemispherical_integral(t)[0, hit[0]])
    if not integral > 0:
        raise AdapterError(
            path, f"the table at incidence {ref:g} deg integrates to {integral:g}: expected > 0"
        )
    meta = {
        "rule": "BRDF = table x (coefficient / 100) / integral, with integral the "
        "hemispherical integral int f cos(theta) d omega (trapezoid on the table's grid) "
        "of the table at the spectrum's incidence",
        "reference_theta_i_deg": ref,
        "table_integral": integral,
    }
    return 1.0 / integral, meta


def _frame(t: SpeosTable, path: str | os.PathLike[str], per_unit: float) -> Any:
    """Rows in the dataset schema: one per direction, incidence, rotation, wavelength."""
    phi = t.phi_deg
    keep_phi = ~((phi >= 360.0) & np.isclose(phi[0], 0.0))  # 360 repeats 0
    v = t.values[..., keep_phi]
    ph = phi[keep_phi]
    nrot, naoi, nth, nph = v.shape
    pole = t.theta_deg == 0.0
    # the pole is one direction: its first azimuth only
    keep = np.ones((nth, nph), dtype=bool)
    keep[pole, 1:] = False
    th_g, ph_g = np.broadcast_to(t.theta_deg[:, None], (nth, nph)), np.broadcast_to(ph, (nth, nph))
    th_k, ph_k = th_g[keep], np.mod(ph_g[keep] + 180.0, 360.0)
    ph_k = np.where(th_k == 0.0, 0.0, ph_k)
    per_block = v[..., keep]  # (rot, aoi, points)
    npt = per_block.shape[-1]
    scale = t.coefficient_pct / 100.0 * per_unit
    values = per_block[None] * scale[:, None, None, None]  # (wl, rot, aoi, points)
    shape = values.shape
    optional: dict[str, Any] = {}
    if nrot > 1 or t.rotation_deg[0] != 0:
        optional["sample_rotation_deg"] = np.broadcast_to(
            t.rotation_deg[None, :, None, None], shape
        ).reshape(-1)
    return build_frame(
        sample=Path(path).stem,
        instrument=INSTRUMENT,
        source=os.path.basename(os.fspath(path)),
        quantity="brdf",
        value=values.reshape(-1),
        unit="sr-1",
        wavelength_nm=np.repeat(t.wavelength_nm, nrot * naoi * npt),
        theta_i_deg=np.broadcast_to(t.theta_i_deg[None, None, :, None], shape).reshape(-1),
        theta_r_deg=np.broadcast_to(th_k, shape).reshape(-1),
        phi_r_deg=np.broadcast_to(ph_k, shape).reshape(-1),
        **optional,
    ), {
        "pole_spread": float(np.ptp(t.values[..., pole, :], axis=-1).max(initial=0.0)),
        "phi_360_dropped": bool((~keep_phi).any()),
    }


def read_speos_bsdf(path: str | os.PathLike[str]) -> Measurement:
    """Read a Speos ``.anisotropicbsdf`` text file (reflection tables) as BRDF [sr-1].

    Parameters
    ----------
    path : str or path-like
        The file.

    Returns
    -------
    Measurement
        Quantity ``brdf`` [sr-1] at every spectrum wavelength: the table scaled so that
        its hemispherical integral at the spectrum's incidence equals the spectrum
        coefficient (see the module docstring); ``theta_r_deg`` from the normal,
        ``phi_r_deg`` = table azimuth + 180 (source at 0, specular at 180); the pole
        (theta 0) once per table and the azimuth 360 (= 0) left out.
        ``sample_rotation_deg`` when an anisotropy angle other than 0 is given. ``meta``
        holds the header, the grid, the spectrum and ``scale``.

    Raises
    ------
    AdapterError
        See :func:`read_speos_table`; also a spectrum measured at an incidence that has no
        table, or a reference table that integrates to 0.
    """
    t = read_speos_table(path)
    per_unit, scale = _scale(path, t)
    frame, extra = _frame(t, path, per_unit)
    meta: dict[str, Any] = {
        "format": INSTRUMENT,
        "version": t.version,
        "comment": t.comment,
        "description": t.description,
        "anisotropy_vector": t.anisotropy_vector.tolist(),
        "grid": {
            "rotation_deg": t.rotation_deg.tolist(),
            "theta_i_deg": t.theta_i_deg.tolist(),
            "theta_deg": t.theta_deg.tolist(),
            "phi_deg": t.phi_deg.tolist(),
            "frame": "normal reference: theta from the normal, phi = 0 at the specular "
            "direction; phi_r_deg = phi + 180",
        },
        "spectrum": {
            "theta_phi_deg": list(t.spectrum_direction_deg),
            "wavelength_nm": t.wavelength_nm.tolist(),
            "coefficient_pct": t.coefficient_pct.tolist(),
        },
        "scale": scale,
        **extra,
    }
    try:
        return Measurement(frame, meta)
    except ValueError as exc:
        raise AdapterError(path, f"invalid data: {exc}") from None


def _sniff(head: bytes) -> bool:
    return head.lstrip(b"\xef\xbb\xbf").startswith(MAGIC.encode())


FORMATS = (
    Format(
        "speos-bsdf",
        "Ansys Speos .anisotropicbsdf text (reflection tables in the normal reference, "
        "scaled by the spectrum to BRDF)",
        (".anisotropicbsdf",),
        _sniff,
        read_speos_bsdf,
        ("brdf",),
        keywords=(MAGIC.encode(),),
        examples=(
            Example(
                "speos-anisotropicbsdf/test_13_planesymmetric_brdf_speos_reference"
                ".anisotropicbsdf",
                number=("0.19080148460981583", 21),
            ),
        ),
    ),
)
