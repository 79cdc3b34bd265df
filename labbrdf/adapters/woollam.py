"""J.A. Woollam ASCII data files: WVASE32 and CompleteEASE exports (``.dat``).

Layout (docs/formats.md sections 1-2, checked on every real WVASE and CompleteEASE export
the test suite reads): a header of up to five lines found by content, not by
position (:mod:`labbrdf.adapters.woollam_header`) --

1. a free-text title (may be empty: CompleteEASE 3.x),
2. ``VASEmethod[...]`` (ellipsometry) or ``RTmethod[...]`` (intensity reflectance), a list
   of ``key=value`` items and bare flags ending with a date,
3. ``Original[<file name>]`` (WVASE only),
4. optionally ``Dynamic`` (CompleteEASE 3.x kinetic series),
5. the spectral unit on its own line: ``nm``, ``eV``, ``Angstroms`` (seen in real files;
   ``A``, ``um``, ``microns`` and ``cm-1`` are accepted too but were not seen);

then one record per line, TAB separated. An untagged row is ``x AOI Psi Delta sPsi sDelta``
(CompleteEASE 3.x adds a trailing TAB; the dynamic variant adds an empty column and the time
in minutes). A tagged row starts with its data type:

===========================  ==================================================  ==============
tag                          fields after the tag                                quantity
===========================  ==================================================  ==============
``E``                        x AOI Psi Delta sPsi sDelta                         psi, delta
``AnE`` / ``Aps`` / ``Asp``  x AOI Psi Delta sPsi sDelta (channel pp / ps / sp)  psi, delta
``dpolE`` / ``dPolE``        x AOI depolarisation[%] sigma[%]                    depolarization
``uR`` / ``pR`` / ``sR``     x AOI R sigma (channel u / p / s)                   see below
``mm11`` .. ``mm44``         x AOI M M sM sM (value written twice)               mueller_ij
===========================  ==================================================  ==============

Reflectance: in an ``RTmethod`` file the ``uR``/``pR``/``sR`` rows are calibrated specular
reflectances (fractions, as in ``ta2o5_02262007_rp.dat``) and become ``reflectance`` with
theta_r = theta_i, phi_r = 180 deg. They are reflectances of one polarisation (the header's
``PolRT`` is the fixed polariser: -0.08 deg for p, 89.92 deg for s), not the unpolarised
reflectance a colour is computed from; ``meta["reflectance_kind"]`` says so, e.g.
``"single-polarisation (p) ellipsometer reflectance"``.

The angle field of such a row is not always the angle of incidence.
``ots_sio2_1mm_02262007_rp.dat`` ("Rp several angles", ``PolRT=-0.08``) has six blocks of
the same 676 wavelengths with the field at 0, 10, ..., 50 deg, and its Rp is the same in all
of them (median spread 0.3 %, no trend; thin-film fringes at the same wavelengths), whereas
Fresnel's Rp of any surface changes by tens of percent between 0 and 50 deg (Si at 1000 nm:
0.32 to 0.17), and at 0 deg a reflection ellipsometer cannot record a specular beam at all.
Its siblings ``ta2o5_02262007_rp.dat``/``_rs.dat`` (same instrument and day, same header
layout) carry one block at 45 deg whose Rp and Rs differ as Fresnel says they do at 45 deg.
So the field there is a setting that did not change the measurement: not the polariser
(fixed by ``PolRT`` in the header; turning it would mix in Rs), not a tilt (the beam would
leave the detector), but something an isotropic sample is blind to, most likely a rotation
of the sample about its normal; the file does not say which. Such rows are read with
theta_i = theta_r = phi_r = NaN (the geometry is unknown) and the column is kept in
``meta["angle_column"]`` (values, rows per value in file order, the reason). The test: the
field goes below 10 deg, or it spans at least 30 deg while the reflectance stays within 1 %.

In an ellipsometric (``VASEmethod``) file an ``uR`` row
is the reflected intensity the ellipsometer recorded on the side: CompleteEASE 3.65 writes
values of 0.65-6.9 with a constant placeholder sigma of 1 that rise and fall with wavelength
like a lamp spectrum, which is neither a reflectance fraction (> 1) nor a plausible percent
reflectance of the sample at 70 deg. Those rows are kept as ``specular_intensity`` (unit
``1``, arbitrary scale), never as reflectance.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from ..dataset import Measurement
from ._base import AdapterError, Example, Format, decode, read_bytes
from ._frame import (
    build_frame,
    check_rows,
    delta_range,
    group_angles,
    measurement,
    mueller_convention,
    within,
)
from ._numblock import Block, body_bytes, parse_block
from .woollam_header import (
    WVASE_HC_EV_NM,
    ascii_head,
    parse_method,
    read_header,
    sniff_completeease,
    sniff_wvase,
    to_nm,
)
from .woollam_rows import MUELLER, Parts, Tags, check_fields, collect, reassign_aoi
from .woollam_rt import rt_geometry

__all__ = [
    "FORMATS",
    "WVASE_HC_EV_NM",
    "parse_method",
    "read_woollam",
    "sniff_completeease",
    "sniff_wvase",
]

# ----------------------------------------------------------------------------- reader


def read_woollam(path: str | os.PathLike[str]) -> Measurement:
    """Read a WVASE32 or CompleteEASE ASCII data file.

    Parameters
    ----------
    path : str or path-like
        The ``.dat`` export.

    Returns
    -------
    Measurement
        Rows ``psi``/``delta`` [deg] (with ``channel`` ``pp``/``ps``/``sp`` for generalized
        ellipsometry), ``depolarization`` [fraction], ``reflectance`` [fraction] (RTmethod
        files, ``channel`` ``u``/``p``/``s``), ``specular_intensity`` (uR inside an
        ellipsometric file, arbitrary scale) and ``mueller_ij`` (normalised), with the
        file's sigmas, wavelength in nm, theta_i = the AOI as written (never rounded),
        theta_r = theta_i and phi_r = 180 deg (specular), except RTmethod reflectances whose
        angle field cannot be the angle of incidence (NaN, field in
        ``meta["angle_column"]``; see the module notes). Dynamic CompleteEASE data carry
        ``time_s``. Delta is wrapped into [0, 360).

    Raises
    ------
    AdapterError
        Not a Woollam export, unknown tag or unit, a row with the wrong number of fields
        or a non-number (with its line), psi or AOI outside [0, 90] deg, no data.

    Notes
    -----
    Conventions (checked on the real files, docs/formats.md 1-2):

    * Delta is Woollam's, i.e. the Nebraska convention of ``docs/conventions.md`` (Delta =
      180 deg at normal incidence, 0 < Delta < 180 deg for an absorbing substrate: the Ta
      metal file ``w2_10102006.dat`` has 68 < Delta < 159 deg). Files write it in 0..360 or
      -180..180; it is only wrapped, and the range as written is kept in
      ``meta["delta_range_in_file"]``.
    * eV is converted by lambda = 1240 eV nm / E (not E * hc, the pyElli 0.23.1 bug), with
      the 1240 WVASE itself uses (see :data:`WVASE_HC_EV_NM`), giving 245.73-1697.77 nm for
      ``wafer_2_01242007.dat`` like the nm files of the same instrument; Angstrom by /10.
    * Depolarisation (``dpolE``) is written in percent and stored as a fraction, sigma too.
    * CompleteEASE 3.x static files interleave per wavelength a Psi/Delta row, a ``dPolE``
      row and an ``uR`` row whose AOI field is 0. Such a tagged row with AOI 0 at most two
      lines after a Psi/Delta row of the same wavelength (its triplet) was measured in the
      same acquisition, so it gets that row's AOI; ``meta["aoi_reassigned"]`` counts them.
      A tagged row with AOI 0 anywhere else stays at normal incidence.
    * Rows whose value is not finite (CompleteEASE 6.x writes a whole ``uR`` block of
      ``inf``: nothing was measured) are dropped, and each drop is listed in
      ``meta["dropped_rows"]`` with tag, count and reason; never silently.
    * Mueller rows (``mm12`` ...) write the value twice and the sigma twice; the first copy
      of each is used. Woollam's Stokes convention has ``S1 = Ip - Is`` (``mm12 = -cos 2psi``
      for an isotropic sample); the values are converted to :mod:`labbrdf.optics`
      (``M12 = +cos 2psi``) by flipping M12, M21, M23, M24, M32, M42, and
      ``meta["mueller_convention"]`` says so.
    """
    meta, block = _read_block(path)
    v = block.values
    tags = Tags(block)
    dynamic = bool(meta["dynamic"])
    check_fields(path, block, tags, dynamic)
    x = v[:, 0]
    wl = to_nm(path, x, meta["spectral_unit"], block, np.ones(tags.n, dtype=bool))
    aoi = v[:, 1]
    if not within(aoi, 0.0, 90.0):
        check_rows(
            path,
            block,
            ~(np.isfinite(aoi) & (aoi >= 0) & (aoi <= 90)),
            "angle of incidence must be within [0, 90] deg",
        )
    time_s = v[:, 7] * 60.0 if dynamic else None
    aoi = reassign_aoi(tags, x, aoi, meta)
    rt = meta["method"] == "RTmethod"
    parts = Parts(path, block, tags.n)
    delta_seen = collect(parts, tags, v, rt)
    if sum(parts.counts()) == 0:
        raise AdapterError(
            path,
            "no finite data values in the file"
            + (f" (dropped: {parts.dropped})" if parts.dropped else ""),
        )
    theta = aoi
    phi = np.full(tags.n, 180.0)
    if rt:
        theta = aoi.copy()
        rt_geometry(wl, aoi, v[:, 2], tags.codes, tags.code, tags.utags, theta, phi, meta)
    frame = _frame(path, meta, parts, wl, theta, phi, time_s)
    _finish_meta(meta, tags, block, parts, delta_seen, theta, wl)
    return measurement(path, frame, meta)


def _read_block(path: str | os.PathLike[str]) -> tuple[dict[str, Any], Block]:
    """The header's meta (with source file and encoding) and the data block of a file."""
    raw = read_bytes(path)
    p = Path(path)
    if raw.isascii() and b"\x00" not in raw:
        # pure ASCII (every real export seen) decodes alike in every accepted encoding, so
        # only the header is decoded and the block is parsed from the bytes in place
        meta, offset, first = read_header(path, ascii_head(raw, 8))
        encoding, body, data, start = "utf-8", None, raw, offset
    else:
        text, encoding = decode(raw, path)
        meta, offset, first = read_header(path, text)
        body, data, start = text[offset:], body_bytes(raw, text, offset, encoding), 0
    meta = {"source_file": p.name, "encoding": encoding, **meta}
    block = parse_block(path, body, first, 8, sep="\t", tagged=True, data=data, data_start=start)
    if len(block.lines) == 0:
        raise AdapterError(path, "no data rows after the header")
    return meta, block


def _frame(
    path: str | os.PathLike[str],
    meta: dict[str, Any],
    parts: Parts,
    wl: np.ndarray,
    theta: np.ndarray,
    phi: np.ndarray,
    time_s: np.ndarray | None,
) -> pd.DataFrame:
    """The tidy frame of the collected quantities."""
    p = Path(path)
    optional: dict[str, Any] = {}
    if any(pp["channel"] and pp["count"] for pp in parts.parts):
        optional["channel"] = parts.lab("channel")
    if time_s is not None:
        optional["time_s"] = parts.take(time_s)
    sample = meta["title"] or p.stem
    software = meta.get("software", "")
    instrument = (
        "woollam-completeease" if software.startswith("CompleteEASE") else ("woollam-wvase")
    )
    return build_frame(
        sample=sample,
        instrument=instrument,
        source=p.name,
        quantity=parts.lab("quantity"),
        value=parts.num("value"),
        sigma=parts.num("sigma"),
        unit=parts.lab("unit"),
        wavelength_nm=parts.take(wl),
        theta_i_deg=parts.take(theta),
        theta_r_deg=parts.take(theta),  # a second array: the columns must not share memory
        phi_r_deg=parts.take(phi),
        **optional,
    )


def _finish_meta(
    meta: dict[str, Any],
    tags: Tags,
    block: Block,
    parts: Parts,
    delta_seen: list[np.ndarray],
    theta: np.ndarray,
    wl: np.ndarray,
) -> None:
    """Record in ``meta`` what was read: variant, tags, drops and conventions."""
    if meta["dynamic"]:
        meta["time_unit_in_file"] = "min"
    meta["variant"] = _variant(meta, "" in tags.code)
    counts_per_tag = np.bincount(tags.codes, minlength=len(tags.utags))
    meta["tags"] = {
        t or "(untagged)": int(counts_per_tag[tags.code[t]]) for t in sorted(tags.utags)
    }
    meta["data_lines"] = int(tags.n)
    meta["blank_lines_skipped"] = block.blank_lines
    meta["dropped_rows"] = parts.dropped
    if any(t in MUELLER for t in tags.utags):
        meta["mueller_convention"] = mueller_convention("Woollam")
    meta["delta_convention"] = "Nebraska (Woollam): Delta = 180 deg at normal incidence"
    meta["delta_range_in_file"] = delta_range(np.concatenate(delta_seen)) if delta_seen else None
    meta["delta_range"] = "[0, 360)"
    meta["angles_deg"] = group_angles(theta)
    meta["wavelength_nm"] = [float(np.min(wl)), float(np.max(wl))]


def _variant(meta: dict[str, Any], untagged_rows: bool) -> str:
    sw = meta.get("software", "")
    if sw.startswith("CompleteEASE"):
        if meta["dynamic"]:
            return "completeease-dynamic"
        if untagged_rows:
            return "completeease-interleaved"
        return "completeease-tagged"
    return "wvase-rt" if meta["method"] == "RTmethod" else "wvase"


FORMATS: tuple[Format, ...] = (
    Format(
        name="woollam-wvase",
        description="J.A. Woollam WVASE32 ASCII data (VASEmethod/RTmethod), psi/Delta, "
        "generalized ellipsometry, depolarization, reflectance, Mueller matrix",
        extensions=(".dat",),
        sniff=sniff_wvase,
        keywords=(b"VASEmethod[", b"RTmethod[", b"WVASE"),
        read=read_woollam,
        quantities=(
            "psi",
            "delta",
            "depolarization",
            "reflectance",
            "specular_intensity",
            *MUELLER.values(),
        ),
        examples=(
            Example(
                "woollam-wvase-ascii/w2_10102006.dat", number=("26.418438", 5), rows_per_line=2
            ),
            Example("woollam-wvase-ascii/wafer_2_01242007.dat", rows_per_line=2),
            Example("woollam-wvase-ascii/ta2o5_02262007_rp.dat", rows_per_line=2),
            Example("woollam-wvase-ascii/wvase_example.dat", rows_per_line=2),
            Example("woollam-wvase-ascii/w1_al2o3_20081120_anisotropy.dat", rows_per_line=2),
        ),
    ),
    Format(
        name="woollam-completeease",
        description="J.A. Woollam CompleteEASE ASCII export (3.x static/dynamic, 6.x tagged)",
        extensions=(".dat",),
        sniff=sniff_completeease,
        keywords=(b"VASEmethod[", b"CompleteEASE"),
        read=read_woollam,
        quantities=("psi", "delta", "depolarization", "specular_intensity"),
        examples=(
            Example("woollam-completeease-ascii/complete_ease_example.dat", rows_per_line=2),
            Example(
                "woollam-completeease-ascii/Woolam_staticTest.dat",
                number=("21.4553", 4),
                rows_per_line=2,
            ),
            Example("woollam-completeease-ascii/Woolam_kineticTest.dat", rows_per_line=2),
        ),
    ),
)
