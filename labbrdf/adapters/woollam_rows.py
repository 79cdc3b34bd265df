"""The data rows of a J.A. Woollam ASCII export: tags, fields and the quantities they hold.

The layout (the table of tags) is described in :mod:`labbrdf.adapters.woollam`. Here: the
row tags as integer codes (:class:`Tags`), the check of each row's fields against its tag
(:func:`check_fields`), the angle of incidence that CompleteEASE 3.x leaves at 0 on the rows
interleaved with a Psi/Delta row (:func:`reassign_aoi`), and the quantities of every tag
collected with the rows dropped as not measured (:class:`Parts`, :func:`collect`): Psi and
Delta (Delta wrapped into [0, 360)), depolarisation, reflectance and the Mueller elements in
the :mod:`labbrdf.optics` sign convention.
"""

from __future__ import annotations

import os
from typing import Any

import numpy as np
import pandas as pd

from ..dataset import wrap_delta
from ._frame import MUELLER_S1_FLIP, check_rows, labels, within
from ._numblock import Block

__all__ = [
    "DEPOL",
    "MUELLER",
    "PSI_DELTA",
    "REFL",
    "Parts",
    "Tags",
    "check_fields",
    "collect",
    "reassign_aoi",
    "wrap_finite",
]

#: Psi/Delta tags -> channel (untagged and ``E``: the ordinary pp channel, written "")
PSI_DELTA = {"": "", "E": "", "AnE": "pp", "Aps": "ps", "Asp": "sp"}
#: depolarisation tags (WVASE32 and CompleteEASE spell them differently)
DEPOL = {"dpolE", "dPolE"}
#: reflectance / intensity tags -> channel
REFL = {"uR": "u", "pR": "p", "sR": "s"}
#: Mueller tags -> quantity
MUELLER = {f"mm{i}{j}": f"mueller_{i}{j}" for i in range(1, 5) for j in range(1, 5)}
_NFIELDS = {
    **{t: 6 for t in PSI_DELTA},
    **{t: 4 for t in DEPOL},
    **{t: 4 for t in REFL},
    **{t: 6 for t in MUELLER},
}
_SUPPORTED = sorted(set(_NFIELDS) - {""})


class Tags:
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


def check_fields(path: str | os.PathLike[str], block: Block, tags: Tags, dynamic: bool) -> None:
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


def reassign_aoi(tags: Tags, x: np.ndarray, aoi: np.ndarray, meta: dict[str, Any]) -> np.ndarray:
    """CompleteEASE 3.x: tagged rows with AOI 0 after a Psi/Delta row of the same x.

    They take that row's AOI (see :func:`read_woollam`); ``meta["aoi_reassigned"]``
    counts them.
    """
    n = tags.n
    reassigned = 0
    only_pd = all(t in PSI_DELTA for t in tags.utags)  # then there is nothing to reassign
    is_pd = tags.mask(*PSI_DELTA) if not only_pd else None
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


class Parts:
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
        """Rows per part, in order."""
        return [pp["count"] for pp in self.parts]

    # rows come grouped by tag and quantity (file order within each group)
    def take(self, a: np.ndarray) -> np.ndarray:
        """The per-line array ``a`` at the rows of every part, parts one after another."""
        return np.concatenate([a if pp["r"] is None else a[pp["r"]] for pp in self.parts])

    def num(self, key: str) -> np.ndarray:
        """The numeric column ``key`` (``value``, ``sigma``) of every part, one after another."""
        return np.concatenate([pp[key] for pp in self.parts])

    def lab(self, key: str) -> pd.Categorical:
        """The text column ``key`` (``quantity``, ``unit``, ``channel``) as a categorical."""
        return labels([pp[key] for pp in self.parts], self.counts())


def collect(parts: Parts, tags: Tags, v: np.ndarray, rt: bool) -> list[np.ndarray]:
    """Add the quantities of every tag to ``parts``; return the Delta columns as written."""
    path, block = parts.path, parts.block
    delta_seen: list[np.ndarray] = []
    for t in sorted(tags.utags):
        rows = None if len(tags.utags) == 1 else tags.codes == tags.code[t]

        def col(j: int, rows: np.ndarray | None = rows) -> np.ndarray:
            return v[:, j] if rows is None else v[rows, j]

        if t in PSI_DELTA:
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
            ch = PSI_DELTA[t]
            # psi and delta of one line share its fate: both kept or both dropped
            if psi_ok and within(delta):
                psi_v, delta_v = psi, wrap_finite(delta)
            else:
                both = np.isfinite(psi) & np.isfinite(delta)
                psi_v = np.where(both, psi, np.nan)
                delta_v = np.where(both, wrap_delta(np.where(both, delta, 0.0)), np.nan)
            parts.add(rows, "psi", psi_v, col(4), "deg", ch, t)
            parts.add(rows, "delta", delta_v, col(5), "deg", ch, t)
        elif t in DEPOL:
            parts.add(rows, "depolarization", col(2) / 100.0, col(3) / 100.0, "1", "", t)
        elif t in REFL:
            q = "reflectance" if rt else "specular_intensity"
            parts.add(rows, q, col(2), col(3), "1", REFL[t], t)
        else:  # Mueller, converted to the labbrdf.optics convention
            sign = -1.0 if MUELLER[t] in MUELLER_S1_FLIP else 1.0
            parts.add(rows, MUELLER[t], sign * col(2), col(4), "1", "", t)
    return delta_seen


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


def wrap_finite(delta: np.ndarray) -> np.ndarray:
    """``labbrdf.dataset.wrap_delta`` of finite values, without the division.

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
