"""Reading optical constants from files: n, k tables and pseudo-constants of ellipsometer files.

:func:`read_nk` reads a file's pseudo-constants (a table written by ``labbrdf nk`` or any
ellipsometer export), :func:`tabulated_from_file` a material's ``n, k`` as a
:class:`~labbrdf.nk.dispersion.Tabulated` (a text table, or an ellipsometer file combined over
its angles of incidence); below the film objects, which read their table files through it.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from .. import adapters
from ..errors import LabbrdfError
from . import dispersion as disp
from .tables import combined_table

#: largest n,k table (or ellipsometer file) that :func:`tabulated_from_file` reads [bytes]:
#: a table of a million rows is ~40 MB
MAX_TABLE_BYTES = 64 << 20


class NkError(LabbrdfError, ValueError):
    """n, k that a file cannot give: no psi/Delta, outside its range, not a bulk index.

    The message starts with the file it is about.
    """


def read_nk(path: str | os.PathLike[str]) -> pd.DataFrame:
    """The per-wavelength combined n, k of an ellipsometer file (its psi/Delta inverted).

    Parameters
    ----------
    path : path-like
        Any export :func:`labbrdf.read` reads that holds ordinary psi/Delta rows.

    Returns
    -------
    pandas.DataFrame
        The file's :func:`combined_table`, for :func:`bulk_index_at` or :func:`nk_at`.

    Raises
    ------
    labbrdf.AdapterError
        The file cannot be read.
    NkError
        It holds no psi/Delta to invert (the message names the file).
    """
    from .. import adapters  # the readers, imported where needed

    m = adapters.read(path)
    try:
        return combined_table(m)
    except ValueError as exc:
        raise NkError(f"{path}: {exc}") from None


def tabulated_from_file(
    path: str | os.PathLike[str], *, theta_deg: float | None = None
) -> disp.Tabulated:
    """Tabulated ``n, k`` of a material, read from a file.

    Parameters
    ----------
    path : path-like
        A text table ``wavelength_nm n [k]`` (comma, semicolon or whitespace separated,
        ``#`` comments, an optional header line; :func:`labbrdf.nk.dispersion.parse_nk_table`),
        or any ellipsometer export labbrdf reads: its psi/Delta are inverted to two-phase
        pseudo-constants (:func:`nk_table`) and averaged over the angles of incidence with
        the inverse-variance weights of :func:`combined_table` (a bare, smooth substrate:
        the pseudo-constants are the material's).
    theta_deg : float, optional
        Use only this angle of incidence of an ellipsometer file.

    Returns
    -------
    labbrdf.nk.dispersion.Tabulated
        Keyed ``file:PATH`` (its ``to_dict`` names the file).

    Raises
    ------
    labbrdf.nk.dispersion.DispersionError
        The file cannot be read as either, is not a regular file (a device, a FIFO: refused
        before it is opened) or is larger than :data:`MAX_TABLE_BYTES`; names the file (and
        the line of a table).
    """
    from ..outputs import InputFileError, read_input_file

    p = Path(path)
    try:
        raw = read_input_file(p, max_bytes=MAX_TABLE_BYTES, what="n,k table or ellipsometer file")
    except InputFileError as exc:
        raise disp.DispersionError(str(exc)) from None
    text = raw.decode("utf-8", errors="replace")
    try:
        w, n, k = disp.parse_nk_table(text, str(p))
    except disp.DispersionError as table_error:
        w, n, k = _pseudo_constants(p, theta_deg, table_error)
    return disp.Tabulated(w, n, k, source=str(p), key=f"file:{p}")


def _pseudo_constants(
    path: Path, theta_deg: float | None, table_error: disp.DispersionError
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Pseudo-constants of an ellipsometer file, combined over angles."""
    try:
        meas = adapters.read(path)
    except ValueError as exc:
        raise disp.DispersionError(
            f"{path}: neither an n,k table ({table_error}) nor an ellipsometer file ({exc})"
        ) from None
    df = meas.data
    if theta_deg is not None:
        keep = (~df["quantity"].isin(["psi", "delta"])) | (
            np.abs(df["theta_i_deg"] - theta_deg) < 1e-3
        )
        df = df[keep]
    try:
        table = combined_table(df, on_ill_conditioned="ignore")
    except ValueError as exc:
        raise disp.DispersionError(f"{path}: no pseudo-constants ({exc})") from None
    if "combined" in table and not bool(table["combined"].all()):
        raise disp.DispersionError(
            f"{path}: its angles of incidence disagree (pseudo-constants of a stack, not a "
            "material's constants); fit the stack with `labbrdf film` and use its layers"
        )
    table = table.sort_values("wavelength_nm").drop_duplicates("wavelength_nm")
    n = table["n"].to_numpy(float)
    k = table["k"].to_numpy(float)
    if np.any(n < 0) or np.any(k < 0):
        raise disp.DispersionError(
            f"{path}: the pseudo-constants have n < 0 or k < 0 at some wavelengths; they "
            "are not a material's constants (a film or a rough surface)"
        )
    return table["wavelength_nm"].to_numpy(float), n, k
