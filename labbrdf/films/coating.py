"""The tracer's coating from a fitted one-layer stack: its index at a wavelength, its thickness."""

from __future__ import annotations

import math
import os
from typing import Any

import numpy as np

from .materials import Roughness
from .stack import read_fit_json


def coating_from_fit(path: str | os.PathLike[str], wavelength_nm: float) -> tuple[complex, float]:
    """The coating of a one-layer film fit: its index at a wavelength and its thickness.

    Parameters
    ----------
    path : path-like
        A film fit's JSON (:meth:`labbrdf.FilmFit.save_json`, ``labbrdf film
        --fit-json FIT.json``) whose stack has exactly one layer over the substrate
        (the tracer's one coating).
    wavelength_nm : float
        Vacuum wavelength [nm], inside the fitted wavelength range.

    Returns
    -------
    N : complex
        The layer's fitted index ``n + ik`` at ``wavelength_nm`` [1].
    thickness_nm : float
        Its fitted thickness [nm].

    Raises
    ------
    ValueError
        The file is not a film fit (:class:`labbrdf.films.FilmError`, naming the file and
        line), its stack has no layer, several layers or a roughness layer, or the
        wavelength lies outside the fitted range (a dispersion model is not extrapolated
        beyond the data that fixed it).
    """
    stack, fitted = read_fit_json(path)
    layer_n, thickness, _ = coating_of_stack(
        stack,
        wavelength_nm,
        fitted,
        where=str(path),
        hint="fit one layer, or give --coating and --thickness",
    )
    return layer_n, thickness


def coating_of_stack(
    stack: Any,
    wavelength_nm: float,
    fitted_range_nm: tuple[float, float],
    *,
    where: str,
    hint: str = "fit one layer",
) -> tuple[complex, float, complex]:
    """The tracer's coating and substrate from a fitted one-layer stack, at one wavelength.

    Parameters
    ----------
    stack : labbrdf.films.Stack
        The fitted stack (the ``stack`` of a :class:`labbrdf.FilmFit`), one layer over the
        substrate.
    wavelength_nm : float
        Vacuum wavelength [nm], inside ``fitted_range_nm``.
    fitted_range_nm : (float, float)
        The wavelengths the fit saw [nm]; a dispersion model is not extrapolated beyond
        the data that fixed it.
    where : str
        The fit's origin (a file), named in the errors.
    hint : str
        What to do about a stack of another shape, appended to that error.

    Returns
    -------
    layer_index : complex
        The layer's ``n + ik`` at ``wavelength_nm`` [1].
    thickness_nm : float
        Its thickness [nm].
    substrate_index : complex
        The stack's substrate ``n + ik`` at ``wavelength_nm`` [1].

    Raises
    ------
    ValueError
        No layer, several layers or a roughness layer, or a wavelength outside the fitted
        range.
    """
    names = [lay.name for lay in stack.layers]
    if len(stack.layers) != 1 or isinstance(stack.layers[0].material, Roughness):
        raise ValueError(
            f"{where}: the tracer has one coating over the substrate; this fit's stack has "
            f"{len(names)} layer(s) {names} ({hint})"
        )
    wl = float(wavelength_nm)
    lo, hi = float(fitted_range_nm[0]), float(fitted_range_nm[1])
    if not (math.isfinite(wl) and lo <= wl <= hi):
        raise ValueError(
            f"{where}: {wl:g} nm is outside the fitted range [{lo:g}, {hi:g}] nm; the layer's "
            "dispersion is not extrapolated"
        )
    layer = stack.layers[0]
    at = stack.nk(wl)
    return (
        complex(np.asarray(at[layer.name]).ravel()[0]),
        float(layer.thickness_nm),
        complex(np.asarray(at["substrate"]).ravel()[0]),
    )
