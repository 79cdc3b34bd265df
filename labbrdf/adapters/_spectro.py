"""Helpers shared by the spectrophotometer adapters (JASCO, PerkinElmer, Cary, JCAMP, SPC).

One spectrum is an ordinate ``y`` against a wavelength axis ``x`` [nm] in the file's own unit
(percent, absorbance). :func:`spectrum_frame` converts it to the canonical schema (percent to
fraction), drops missing points and counts them, and :func:`finish` wraps the frames in a
validated :class:`~labbrdf.dataset.Measurement`, turning a schema violation into an
:class:`~labbrdf.AdapterError` that names the file.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from typing import Any

import numpy as np
import pandas as pd

from ..dataset import DatasetError, Measurement, make_frame
from ._base import AdapterError, parse_number

__all__ = ["finish", "number", "spectrum_frame"]

#: factor from a percentage to the canonical fraction (unit "1")
PERCENT = 0.01


def number(text: str, path: str | os.PathLike[str], line: int | None, what: str) -> float:
    """Parse one finite ASCII decimal number (no ``nan``/``inf``/``1_000``/``１２``), or raise.

    Parameters
    ----------
    text : str
        The field, surrounding blanks allowed.
    path, line
        For the error message (``line`` is 1-based, or None).
    what : str
        What the field is, e.g. ``"NPOINTS"``.
    """
    return parse_number(text, path, line, what)


def spectrum_frame(
    *,
    path: str | os.PathLike[str],
    sample: str,
    instrument: str,
    quantity: str,
    scale: float,
    x_nm: Sequence[float] | np.ndarray,
    y: Sequence[float] | np.ndarray,
    theta_i_deg: float = float("nan"),
) -> tuple[pd.DataFrame, int]:
    """One spectrum in the canonical schema, and the number of missing points dropped.

    Parameters
    ----------
    path : path-like
        The source file (its name goes in ``source``).
    sample, instrument, quantity : str
        Schema columns; ``quantity`` is one of ``reflectance``, ``hemispherical_reflectance``,
        ``transmittance``, ``absorbance`` (all in unit ``"1"``).
    scale : float
        Factor from the file's ordinate to the canonical unit (0.01 for percent, 1 otherwise).
    x_nm : array_like
        Wavelength [nm].
    y : array_like
        Ordinate in the file's unit; non-finite entries are missing points and are dropped.
    theta_i_deg : float
        Angle of incidence [deg]; NaN (the default) for normal-incidence or sphere data.
    """
    x = np.asarray(x_nm, dtype=float)
    yy = np.asarray(y, dtype=float)
    keep = np.isfinite(yy)
    dropped = int(np.count_nonzero(~keep))
    with np.errstate(over="ignore"):  # an overflow gives inf, which validate() reports
        value = yy[keep] * scale
    frame = make_frame(
        sample=sample,
        instrument=instrument,
        source=os.path.basename(os.fspath(path)),
        quantity=quantity,
        value=value,
        unit="1",
        wavelength_nm=x[keep],
        theta_i_deg=theta_i_deg,
    )
    return frame, dropped


def finish(
    path: str | os.PathLike[str], frames: list[pd.DataFrame], meta: dict[str, Any]
) -> Measurement:
    """Concatenate spectra and validate them; a schema violation becomes an AdapterError."""
    frames = [f for f in frames if len(f)]
    if not frames:
        raise AdapterError(path, "no valid data points in the file")
    data = pd.concat(frames, ignore_index=True) if len(frames) > 1 else frames[0]
    try:
        return Measurement(data, meta)
    except DatasetError as exc:
        raise AdapterError(path, f"invalid data: {exc}") from None
