"""A sample's coating from its film fit: the layer's index at a wavelength, its thickness.

- :func:`coating_from_fit`: the index and thickness of a saved one-layer film fit (``labbrdf
  trace --coating-from FIT.json``);
- :func:`coating_of_stack`: the same of a fitted stack in memory, with its substrate index;
- :func:`film_coating`: the tracer's :class:`~labbrdf.Coating` and substrate index of a
  :class:`~labbrdf.FilmFit` (the prediction's coated sample).
"""

from __future__ import annotations

import math
import os
import warnings
from typing import Any

import numpy as np

from ..errors import SampleError
from ..films.graded import Graded
from ..films.materials import Roughness
from ..films.stack import read_fit_json
from ..nk.reading import tabulated_from_file
from ..roughness.topography import SlopeFit
from ..tracer.config import Coating

__all__ = ["CoatingWarning", "coating_from_fit", "coating_of_stack", "film_coating"]


class CoatingWarning(UserWarning):
    """A part of a fitted stack that the tracer's coating leaves out (a substrate's backside)."""


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
    stack, fitted = read_fit_json(path, tabulated_from_file)
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
        No layer, several layers or a roughness layer, a layer graded through its
        thickness, or a wavelength outside the fitted range.

    Warns
    -----
    CoatingWarning
        The stack's substrate has a finite thickness: the tracer's substrate is
        semi-infinite, and the light of its backside is left out.

    Notes
    -----
    The tracer's coating is one homogeneous layer added in intensity (Beer-Lambert). A
    graded layer whose parameter is the same at its top and bottom is homogeneous and
    taken; one that varies is refused, naming it: its two interfaces see different
    indices, which no single index represents. An incoherent layer is what the tracer
    computes anyway. A thickness spread, bandwidth or angle spread of the fit smooths the
    thin-film interference, which the incoherent coating does not have: nothing is lost.
    """
    names = [lay.name for lay in stack.layers]
    if len(stack.layers) != 1 or isinstance(stack.layers[0].material, Roughness):
        raise ValueError(
            f"{where}: the tracer has one coating over the substrate; this fit's stack has "
            f"{len(names)} layer(s) {names} ({hint})"
        )
    m = stack.layers[0].material
    if isinstance(m, Graded) and m.top != m.bottom:
        raise ValueError(
            f"{where}: layer {names[0]!r} is graded ({m.parameter} from {m.top:.6g} at the top "
            f"to {m.bottom:.6g} at the bottom); the tracer's coating is one homogeneous "
            f"layer, which cannot have two indices ({hint} without a gradient)"
        )
    if stack.substrate_thickness_nm is not None:
        warnings.warn(
            f"{where}: the fit's substrate is {stack.substrate_thickness_nm:g} nm thick, with "
            "the light of its backside; the tracer's substrate is semi-infinite, so that light "
            "is left out of the prediction",
            CoatingWarning,
            stacklevel=2,
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


def film_coating(
    fit: Any,
    wavelength_nm: float,
    roughness: SlopeFit | float,
    *,
    ndf: Any = None,
) -> tuple[Coating, complex]:
    """The tracer's coating and substrate index from a one-layer film fit of the sample.

    The layer's index at ``wavelength_nm`` and its fitted thickness become the
    :class:`~labbrdf.Coating` (as ``labbrdf trace --coating-from`` does with a saved fit,
    :func:`coating_of_stack`), the fit's substrate index the substrate's.

    Parameters
    ----------
    fit : labbrdf.FilmFit
        A film fit (:func:`labbrdf.fit_film`) of the sample's psi/Delta, one layer.
    wavelength_nm : float
        The wavelength traced [nm], inside the fit's wavelength range.
    roughness : SlopeFit or float
        GGX alpha [1] of the height map, given to the coating's top.
    ndf : TabulatedNDF, optional
        The height map's measured slope table for the coating's top instead of GGX.

    Returns
    -------
    coating : Coating
    substrate_index : complex
        The fit's substrate ``n + ik`` at ``wavelength_nm`` [1] (the psi/Delta of a coated
        sample are the stack's: their two-phase inversion is no substrate's index).

    Raises
    ------
    labbrdf.errors.SampleError
        A stack of more than one layer (or a roughness layer), a wavelength outside the
        fitted range, or a layer the tracer cannot hold (0 nm: the incoherent coating
        needs a thickness).

    Notes
    -----
    Conformal coating: the height map is taken as measured on the coating's top, and the
    substrate below has the same roughness (the tracer's default for ``--coating-from``,
    the substrate's alpha). The coating is incoherent (intensities, Beer-Lambert in the
    layer), as :func:`labbrdf.sample.trace_config_from_inputs` builds it; the film fit
    itself is coherent, so thin-film interference colours the fit, not the prediction.
    """
    d = getattr(fit, "data", None)
    src = "film fit"
    if d is not None and "source" in d.columns and len(d):
        src = "film fit of " + ", ".join(sorted(set(d["source"].astype(str))))[:200]
    w = np.asarray(d["wavelength_nm"], float) if d is not None else np.array([np.nan])
    try:
        layer_n, thickness, sub = coating_of_stack(
            fit.stack,
            wavelength_nm,
            (float(np.nanmin(w)), float(np.nanmax(w))),
            where=src,
            hint="the prediction traces one coating; fit a one-layer model",
        )
    except ValueError as exc:
        raise SampleError(str(exc)) from None
    alpha = float(roughness.alpha) if isinstance(roughness, SlopeFit) else float(roughness)
    if not thickness > 0:
        raise SampleError(
            f"{src}: the fitted layer is {thickness:g} nm thick; an incoherent coating needs "
            "a thickness > 0 (a 0 nm layer is the bare substrate)"
        )
    try:
        coating = Coating(
            n=layer_n.real, k=layer_n.imag, thickness_nm=thickness, alpha=alpha, ndf=ndf
        )
    except ValueError as exc:
        raise SampleError(f"{src}: {exc}") from None
    return coating, sub
