"""Whether a film fit's numbers mean anything, in words, and the names of its materials.

Woollam's MSE (:func:`labbrdf.fitting.film.woollam_mse`) is ``sqrt(chi2/nu)`` with the
files' sigmas: the root-mean-square misfit in units of the measurement's standard
deviation. WVASE and CompleteEASE users read an MSE of a few as a good model and one above
about 20 as a wrong one (a wrong substrate, a missing layer): the model then misses every
point by some twenty standard deviations, far beyond what any error in the sigmas explains,
and the best-fit values are those of a different sample. :data:`MSE_WRONG_MODEL` is that
threshold; below it a fit that chi-square rejects (p < 0.01) still gets scaled intervals
(:attr:`labbrdf.FilmFit.misfit_scale`), above it the fit says that its parameters are not
meaningful and what to try.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

__all__ = ["MSE_WRONG_MODEL", "material_label", "wrong_model_verdict"]

#: Woollam MSE (``sqrt(chi2/nu)``) above which a film fit is read as the wrong model
MSE_WRONG_MODEL = 20.0


def material_label(material: Mapping[str, Any] | Any) -> str:
    """A material in a few words: a reference table's name, a file's name, a model's.

    Parameters
    ----------
    material : mapping or material
        A material's ``to_dict()`` (as in :meth:`labbrdf.FilmFit.summary`) or the material.

    Returns
    -------
    str
        e.g. ``"si (reference table, Green 2008)"``, ``"w2_10102006.dat (n, k from this
        file)"``, ``"cauchy"``, ``"constant n = 3.9 + 0.02i"``.
    """
    d = material if isinstance(material, Mapping) else material.to_dict()
    model = str(d.get("model", "?"))
    if model == "tabulated" and "reference" in d:
        ref = str(d["reference"])
        cite = {"si": "Green 2008", "sio2": "Malitson 1965"}.get(ref)
        return f"{ref} (reference table{', ' + cite if cite else ''})"
    if model == "tabulated" and "file" in d:
        return f"{Path(str(d['file'])).name} (n, k from this file)"
    if model == "tabulated":
        return f"table ({d.get('source', 'given as arrays')})"
    if model == "constant":
        n, k = float(d.get("n", float("nan"))), float(d.get("k", 0.0))
        return f"constant n = {n:.4g}" + (f" + {k:.4g}i" if k else "")
    return model


def wrong_model_verdict(mse: float, substrate: str) -> str | None:
    """The words of a fit whose MSE says the model is wrong; None below the threshold.

    Parameters
    ----------
    mse : float
        Woollam's MSE of the fit [1].
    substrate : str
        The substrate used (:func:`material_label`).

    Returns
    -------
    str or None
        Above :data:`MSE_WRONG_MODEL`: that the parameters are not meaningful and what to
        try (another substrate, the lab's bare-substrate file as the substrate, more layers).
    """
    if not mse > MSE_WRONG_MODEL:
        return None
    return (
        f"MSE {mse:.4g} > {MSE_WRONG_MODEL:g}: the model does not describe this sample (it "
        f"misses the data by ~{mse:.0f} standard deviations at every point); the parameters "
        "above are not meaningful until a model fits. Try: another substrate (this fit "
        f"used {substrate}); your lab's ellipsometer file of the bare substrate as the "
        "substrate (command line: --substrate BARE.dat; model file: [substrate] file = "
        '"BARE.dat"; Python: labbrdf.nk.tabulated_from_file("BARE.dat")); more layers '
        "(an interface, a roughness layer, an absorbing film) or a narrower "
        "--wavelength-range where the film is transparent"
    )
