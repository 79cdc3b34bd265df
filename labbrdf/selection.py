"""Row selection on a dataset, as the command line's selection options do it.

The ``--wavelength-range``, ``--theta-i-range``, ``--theta-r``, ``--quantity`` and
``--sample`` options, as one function.

Ranges are closed intervals ``MIN:MAX`` (either end may be left open, ``400:`` or ``:700``);
a single number selects that value to 1e-6. Selection never changes a value; a selection
that keeps no row raises :class:`SelectionError` saying what the data hold.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd

from .dataset import Measurement

__all__ = ["Range", "SelectionError", "parse_range", "select"]

_EXACT = 1e-6


class SelectionError(ValueError):
    """A selection that cannot be parsed or keeps no row."""


@dataclass(frozen=True)
class Range:
    """A closed interval ``[lo, hi]``; infinite ends are open."""

    lo: float = -math.inf
    hi: float = math.inf

    def mask(self, values: pd.Series) -> np.ndarray:
        """True where ``values`` lie in the interval (NaN never does)."""
        v = values.to_numpy(dtype=float)
        with np.errstate(invalid="ignore"):
            return (v >= self.lo) & (v <= self.hi)

    def __str__(self) -> str:
        lo = "" if math.isinf(self.lo) else f"{self.lo:g}"
        hi = "" if math.isinf(self.hi) else f"{self.hi:g}"
        return f"{lo}:{hi}" if (lo != hi or not lo) else lo


def _number(text: str, option: str) -> float:
    t = text.strip()
    if not t.isascii():
        raise SelectionError(f"{option} {text!r}: expected an ASCII number")
    try:
        x = float(t)
    except ValueError:
        raise SelectionError(f"{option} {text!r}: {t!r} is not a number") from None
    if not math.isfinite(x):
        raise SelectionError(f"{option} {text!r}: expected a finite number")
    return x


def parse_range(text: str, option: str = "range") -> Range:
    """``"400:700"``, ``"400:"``, ``":700"`` or ``"550"`` (550 +- 1e-6) as a :class:`Range`.

    Raises
    ------
    SelectionError
        Not of that form, not finite, or MIN > MAX.
    """
    if ":" in text:
        a, _, b = text.partition(":")
        lo = _number(a, option) if a.strip() else -math.inf
        hi = _number(b, option) if b.strip() else math.inf
    else:
        x = _number(text, option)
        lo, hi = x - _EXACT, x + _EXACT
    if lo > hi:
        raise SelectionError(f"{option} {text!r}: MIN must not exceed MAX")
    return Range(lo, hi)


def _names(values: Sequence[str] | str | None) -> list[str]:
    if values is None:
        return []
    items = [values] if isinstance(values, str) else list(values)
    return [x.strip() for item in items for x in item.split(",") if x.strip()]


def select(
    data: Measurement | pd.DataFrame,
    *,
    wavelength: Range | str | None = None,
    theta_i: Range | str | None = None,
    theta_r: Range | str | None = None,
    quantity: Sequence[str] | str | None = None,
    sample: Sequence[str] | str | None = None,
) -> pd.DataFrame:
    """Rows of a dataset table inside every given selection.

    Parameters
    ----------
    data : Measurement or DataFrame
        Dataset-schema rows.
    wavelength, theta_i, theta_r : Range or str, optional
        Closed ranges of ``wavelength_nm`` [nm], ``theta_i_deg`` and ``theta_r_deg`` [deg]
        (see :func:`parse_range`); rows without a ``theta_r_deg`` (NaN) are dropped by a
        ``theta_r`` range.
    quantity, sample : str or sequence of str, optional
        Names to keep (comma-separated in a string).

    Returns
    -------
    pandas.DataFrame
        The selected rows, index reset.

    Raises
    ------
    SelectionError
        A selection keeps no row; the message lists what the data hold.
    """
    df = data.data if isinstance(data, Measurement) else data
    keep = np.ones(len(df), bool)
    for col, rng, opt in (
        ("wavelength_nm", wavelength, "--wavelength-range"),
        ("theta_i_deg", theta_i, "--theta-i-range"),
        ("theta_r_deg", theta_r, "--theta-r"),
    ):
        if rng is None:
            continue
        r = parse_range(rng, opt) if isinstance(rng, str) else rng
        m = r.mask(df[col])
        if not (keep & m).any():
            v = df[col].to_numpy(dtype=float)
            v = v[np.isfinite(v)]
            held = f"{v.min():g} to {v.max():g}" if v.size else "no finite values"
            raise SelectionError(f"{opt} {r}: no row left; the data hold {col} {held}")
        keep &= m
    for col, names, opt in (("quantity", quantity, "--quantity"), ("sample", sample, "--sample")):
        wanted: list[str] = _names(names)
        if not wanted:
            continue
        m = df[col].astype(str).isin(wanted).to_numpy()
        if not (keep & m).any():
            present = sorted(set(df[col].astype(str)))
            raise SelectionError(f"{opt} {','.join(wanted)}: no row left; the data hold {present}")
        keep &= m
    return df[keep].reset_index(drop=True)
