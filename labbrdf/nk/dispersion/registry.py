"""The dispersion models by name: one line per model.

A model is a module of this package defining one :class:`~labbrdf.nk.dispersion.Dispersion`
subclass with a ``name``; :data:`_MODULES` lists it, and :data:`MODELS`, model files, fit
JSON, ``--layer`` and the film fit then know it by that name.
"""

from __future__ import annotations

from collections.abc import Mapping
from importlib import import_module
from typing import Any

from .base import Dispersion, DispersionError
from .tabulated import Tabulated

#: module of this package -> the Dispersion class it defines; one line per model
_MODULES = {
    "constant": "Constant",
    "cauchy": "Cauchy",
    "sellmeier": "Sellmeier",
    "tauc_lorentz": "TaucLorentz",
    "drude": "Drude",
    "lorentz": "Lorentz",
    "cody_lorentz": "CodyLorentz",
    "gaussian": "Gaussian",
    "bspline": "BSpline",
    "composite": "Sum",
    "tabulated": "Tabulated",
}


def _models() -> dict[str, type[Dispersion]]:
    out: dict[str, type[Dispersion]] = {}
    for module, cls_name in _MODULES.items():
        cls = getattr(import_module(f"{__package__}.{module}"), cls_name)
        if not (isinstance(cls, type) and issubclass(cls, Dispersion)):
            raise TypeError(f"{__package__}.{module}.{cls_name} is not a Dispersion")
        out[cls.name] = cls
    return out


#: registry name -> class
MODELS: dict[str, type[Dispersion]] = _models()


def from_dict(d: Mapping[str, Any]) -> Dispersion:
    """Inverse of ``Dispersion.to_dict()``; also accepts a bare complex index ``{"n", "k"}``.

    Raises
    ------
    DispersionError
        Unknown model or parameter names.
    """
    d = dict(d)
    name = str(d.pop("model", "")).lower()
    if name not in MODELS:
        raise DispersionError(f"unknown dispersion model {name!r}; models: {sorted(MODELS)}")
    if name == "tabulated":
        if "reference" in d:
            return Tabulated.reference(str(d["reference"]))
        if "file" in d:
            raise DispersionError(
                f"tabulated: {d['file']!r} is a file; read it with "
                "labbrdf.nk.tabulated_from_file (labbrdf.films.as_material's read_table)"
            )
        if "wavelength_nm" in d:
            return Tabulated(
                d["wavelength_nm"],
                d["n"],
                d.get("k", [0.0] * len(d["n"])),
                str(d.get("source", "table")),
            )
        raise DispersionError("tabulated: give 'reference' (si, sio2) or 'file'")
    return MODELS[name].from_params(d)
