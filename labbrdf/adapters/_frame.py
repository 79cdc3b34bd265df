"""From parsed arrays to a validated :class:`~labbrdf.dataset.Measurement`.

Private helpers shared by the adapters: the schema table built from arrays without per-row
Python work (:func:`build_frame`, :func:`labels`), its validation (:func:`measurement`),
row checks that name the first offending line (:func:`check_rows`, :func:`within`), the
summaries a reader puts in its metadata (:func:`group_angles`, :func:`delta_range`) and the
vendors' Mueller sign convention (:data:`MUELLER_S1_FLIP`, :func:`mueller_convention`).
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING, Any

import numpy as np
import pandas as pd

from ..dataset import DatasetError, Measurement
from ._base import AdapterError

if TYPE_CHECKING:
    from ._numblock import Block

__all__ = [
    "MUELLER_S1_FLIP",
    "build_frame",
    "check_rows",
    "delta_range",
    "first_bad",
    "group_angles",
    "labels",
    "measurement",
    "mueller_convention",
    "within",
]


def group_angles(angles: Any, tol: float = 0.05) -> list[dict[str, float | int]]:
    """Group nearly equal angles for a summary (goniometer readings such as 64.999634).

    Parameters
    ----------
    angles : array_like
        Angles [deg]; NaN ignored.
    tol : float
        Largest gap inside one group [deg].

    Returns
    -------
    list of dict
        One ``{"nominal", "min", "max", "rows"}`` per group, ascending; ``nominal`` is the
        group mean rounded to 3 decimals. The data themselves are never rounded.
    """
    a = np.asarray(angles, dtype=float).ravel()
    a = np.sort(a[np.isfinite(a)])
    if a.size == 0:
        return []
    cuts = np.flatnonzero(np.diff(a) > tol) + 1
    out = []
    for g in np.split(a, cuts):
        out.append(
            {
                "nominal": round(float(g.mean()), 3),
                "min": float(g[0]),
                "max": float(g[-1]),
                "rows": int(g.size),
            }
        )
    return out


def build_frame(
    *,
    sample: str,
    instrument: str,
    source: str,
    quantity: Any,
    value: Any,
    unit: Any,
    wavelength_nm: Any,
    sigma: Any = np.nan,
    theta_i_deg: Any = np.nan,
    theta_r_deg: Any = np.nan,
    phi_r_deg: Any = np.nan,
    **optional: Any,
) -> pd.DataFrame:
    """Build a schema table from arrays and scalars without per-row Python work.

    Like :func:`labbrdf.dataset.make_frame`, but string columns are built as categoricals
    (a constant string, an object array, or a :class:`pandas.Categorical` made with
    :func:`labels`), which keeps files of millions of rows fast; :func:`measurement`
    validates the result (and :func:`labbrdf.dataset.validate` turns them into plain
    strings).
    """
    value = np.asarray(value, dtype=float).ravel()
    n = value.size

    def num(v: Any) -> np.ndarray:
        if np.ndim(v) == 0:
            return np.full(n, v, dtype=float)
        arr = np.asarray(v, dtype=float).ravel()
        if arr.size != n:  # pragma: no cover - programming error
            raise ValueError(f"column has {arr.size} values, expected {n}")
        return arr

    def text(v: Any) -> pd.Categorical:
        if isinstance(v, str):
            return pd.Categorical.from_codes(np.zeros(n, dtype=np.int8), categories=[v])
        if isinstance(v, pd.Categorical):
            out = v
        else:
            out = pd.Categorical(np.asarray(v, dtype=object).ravel())
        if len(out) != n:  # pragma: no cover - programming error
            raise ValueError(f"column has {len(out)} values, expected {n}")
        return out

    cols: dict[str, Any] = {
        "sample": text(sample),
        "instrument": text(instrument),
        "source": text(source),
        "quantity": text(quantity),
        "value": value,
        "sigma": num(sigma),
        "unit": text(unit),
        "wavelength_nm": num(wavelength_nm),
        "theta_i_deg": num(theta_i_deg),
        "theta_r_deg": num(theta_r_deg),
        "phi_r_deg": num(phi_r_deg),
    }
    for k, v in optional.items():
        cols[k] = text(v) if k == "channel" else num(v)
    return pd.DataFrame(cols, copy=False)


#: Mueller elements whose sign differs between the vendors' convention (Woollam, SENTECH:
#: ``M12 = M21 = -cos 2psi`` for an isotropic sample, i.e. ``S1 = Ip - Is``) and
#: :mod:`labbrdf.optics` (``S1 = Is - Ip``, ``M12 = M21 = +cos 2psi``, ``M33 = sin 2psi cos
#: Delta``, ``M34 = sin 2psi sin Delta``): ``M_optics = D M_vendor D`` with ``D = diag(1, -1,
#: 1, 1)`` flips every element with exactly one index 2.
MUELLER_S1_FLIP = frozenset(
    {"mueller_12", "mueller_21", "mueller_23", "mueller_24", "mueller_32", "mueller_42"}
)


def mueller_convention(vendor: str) -> dict[str, str]:
    """The ``meta["mueller_convention"]`` record of a reader that converted Mueller data."""
    return {
        "vendor": f"{vendor}: S1 = Ip - Is, M12 = M21 = -cos 2psi for an isotropic sample",
        "converted": "labbrdf.optics: S1 = Is - Ip, M12 = M21 = +cos 2psi, M33 = sin 2psi "
        "cos Delta, M34 = sin 2psi sin Delta; M = D M_vendor D, D = diag(1, -1, 1, 1) "
        "(M12, M21, M23, M24, M32, M42 change sign)",
    }


def labels(names: list[str], counts: list[int] | np.ndarray) -> pd.Categorical:
    """``names[k]`` repeated ``counts[k]`` times, as a categorical (no per-row strings)."""
    uniq = list(dict.fromkeys(names))
    codes = np.array([uniq.index(x) for x in names], dtype=np.int16)
    return pd.Categorical.from_codes(np.repeat(codes, counts), categories=uniq)


def measurement(
    path: str | os.PathLike[str], frame: pd.DataFrame, meta: dict[str, Any]
) -> Measurement:
    """Validate into a :class:`Measurement`; a schema problem becomes an :class:`AdapterError`."""
    if len(frame) == 0:
        raise AdapterError(path, "no data rows found")
    try:
        return Measurement(frame, meta)
    except DatasetError as exc:
        raise AdapterError(path, f"data do not fit the labbrdf schema: {exc}") from None


def first_bad(mask: np.ndarray) -> int | None:
    """Index of the first True in ``mask`` or None."""
    idx = np.flatnonzero(mask)
    return int(idx[0]) if idx.size else None


def check_rows(path: str | os.PathLike[str], block: Block, mask: np.ndarray, message: str) -> None:
    """Raise ``AdapterError(path, message, line)`` for the first row where ``mask`` is True."""
    i = first_bad(mask)
    if i is not None:
        raise AdapterError(path, message, int(block.lines[i]))


def delta_range(delta: np.ndarray) -> list[float] | None:
    """[min, max] of the Delta values as written in the file (JSON-safe), None if empty."""
    d = np.asarray(delta, dtype=float)
    if within(d):
        return [float(d.min()), float(d.max())]
    d = d[np.isfinite(d)]
    if d.size == 0:
        return None
    return [float(d.min()), float(d.max())]


def within(
    a: np.ndarray, lo: float = -np.inf, hi: float = np.inf, *, hi_open: bool = False
) -> bool:
    """True when every value of ``a`` is finite and within [lo, hi] ([lo, hi) with ``hi_open``).

    Two reductions (NaN propagates into min and max) instead of several full-length masks:
    the fast path of a range check; when it says no, the caller builds the exact row mask
    to name the first offending line. True for an empty array.
    """
    if a.size == 0:
        return True
    mn, mx = float(np.min(a)), float(np.max(a))
    if not (np.isfinite(mn) and np.isfinite(mx)):
        return False
    return mn >= lo and (mx < hi if hi_open else mx <= hi)
