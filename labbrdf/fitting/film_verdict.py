"""Whether a film fit's numbers mean anything, in words, and the names of its materials.

Woollam's MSE (:func:`labbrdf.fitting.film.woollam_mse`) is ``sqrt(chi2/nu)`` with the
files' sigmas: the root-mean-square misfit in units of the measurement's standard
deviation. WVASE and CompleteEASE users read an MSE of a few as a good model and one above
about 20 as one that lacks something: the model then misses every point by some twenty
standard deviations, far beyond what any error in the sigmas explains. Two thresholds, read
off the shared Ta2O5-on-tantalum wafer, say how far the numbers can still be used:

* above :data:`MSE_INCOMPLETE` (20) the model lacks a part of the sample (an interface, a
  roughness layer): the right Cauchy film on the lab's bare-tantalum table has MSE 36-58
  without its interface layer and 22.6 with it, and the thickness moves by 2 % between
  them; the parameters are those of the sample, biased by what is missing, and the fit
  says so and what to add;
* above :data:`MSE_WRONG_MODEL` (100) the model is the wrong one (the same film fitted on
  the default silicon has MSE ~1000 and a thickness of 344 nm for a 180 nm film): the
  parameters are not meaningful, and the fit says so and what to try.

Below 20 a fit that chi-square rejects (p < 0.01) still gets scaled intervals
(:attr:`labbrdf.FilmFit.misfit_scale`).
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

__all__ = ["MSE_INCOMPLETE", "MSE_WRONG_MODEL", "material_label", "wrong_model_verdict"]

#: Woollam MSE (``sqrt(chi2/nu)``) above which a film model is read as lacking something
MSE_INCOMPLETE = 20.0
#: Woollam MSE above which a film fit is read as the wrong model: its parameters mean nothing
MSE_WRONG_MODEL = 100.0


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
    """The words of a fit whose MSE says the model is wrong or incomplete; None below.

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
        try (another substrate, the lab's bare-substrate file as the substrate, more
        layers). Between :data:`MSE_INCOMPLETE` and it: that the model lacks something and
        the parameters may carry its bias, and what to add. The text starts with
        ``"MSE <value> > <threshold>"``.
    """
    if mse > MSE_WRONG_MODEL:
        return (
            f"MSE {mse:.4g} > {MSE_WRONG_MODEL:g}: the model does not describe this sample (it "
            f"misses the data by ~{mse:.0f} standard deviations at every point); the "
            "parameters above are not meaningful until a model fits. Try: another substrate "
            f"(this fit used {substrate}); {_BARE} more layers (an interface, a roughness "
            "layer, an absorbing film) or a narrower --wavelength-range where the film is "
            "transparent"
        )
    if mse > MSE_INCOMPLETE:
        return (
            f"MSE {mse:.4g} > {MSE_INCOMPLETE:g}: the model lacks something this sample has "
            "(WVASE users read an MSE above ~20 so); the parameters above may carry its "
            "bias, which the scaled intervals do not include (on a Ta2O5 wafer a missing "
            "interface layer moves the thickness by 2 %). Try: an interface or roughness "
            "layer (e.g. --layer iface:ema(@film,void):0..10:fraction=0..1 below the film), "
            f"another substrate (this fit used {substrate}); {_BARE}"
        )
    return None


#: how to give the lab's own bare-substrate file, on each of the three ways in
_BARE = (
    "your lab's ellipsometer file of the bare substrate as the substrate (command line: "
    '--substrate BARE.dat; model file: [substrate] file = "BARE.dat"; Python: '
    'labbrdf.nk.tabulated_from_file("BARE.dat"));'
)
