"""A sample's substrate index from its ellipsometer file: the bulk n, k at one wavelength.

The one reading of a substrate's ``n + ik`` from measured psi/Delta that ``labbrdf trace
--nk-from``, the report's tracer maps and the prediction share:

- :func:`bulk_index` takes a file (or its rows, already read) and gives the bulk index at one
  wavelength: the two-phase pseudo-constants combined over the angles of incidence
  (:func:`labbrdf.nk.combined_table`), interpolated in wavelength and checked physical
  (:func:`labbrdf.nk.bulk_index_at`);
- :func:`substrate_nk` gives them with their standard uncertainties at several wavelengths
  (:func:`labbrdf.nk.nk_at`), for the prediction's tables.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from ..errors import SampleError
from ..nk import bulk_index_at, combined_table, nk_at, ordinary_psi_delta, read_nk

__all__ = ["bulk_index", "substrate_nk"]


def _sources(data: pd.DataFrame) -> str:
    """The files of a dataset's rows, for an error message."""
    return ", ".join(sorted(set(data["source"].astype(str))))[:200] if len(data) else "-"


def bulk_index(
    source: str | os.PathLike[str] | pd.DataFrame,
    wavelength_nm: float,
    *,
    where: str | os.PathLike[str] | None = None,
) -> complex:
    """The bulk index ``n + ik`` of a bare sample's psi/Delta at one wavelength.

    Parameters
    ----------
    source : path-like or pandas.DataFrame
        An ellipsometer file (:func:`labbrdf.nk.read_nk` reads it), or its rows as
        :func:`labbrdf.read` gave them.
    wavelength_nm : float
        Vacuum wavelength [nm] inside the measured range.
    where : str or path-like, optional
        What the rows came from, the start of every error (default: the file, or the
        rows' ``source``).

    Returns
    -------
    complex
        ``n + ik`` [1], ``n > 0`` and ``k >= 0``.

    Raises
    ------
    labbrdf.AdapterError
        The file cannot be read.
    labbrdf.NkError
        No psi/Delta, a wavelength outside the measured range, angles of incidence that
        disagree there (a stack) or a pseudo-index that is no material's (the message
        names the file).
    """
    if isinstance(source, pd.DataFrame):
        table = combined_table(source)
        label: str | os.PathLike[str] = where if where is not None else _sources(source)
    else:
        table = read_nk(source)
        label = where if where is not None else source
    n, k = bulk_index_at(table, wavelength_nm, source=label)
    return complex(n, k)


def substrate_nk(
    data: pd.DataFrame, wavelength_nm: float | Sequence[float] | NDArray[np.float64]
) -> dict[str, Any]:
    """The substrate's n, k at given wavelengths from a psi/Delta dataset (all angles).

    :func:`labbrdf.nk.nk_at` on :func:`labbrdf.nk.combined_table`: the two-phase inversion
    of every point, combined over the angles of incidence, interpolated in wavelength.

    Raises
    ------
    labbrdf.errors.SampleError
        No psi/Delta, several files, a wavelength outside the measured range, or angles of
        incidence that disagree (a stack: its two-phase n, k is no material's).
    """
    try:
        table = combined_table(ordinary_psi_delta(data), on_ill_conditioned="ignore")
        return nk_at(table, wavelength_nm)
    except ValueError as exc:
        raise SampleError(f"{_sources(data)}: {exc}") from None
