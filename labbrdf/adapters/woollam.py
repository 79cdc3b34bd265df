"""J.A. Woollam ASCII data files: WVASE32 and CompleteEASE exports (``.dat``).

Layout (docs/formats.md sections 1-2, checked on every real WVASE and CompleteEASE export
the test suite reads): a header of up to five lines found by content, not by
position --

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
import re
from datetime import datetime
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from ..dataset import Measurement, wrap_delta
from ._base import DECIMAL, AdapterError, Example, Format, decode, read_bytes
from ._frame import (
    MUELLER_S1_FLIP,
    build_frame,
    check_rows,
    delta_range,
    group_angles,
    labels,
    measurement,
    mueller_convention,
    within,
)
from ._numblock import Block, body_bytes, head_lines, parse_block

__all__ = [
    "FORMATS",
    "WVASE_HC_EV_NM",
    "parse_method",
    "read_woollam",
    "sniff_completeease",
    "sniff_wvase",
]

_METHOD = re.compile(r"^\s*(VASE|RT)method\[(.*)\]\s*$")
_ORIGINAL = re.compile(r"^\s*Original\[(.*)\]\s*$")

#: spectral unit line -> (canonical name, conversion to nm)
_UNITS: dict[str, str] = {
    "nm": "nm",
    "ev": "eV",
    "angstroms": "Angstrom",
    "angstrom": "Angstrom",
    "a": "Angstrom",
    "um": "um",
    "microns": "um",
    "micrometers": "um",
    "cm-1": "cm-1",
    "1/cm": "cm-1",
}

#: The h*c [eV nm] WVASE32 uses to write an eV axis: lambda[nm] = 1240 / E[eV]. Inverting
#: the software's own conversion gives back the monochromator's wavelengths: the eV grid of
#: ``wafer_2_01242007.dat`` times 1240 reproduces the nm grid of ``w2_10102006.dat`` (same
#: instrument and spectral grid) to 6e-7 relative, the 7 digits printed; CODATA
#: hc = 1239.84198 eV nm would be 1.3e-4 (0.2 nm at 1698 nm) off.
WVASE_HC_EV_NM = 1240.0

_PSI_DELTA = {"": "", "E": "", "AnE": "pp", "Aps": "ps", "Asp": "sp"}
_DEPOL = {"dpolE", "dPolE"}
_REFL = {"uR": "u", "pR": "p", "sR": "s"}
_MM = {f"mm{i}{j}": f"mueller_{i}{j}" for i in range(1, 5) for j in range(1, 5)}
_NFIELDS = {
    **{t: 6 for t in _PSI_DELTA},
    **{t: 4 for t in _DEPOL},
    **{t: 4 for t in _REFL},
    **{t: 6 for t in _MM},
}
_SUPPORTED = sorted(set(_NFIELDS) - {""})
_DATE_FORMATS = ("%a %b %d %H:%M:%S %Y",)


# ----------------------------------------------------------------------------- sniffing


def _method_line(head: bytes) -> str | None:
    try:
        text = head.decode("latin-1")
        for line in text.splitlines()[:4]:
            if _METHOD.match(line) or line.lstrip().startswith(("VASEmethod[", "RTmethod[")):
                return line
    except Exception:  # a sniffer never raises
        return None
    return None


def sniff_wvase(head: bytes) -> bool:
    """True for a WVASE32 export: a ``VASEmethod[``/``RTmethod[`` line without CompleteEASE."""
    line = _method_line(head)
    return line is not None and "CompleteEASE" not in line


def sniff_completeease(head: bytes) -> bool:
    """True for a CompleteEASE export: the method line names ``CompleteEASE=``."""
    line = _method_line(head)
    return line is not None and "CompleteEASE" in line


# ----------------------------------------------------------------------------- header


def _number_or_text(v: str) -> float | int | str:
    if DECIMAL.fullmatch(v) is None:
        return v
    try:
        f = float(v)
    except ValueError:
        return v
    if not np.isfinite(f):
        return v
    return int(f) if re.fullmatch(r"[+-]?[0-9]+", v) else f


def parse_method(line: str) -> dict[str, Any]:
    """Parse a ``VASEmethod[...]`` / ``RTmethod[...]`` line.

    Parameters
    ----------
    line : str
        The method line.

    Returns
    -------
    dict
        ``method`` (``"VASEmethod"`` or ``"RTmethod"``), ``settings`` (``key=value`` items,
        numbers as numbers; keys kept verbatim, e.g. ``"Acq. Parameters"``), ``flags`` (bare
        items such as ``Isotropic``), ``date`` (the date item as written) and ``datetime``
        (ISO 8601, when the date parses), ``simulated`` (True for WVASE's model-generated
        ``Simulation for ...`` / ``Normal Fit Generation`` data) and ``software``.

    Raises
    ------
    ValueError
        The line is not a method line.
    """
    m = _METHOD.match(line)
    if m is None:
        raise ValueError(f"not a VASEmethod[...] / RTmethod[...] line: {line!r}")
    out: dict[str, Any] = {"method": f"{m.group(1)}method", "settings": {}, "flags": []}
    simulated = False
    for item in (s.strip() for s in m.group(2).split(",")):
        if not item:
            continue
        if "=" in item:
            k, v = (s.strip() for s in item.split("=", 1))
            out["settings"][k] = _number_or_text(v)
            continue
        for fmt in _DATE_FORMATS:
            try:
                out["datetime"] = datetime.strptime(item, fmt).isoformat()
                out["date"] = item
                break
            except ValueError:
                continue
        else:
            if item.startswith(("Simulation for", "Normal Fit Generation")):
                simulated = True
            out["flags"].append(item)
    out["simulated"] = simulated
    st = out["settings"]
    if "CompleteEASE" in st:
        out["software"] = f"CompleteEASE {st['CompleteEASE']}"
    elif "WVASE" in st:
        out["software"] = f"WVASE32 {st['WVASE']}"
    return out


def _header(path: str | os.PathLike[str], text: str) -> tuple[dict[str, Any], int, int]:
    """Find the header lines by content; return meta, the body's offset and first line."""
    lines, _ = head_lines(text, 7)
    meta: dict[str, Any] = {}
    i = 0
    # title: every line before the method line (normally one, may be empty)
    mi = next((k for k, s in enumerate(lines[:3]) if _METHOD.match(s)), None)
    if mi is None:
        raise AdapterError(
            path,
            "no VASEmethod[...] or RTmethod[...] line in the first 3 lines: not a Woollam "
            "WVASE32/CompleteEASE ASCII export",
            min(len(lines), 2) or 1,
        )
    if mi > 2 or (mi == 2 and lines[0].strip()):
        raise AdapterError(path, "expected at most one title line before the method line", mi)
    meta["title"] = lines[mi - 1].strip() if mi >= 1 else ""
    meta.update(parse_method(lines[mi]))
    i = mi + 1
    if i < len(lines) and _ORIGINAL.match(lines[i]):
        meta["original_file"] = _ORIGINAL.match(lines[i]).group(1)  # type: ignore[union-attr]
        i += 1
    meta["dynamic"] = False
    if i < len(lines) and lines[i].strip().lower() == "dynamic":
        meta["dynamic"] = True
        i += 1
    if i >= len(lines):
        raise AdapterError(path, "file ends before the spectral unit line (nm, eV, Angstroms)")
    unit = lines[i].strip()
    if unit.lower() not in _UNITS:
        raise AdapterError(
            path,
            f"expected the spectral unit line (nm, eV or Angstroms), found {unit[:40]!r}",
            i + 1,
        )
    meta["spectral_unit"] = _UNITS[unit.lower()]
    meta["spectral_unit_as_written"] = unit
    if meta["spectral_unit"] == "eV":
        meta["ev_to_nm"] = "lambda[nm] = 1240 / E[eV] (the constant WVASE writes eV with)"
    _, offset = head_lines(text, i + 1)
    return meta, offset, i + 2


def _to_nm(
    path: str | os.PathLike[str], x: np.ndarray, unit: str, block: Block, rows: np.ndarray
) -> np.ndarray:
    if not (within(x, 0.0, np.inf) and x.min() > 0):
        check_rows(
            path,
            block,
            rows & ~(np.isfinite(x) & (x > 0)),
            f"spectral value must be a finite number > 0 [{unit}]",
        )
    with np.errstate(divide="ignore", invalid="ignore"):
        if unit == "nm":
            return x
        if unit == "eV":
            return WVASE_HC_EV_NM / x
        if unit == "Angstrom":
            return x / 10.0
        if unit == "um":
            return x * 1000.0
        if unit == "cm-1":
            return 1e7 / x
    raise AssertionError(unit)  # pragma: no cover


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
    tags = _Tags(block)
    dynamic = bool(meta["dynamic"])
    _check_fields(path, block, tags, dynamic)
    x = v[:, 0]
    wl = _to_nm(path, x, meta["spectral_unit"], block, np.ones(tags.n, dtype=bool))
    aoi = v[:, 1]
    if not within(aoi, 0.0, 90.0):
        check_rows(
            path,
            block,
            ~(np.isfinite(aoi) & (aoi >= 0) & (aoi <= 90)),
            "angle of incidence must be within [0, 90] deg",
        )
    time_s = v[:, 7] * 60.0 if dynamic else None
    aoi = _reassign_aoi(tags, x, aoi, meta)
    rt = meta["method"] == "RTmethod"
    parts = _Parts(path, block, tags.n)
    delta_seen = _collect(parts, tags, v, rt)
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
        _rt_geometry(wl, aoi, v[:, 2], tags.codes, tags.code, tags.utags, theta, phi, meta)
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
        meta, offset, first = _header(path, _ascii_head(raw, 8))
        encoding, body, data, start = "utf-8", None, raw, offset
    else:
        text, encoding = decode(raw, path)
        meta, offset, first = _header(path, text)
        body, data, start = text[offset:], body_bytes(raw, text, offset, encoding), 0
    meta = {"source_file": p.name, "encoding": encoding, **meta}
    block = parse_block(path, body, first, 8, sep="\t", tagged=True, data=data, data_start=start)
    if len(block.lines) == 0:
        raise AdapterError(path, "no data rows after the header")
    return meta, block


class _Tags:
    """The row tags of a block as small integer codes.

    Comparisons on 10^6 object strings are slow, so each line's tag is a code into
    ``utags`` (the distinct tags) and ``code`` maps a tag to its code.
    """

    def __init__(self, block: Block) -> None:
        assert block.tags is not None
        if block.tag_codes is not None:
            tcodes, utags = block.tag_codes
        else:
            tcodes, tuniq = pd.factorize(block.tags)
            utags = [str(t) for t in tuniq]
        self.codes = tcodes
        self.utags = utags
        self.code = {t: k for k, t in enumerate(utags)}
        self.n = len(tcodes)

    def mask(self, *names: str) -> np.ndarray:
        """The lines whose tag is one of ``names``."""
        ks = [self.code[t] for t in names if t in self.code]
        if len(ks) == len(self.utags):
            return np.ones(self.n, dtype=bool)
        return np.isin(self.codes, ks) if ks else np.zeros(self.n, dtype=bool)


def _check_fields(path: str | os.PathLike[str], block: Block, tags: _Tags, dynamic: bool) -> None:
    """Refuse an unknown tag and a line with missing or extra fields for its tag."""
    v = block.values
    unknown = [t for t in tags.utags if t not in _NFIELDS]
    if unknown:
        check_rows(
            path,
            block,
            tags.mask(unknown[0]),
            f"unsupported data tag {unknown[0]!r}; supported are {_SUPPORTED} "
            "and untagged Psi/Delta rows",
        )
    # required fields: all of the first nf must be present; an empty field is never a
    # value: a missing number is an error, only a written inf/NaN counts as "not
    # measured" (dropped and reported below)
    missing, extra = _field_counts(v, tags.codes, [_NFIELDS[t] for t in tags.utags])
    check_rows(
        path,
        block,
        missing,
        "missing field(s): expected x, AOI and the values of this row type "
        "(6 fields for Psi/Delta, 4 for dpolE/uR/pR/sR)",
    )
    if dynamic:
        # untagged dynamic rows: x AOI Psi Delta sPsi sDelta <empty> time_min
        untagged = tags.mask("")
        check_rows(
            path,
            block,
            untagged & np.isnan(v[:, 7]),
            "dynamic data: expected the time [min] in field 8",
        )
        check_rows(
            path,
            block,
            untagged & np.isinf(v[:, 7]),
            "dynamic data: the time [min] in field 8 must be finite",
        )
        extra[untagged] = ~np.isnan(v[untagged, _NFIELDS[""] : 7]).all(axis=1)
    check_rows(
        path,
        block,
        extra,
        "too many fields for this row type (6 for Psi/Delta, 4 for dpolE/uR/pR/sR)",
    )


def _reassign_aoi(tags: _Tags, x: np.ndarray, aoi: np.ndarray, meta: dict[str, Any]) -> np.ndarray:
    """CompleteEASE 3.x: tagged rows with AOI 0 after a Psi/Delta row of the same x.

    They take that row's AOI (see :func:`read_woollam`); ``meta["aoi_reassigned"]``
    counts them.
    """
    n = tags.n
    reassigned = 0
    only_pd = all(t in _PSI_DELTA for t in tags.utags)  # then there is nothing to reassign
    is_pd = tags.mask(*_PSI_DELTA) if not only_pd else None
    zero = ~is_pd & (aoi == 0) if is_pd is not None else None
    if zero is not None and is_pd is not None and zero.any() and is_pd.any():
        last_pd = np.where(is_pd, np.arange(n), -1)
        last_pd = np.maximum.accumulate(last_pd)
        ok = zero & (last_pd >= 0)
        j = np.where(ok, last_pd, 0)
        same = ok & (x[j] == x) & (np.arange(n) - j <= 2)
        aoi = aoi.copy()
        aoi[same] = aoi[j[same]]
        reassigned = int(same.sum())
    if reassigned:
        meta["aoi_reassigned"] = {
            "rows": reassigned,
            "reason": "tagged rows written with AOI 0 right after the Psi/Delta row of the "
            "same wavelength (CompleteEASE 3.x interleaved export) take that row's AOI",
        }
    return aoi


class _Parts:
    """The quantities of a file collected one tag at a time, with the rows dropped."""

    def __init__(self, path: str | os.PathLike[str], block: Block, n: int) -> None:
        self.path, self.block, self.n = path, block, n
        self.parts: list[dict[str, Any]] = []
        self.dropped: list[dict[str, Any]] = []

    def add(
        self,
        rows: np.ndarray | None,
        quantity: str,
        value: np.ndarray,
        sigma: np.ndarray,
        unit_: str,
        channel: str,
        tag: str,
    ) -> None:
        """Collect one quantity of the rows ``rows`` (full-length mask, None: every row).

        Non-finite values are dropped and reported in ``dropped``.
        """
        n = self.n
        if not within(sigma, 0.0, np.inf):  # NaN (no sigma) is fine, inf or < 0 is not
            bad_sigma = np.zeros(n, dtype=bool)
            bad_sigma[slice(None) if rows is None else rows] = ~np.isnan(sigma) & ~(
                np.isfinite(sigma) & (sigma >= 0)
            )
            check_rows(self.path, self.block, bad_sigma, "sigma must be a finite number >= 0")
        r = None if rows is None else np.flatnonzero(rows)
        if not within(value):
            good = np.isfinite(value)
            nbad = int((~good).sum())
            kind = "inf" if np.isinf(value[~good]).all() else "NaN/inf"
            self.dropped.append(
                {
                    "tag": tag or "(untagged)",
                    "quantity": quantity,
                    "count": nbad,
                    "reason": f"value is {kind}: not measured",
                }
            )
            r = (np.arange(n) if r is None else r)[good]
            value, sigma = value[good], sigma[good]
        self.parts.append(
            {
                "r": r,
                "count": n if r is None else len(r),
                "quantity": quantity,
                "value": value,
                "sigma": sigma,
                "unit": unit_,
                "channel": channel,
            }
        )

    def counts(self) -> list[int]:
        return [pp["count"] for pp in self.parts]

    # rows come grouped by tag and quantity (file order within each group)
    def take(self, a: np.ndarray) -> np.ndarray:
        """The per-line array ``a`` at the rows of every part, parts one after another."""
        return np.concatenate([a if pp["r"] is None else a[pp["r"]] for pp in self.parts])

    def num(self, key: str) -> np.ndarray:
        return np.concatenate([pp[key] for pp in self.parts])

    def lab(self, key: str) -> pd.Categorical:
        return labels([pp[key] for pp in self.parts], self.counts())


def _collect(parts: _Parts, tags: _Tags, v: np.ndarray, rt: bool) -> list[np.ndarray]:
    """Add the quantities of every tag to ``parts``; return the Delta columns as written."""
    path, block = parts.path, parts.block
    delta_seen: list[np.ndarray] = []
    for t in sorted(tags.utags):
        rows = None if len(tags.utags) == 1 else tags.codes == tags.code[t]

        def col(j: int, rows: np.ndarray | None = rows) -> np.ndarray:
            return v[:, j] if rows is None else v[rows, j]

        if t in _PSI_DELTA:
            psi, delta = col(2), col(3)
            psi_ok = within(psi, 0.0, 90.0)
            if not psi_ok:
                check_rows(
                    path,
                    block,
                    (True if rows is None else rows)
                    & np.isfinite(v[:, 2])
                    & ((v[:, 2] < 0) | (v[:, 2] > 90)),
                    "psi must be within [0, 90] deg",
                )
            delta_seen.append(delta)
            ch = _PSI_DELTA[t]
            # psi and delta of one line share its fate: both kept or both dropped
            if psi_ok and within(delta):
                psi_v, delta_v = psi, _wrap(delta)
            else:
                both = np.isfinite(psi) & np.isfinite(delta)
                psi_v = np.where(both, psi, np.nan)
                delta_v = np.where(both, wrap_delta(np.where(both, delta, 0.0)), np.nan)
            parts.add(rows, "psi", psi_v, col(4), "deg", ch, t)
            parts.add(rows, "delta", delta_v, col(5), "deg", ch, t)
        elif t in _DEPOL:
            parts.add(rows, "depolarization", col(2) / 100.0, col(3) / 100.0, "1", "", t)
        elif t in _REFL:
            q = "reflectance" if rt else "specular_intensity"
            parts.add(rows, q, col(2), col(3), "1", _REFL[t], t)
        else:  # Mueller, converted to the labbrdf.optics convention
            sign = -1.0 if _MM[t] in MUELLER_S1_FLIP else 1.0
            parts.add(rows, _MM[t], sign * col(2), col(4), "1", "", t)
    return delta_seen


def _frame(
    path: str | os.PathLike[str],
    meta: dict[str, Any],
    parts: _Parts,
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
    tags: _Tags,
    block: Block,
    parts: _Parts,
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
    if any(t in _MM for t in tags.utags):
        meta["mueller_convention"] = mueller_convention("Woollam")
    meta["delta_convention"] = "Nebraska (Woollam): Delta = 180 deg at normal incidence"
    meta["delta_range_in_file"] = delta_range(np.concatenate(delta_seen)) if delta_seen else None
    meta["delta_range"] = "[0, 360)"
    meta["angles_deg"] = group_angles(theta)
    meta["wavelength_nm"] = [float(np.min(wl)), float(np.max(wl))]


#: Below this angle of incidence a reflection ellipsometer cannot record a specular
#: reflectance: source and detector arms would overlap (WVASE's own convention for angle 0
#: is normal incidence in transmission).
_MIN_REFLECTION_AOI_DEG = 10.0
#: A reflectance that stays within this relative spread (median over wavelengths) while the
#: angle column spans at least :data:`_FLAT_SPAN_DEG` cannot be a function of the angle of
#: incidence: Fresnel's Rp changes by more over such a span (Si at 1000 nm: 0.32 at 0 deg,
#: 0.17 at 50 deg; even aluminium changes by several percent between 0 and 50 deg).
_FLAT_RTOL = 0.01
_FLAT_SPAN_DEG = 30.0
_REFL_KIND = {"p": "single-polarisation (p)", "s": "single-polarisation (s)", "u": "unpolarised"}


def _angle_column_not_aoi(wl: np.ndarray, ang: np.ndarray, val: np.ndarray) -> str | None:
    """Why the angle column of reflectance rows cannot be their angle of incidence, or None."""
    reasons = []
    if ang.min() < _MIN_REFLECTION_AOI_DEG:
        reasons.append(
            f"it reaches {ang.min():g} deg, where a reflection ellipsometer cannot measure a "
            "specular reflectance"
        )
    u = np.unique(ang)
    if u.size >= 2 and u[-1] - u[0] >= _FLAT_SPAN_DEG:
        table = (
            pd.DataFrame({"wl": wl, "a": ang, "v": val})
            .pivot_table(index="wl", columns="a", values="v", aggfunc="mean")
            .dropna()
        )
        if len(table):
            spread = (table.max(axis=1) - table.min(axis=1)) / table.abs().mean(axis=1)
            med = float(np.median(spread))
            if med < _FLAT_RTOL:
                reasons.append(
                    f"the reflectance at one wavelength changes by {100 * med:.2g} % (median) "
                    f"over {u[0]:g}-{u[-1]:g} deg, where Fresnel reflectance would change by "
                    "far more"
                )
    return "; ".join(reasons) or None


def _rt_geometry(
    wl: np.ndarray,
    aoi: np.ndarray,
    value: np.ndarray,
    tcodes: np.ndarray,
    code: dict[str, int],
    utags: list[str],
    theta: np.ndarray,
    phi: np.ndarray,
    meta: dict[str, Any],
) -> None:
    """Geometry and kind of the reflectance rows of an ``RTmethod`` file (in place).

    Where the angle column cannot be the angle of incidence (see :func:`read_woollam`),
    ``theta`` and ``phi`` become NaN for those rows and the column goes to
    ``meta["angle_column"]``. ``meta["reflectance_kind"]`` says which polarisation.
    """
    tags = [t for t in sorted(utags) if t in _REFL]
    if not tags:
        return
    meta["reflectance_kind"] = (
        "; ".join(_REFL_KIND[_REFL[t]] for t in tags) + " ellipsometer reflectance"
    )
    flagged = np.zeros(aoi.size, dtype=bool)
    reasons = []
    for t in tags:
        rows = tcodes == code[t]
        ok = rows & np.isfinite(value)
        why = _angle_column_not_aoi(wl[ok], aoi[ok], value[ok]) if ok.any() else None
        if why is not None:
            flagged |= rows
            reasons.append(f"{t}: {why}")
    if not flagged.any():
        return
    theta[flagged] = np.nan
    phi[flagged] = np.nan
    a = aoi[flagged]
    vals, counts = np.unique(a, return_counts=True)
    meta["angle_column"] = {
        "values_deg": [float(x) for x in vals],
        "rows_per_value": [int(c) for c in counts],
        "is_angle_of_incidence": False,
        "reason": "; ".join(reasons),
        "meaning": "a per-block setting (written in the AOI field) that did not change the "
        "measured reflectance, e.g. a sample rotation about its normal; the file does not "
        "say which, so the angle of incidence is unknown (NaN) and the rows are kept in "
        "file order, one block per value",
    }


def _ascii_head(raw: bytes, nlines: int) -> str:
    """The first ``nlines`` LF-ended lines of an ASCII file, decoded (all of it if shorter).

    Ends right after an LF, so a CRLF is never split; lone-CR files give at least as many
    lines. Enough for :func:`_header`, which looks at the first 7 lines.
    """
    pos = -1
    for _ in range(nlines):
        pos = raw.find(b"\n", pos + 1)
        if pos < 0:
            return raw.decode("ascii")
    return raw[: pos + 1].decode("ascii")


def _field_counts(
    v: np.ndarray, tcodes: np.ndarray, nfields: list[int]
) -> tuple[np.ndarray, np.ndarray]:
    """Rows lacking one of their first ``nf`` fields, and rows with a field beyond them.

    ``nfields[k]`` is the field count of tag code ``k``. Works per distinct field count,
    so a file of one row type costs two passes over its values.
    """
    n = v.shape[0]
    nf_u = np.asarray(nfields, dtype=np.int64)
    missing = np.zeros(n, dtype=bool)
    extra = np.zeros(n, dtype=bool)
    for k in np.unique(nf_u):
        ks = np.flatnonzero(nf_u == k)
        sel = slice(None) if ks.size == nf_u.size else np.isin(tcodes, ks)
        sub = v[sel]
        # fast path: a sum is NaN when a field is (or when inf meets -inf: then look closer)
        with np.errstate(invalid="ignore"):
            fields_nan = np.isnan(sub[:, :k].sum())
        if fields_nan:
            missing[sel] = np.isnan(sub[:, :k]).any(axis=1)
        if not np.isnan(sub[:, k:]).all():
            extra[sel] = ~np.isnan(sub[:, k:]).all(axis=1)
    return missing, extra


def _wrap(delta: np.ndarray) -> np.ndarray:
    """:func:`~labbrdf.dataset.wrap_delta` of finite values, without the division.

    Notes
    -----
    For -360 <= d < 0, ``np.mod(d, 360)`` is the single rounding of d + 360 (fmod is exact
    there) and for 0 <= d < 360 it is d (with -0 made +0), so adding 360 where d < 0 gives
    the same bits; other values go through ``wrap_delta``.
    """
    if delta.size == 0 or not (delta.min() >= -360.0 and delta.max() < 360.0):
        return wrap_delta(delta)
    out = delta + 0.0  # a copy, with -0.0 -> +0.0 as np.mod gives
    np.add(out, 360.0, out=out, where=out < 0)
    if out.max() >= 360.0:  # d + 360 rounds to 360 for tiny negative d
        out = np.where(out >= 360.0, out - 360.0, out)
    return out


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
            *_MM.values(),
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
