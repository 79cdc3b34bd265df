"""A sample's bulk n, k at one wavelength, looked up in a combined table, and a model with it."""

from __future__ import annotations

import os
from collections.abc import Sequence
from typing import Any, Literal

import numpy as np
import pandas as pd

from .reading import NkError, read_nk
from .tables import _angle_dependent_message, combined_table


def _single(
    table: pd.DataFrame, sample: str | None, source: str | None, what: str
) -> pd.DataFrame:
    if sample is not None:
        table = table[table["sample"] == sample]
    if source is not None:
        table = table[table["source"] == source]
    pairs = table[["sample", "source"]].drop_duplicates()
    if len(pairs) != 1:
        found = [tuple(r) for r in pairs.itertuples(index=False)]
        raise ValueError(
            f"{what}: expected one (sample, source), found {len(pairs)}: {found[:5]}; "
            "pass sample= and source="
        )
    series = [c for c in ("time_s", "x_mm", "y_mm") if c in table.columns]
    if series and len(table[series].drop_duplicates()) > 1:
        raise ValueError(f"{what}: the table holds a series ({series}); select one member")
    return table


def nk_at(
    table: pd.DataFrame,
    wavelength_nm: float | Sequence[float] | np.ndarray,
    *,
    sample: str | None = None,
    source: str | None = None,
    on_angle_dependent: Literal["raise", "nan"] = "raise",
) -> dict[str, np.ndarray]:
    """Combined ``n, k`` and uncertainties at given wavelengths, by linear interpolation.

    Parameters
    ----------
    table : pandas.DataFrame
        A :func:`combined_table` (or an :func:`nk_table`, combined first).
    wavelength_nm : float or array_like
        Wavelength(s) [nm], within the measured range.
    sample, source : str, optional
        Select one (sample, source) when the table holds several.
    on_angle_dependent : {"raise", "nan"}, optional
        What to do at a wavelength that needs a node without combined n, k (a sample whose
        angles disagree, :func:`combined_table`): raise (default) or return NaN.

    Returns
    -------
    dict
        ``{"wavelength_nm", "n", "k", "n_sigma", "k_sigma", "nk_cov"}`` as float arrays
        shaped like ``wavelength_nm`` (for the tracer's ``Substrate(n=, k=)`` or
        ``models.get("microfacet", n=, k=)``).

    Raises
    ------
    ValueError
        A wavelength outside the measured range (no extrapolation), an ambiguous table,
        or (``on_angle_dependent="raise"``) a wavelength without combined n, k.

    Notes
    -----
    Linear interpolation between the two neighbouring measured wavelengths; the sigmas
    and the covariance are interpolated the same way (exact at the nodes, an
    approximation in between that neglects the interpolation error itself).
    """
    if "theta_i_deg" in table.columns:
        table = combined_table(table)
    t = _single(table, sample, source, "nk_at").sort_values("wavelength_nm")
    wl = t["wavelength_nm"].to_numpy(float)
    x = np.asarray(wavelength_nm, dtype=float)
    lo, hi = float(wl[0]), float(wl[-1])
    if not np.all(np.isfinite(x)) or np.any((x < lo) | (x > hi)):
        bad = x[~((x >= lo) & (x <= hi))]
        raise ValueError(
            f"wavelength_nm: {bad.ravel()[:5].tolist()} outside the measured range "
            f"[{lo:.6g}, {hi:.6g}] nm; n, k are not extrapolated"
        )
    out = {"wavelength_nm": x}
    for c in ("n", "k", "n_sigma", "k_sigma", "nk_cov"):
        out[c] = np.interp(x, wl, t[c].to_numpy(float))
    if on_angle_dependent == "raise":
        bad = ~(np.isfinite(out["n"]) & np.isfinite(out["k"]))
        if bad.any():
            raise ValueError(_angle_dependent_message(x[bad]))
    return out


def bulk_index_at(
    table: pd.DataFrame, wavelength_nm: float, *, source: str | os.PathLike[str] = "n, k"
) -> tuple[float, float]:
    """The bulk index ``(n, k)`` of a combined table at one wavelength, checked physical.

    Parameters
    ----------
    table : pandas.DataFrame
        A :func:`combined_table` (e.g. of :func:`read_nk`) of one sample.
    wavelength_nm : float
        Vacuum wavelength [nm] inside the measured range (linear interpolation,
        :func:`nk_at`).
    source : str or path-like, optional
        What the table came from (its file), the start of every error message.

    Returns
    -------
    n, k : float
        Refractive index and extinction coefficient [1], ``n > 0`` and ``k >= 0``.

    Raises
    ------
    NkError
        The wavelength lies outside the table, the sample's angles disagree there (a
        stack), or the two-phase pseudo-index is not a material's (``n <= 0`` or
        ``k < 0``: a film on the sample, whose pseudo-index can leave the physical
        half-plane).
    """
    try:
        at = nk_at(table, wavelength_nm)
    except ValueError as exc:
        raise NkError(f"{source}: {exc}") from None
    n, k = float(at["n"]), float(at["k"])
    if not (n > 0 and k >= 0):
        raise NkError(
            f"{source}: the pseudo-index at {wavelength_nm:g} nm is n={n:.4g}, "
            f"k={k:.4g}, not a physical bulk index (a film on the sample?)"
        )
    return n, k


def model_with_nk(
    name: str,
    nk_from: str | os.PathLike[str] | pd.DataFrame,
    wavelength_nm: float,
    *,
    source: str | os.PathLike[str] | None = None,
    **options: Any,
) -> Any:
    """A registry model whose index is a sample's bulk n, k at one wavelength.

    Parameters
    ----------
    name : str
        A model that takes an index ``n``, ``k`` (``microfacet``, see
        :func:`labbrdf.models.option_names`).
    nk_from : path-like or pandas.DataFrame
        An ellipsometer file (:func:`read_nk`) or its combined table.
    wavelength_nm : float
        Vacuum wavelength [nm] at which the index is taken (:func:`bulk_index_at`).
    source : str or path-like, optional
        What a table came from, for messages (default: the file, or ``"n, k"``).
    **options
        The model's other options.

    Returns
    -------
    labbrdf.models.Model

    Raises
    ------
    labbrdf.errors.SetupError
        The model takes no index (the message names the keyword ``{nk_from}``).
    NkError
        No bulk n, k at that wavelength (the message starts with the file).
    labbrdf.ModelError
        An unknown model or a bad option.
    """
    from .. import models
    from ..errors import SetupError

    if "n" not in models.option_names(name):
        raise SetupError(f"{{nk_from}}: model {name!r} takes no index n, k")
    if isinstance(nk_from, pd.DataFrame):
        table, where = nk_from, source if source is not None else "n, k"
    else:
        table, where = read_nk(nk_from), source if source is not None else nk_from
    n, k = bulk_index_at(table, wavelength_nm, source=where)
    return models.get(name, **{**options, "n": n, "k": k})
