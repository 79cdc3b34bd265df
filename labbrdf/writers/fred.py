"""A fitted Harvey model written as the scatter definition FRED imports (a FRED script).

FRED (Photon Engineering) defines its scatter models in its scripting language (a BASIC
dialect): a script fills the documented structure of the model and adds it to the
document's Scatterers folder. The ABg model is ``T_ABGSCATTER`` (members ``Acoef``,
``Bcoef``, ``G``, ``Name``, ``Description``, ``ApplyRefl``, ``ApplyTrans``,
``HaltIncident``; initialised by ``InitAbgScatter``, added by ``AddAbgScatter``), the
Harvey-Shack model ``T_HARVEYSHACKSCATTER`` (``b0``, ``L``, ``S`` and the same flags;
``InitHarveyShackScatter``, ``AddHarveyShackScatter``) (FRED Scripting Reference Manual,
"Data Structures"). FRED evaluates both with the formulas of :mod:`labbrdf.models.abg` and
:mod:`labbrdf.models.harvey_shack` and has no wavelength dependence for them, so the
script states, as comments, the wavelength of the fit and the angles it covered: outside
them the parameters are an extrapolation.

The file is written through :func:`labbrdf.outputs.atomic_output` and never replaces an
existing file unless asked.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from ..outputs import OutputError, atomic_output, check_file_output

__all__ = ["FRED_MODELS", "write_fred_script"]

#: registry model -> (FRED structure, Init subroutine, Add function, (labbrdf name, member))
FRED_MODELS: dict[str, tuple[str, str, str, tuple[tuple[str, str], ...]]] = {
    "abg": (
        "T_ABGSCATTER",
        "InitAbgScatter",
        "AddAbgScatter",
        (("A", "Acoef"), ("B", "Bcoef"), ("g", "G")),
    ),
    "harvey_shack": (
        "T_HARVEYSHACKSCATTER",
        "InitHarveyShackScatter",
        "AddHarveyShackScatter",
        (("b0", "b0"), ("L", "L"), ("S", "S")),
    ),
}


def _domain(result: Any, wavelength_stated: bool) -> list[str]:
    """Comment lines: the wavelength and the angles the fit covered."""
    d = result.data
    if d is None:
        raise OutputError("the fit result holds no data: its wavelength and domain are unknown")
    ti, tr = np.asarray(d.theta_i_deg, float), np.asarray(d.theta_r_deg, float)
    wl = None if d.wavelength_nm is None else np.unique(np.asarray(d.wavelength_nm, float))
    wl_text = "not stated" if wl is None or wl.size == 0 else f"{float(wl[0]):.6g} nm"
    if not wavelength_stated:
        wl_text += " (a label: the measurement states no wavelength)"
    return [
        f"wavelength of the fit: {wl_text} (FRED does not scale this model with wavelength)",
        f"fitted domain: theta_i {ti.min():.6g}..{ti.max():.6g} deg, "
        f"theta_s {tr.min():.6g}..{tr.max():.6g} deg, {ti.size} points",
    ]


def _script(result: Any, name: str, wavelength_stated: bool) -> str:
    struct, init, add, members = FRED_MODELS[result.model]
    opts: Mapping[str, Any] = result.options
    if opts.get("diffuse"):
        raise OutputError(
            f"model {result.model!r} with diffuse=True: FRED's {struct} has no Lambertian "
            "floor; export a fit without it (or add FRED's Lambertian model by hand)"
        )
    trans = bool(opts.get("transmission"))
    head = [
        f"labbrdf fit of model {result.model!r} ({'BTDF' if trans else 'BRDF'})",
        *_domain(result, wavelength_stated),
        f"chi2/nu {result.redchi:.6g}, {result.weighting}",
        "the specular (or directly transmitted) ray is kept: the model is the scatter only",
    ]
    body = [f"    Dim scat As {struct}", f"    {init} scat", f'    scat.Name = "{name}"']
    body.append(f'    scat.Description = "labbrdf {result.model} fit"')
    for ours, member in members:
        p = result.params[ours]
        err = "" if p.stderr is None else f"  ' stderr {p.stderr:.6g}"
        body.append(f"    scat.{member} = {float(p.value)!r}{err}")
    body += [
        f"    scat.ApplyRefl = {not trans}",
        f"    scat.ApplyTrans = {trans}",
        "    scat.HaltIncident = False",
        "    Dim id As Long",
        f"    id = {add}(scat)",
    ]
    lines = [f"' {h}" for h in head] + ["", "Sub Main", *body, "End Sub", ""]
    return "\n".join(lines)


def write_fred_script(
    result: Any,
    path: str | os.PathLike[str],
    *,
    name: str | None = None,
    wavelength_stated: bool = True,
    overwrite: bool = False,
) -> Path:
    """Write a fitted ``abg`` or ``harvey_shack`` model as a FRED script (``.frs``).

    Parameters
    ----------
    result : FitResult
        A fit of the ``abg`` or ``harvey_shack`` registry model (without ``diffuse``),
        holding its data (``result.data``: the wavelength and domain written as comments).
    path : str or path-like
        The script file, ending in ``.frs``.
    name : str, optional
        The model's name in FRED's Scatterers folder; default ``labbrdf <model>``.
    wavelength_stated : bool
        False when the measurement's wavelength is a label (a ``.bsdf`` file that states
        none: ``Measurement.meta["wavelength_stated"]``); the comment then says so.
    overwrite : bool
        Replace an existing file.

    Returns
    -------
    pathlib.Path
        The file written.

    Raises
    ------
    OutputError
        Another model, a Lambertian floor FRED's structure cannot hold, a result without
        data, a name with a double quote, or an output that may not be written (exists,
        wrong suffix; :func:`labbrdf.outputs.check_file_output`).
    """
    if getattr(result, "model", None) not in FRED_MODELS:
        raise OutputError(
            f"model {getattr(result, 'model', None)!r}: FRED scripts are written for "
            f"{sorted(FRED_MODELS)} fits"
        )
    label = f"labbrdf {result.model}" if name is None else str(name)
    if '"' in label or "\n" in label:
        raise OutputError(f"name {label!r}: expected a name without double quotes or newlines")
    target = check_file_output(path, suffixes=(".frs",), option="path", overwrite=overwrite)
    text = _script(result, label, wavelength_stated)
    with atomic_output(target) as tmp, open(tmp, "w", encoding="ascii", newline="\r\n") as fh:
        fh.write(text)
    return target
