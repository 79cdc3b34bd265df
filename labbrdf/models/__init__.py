"""Reflectance and BRDF models with a plain-dict registry.

>>> from labbrdf import models
>>> m = models.get("smooth3")            # doctest: +SKIP
>>> m.evaluate(0.785, 0.785)             # doctest: +SKIP
"""

from __future__ import annotations

import inspect
from typing import Any

from .abg import ABg
from .aperture import Apertured
from .base import Model, ModelError, Parameter, Parameters
from .five_param import FiveParam
from .harvey_shack import HarveyShack
from .layered import Layered
from .microfacet import Microfacet
from .rayleigh_rice import RayleighRice
from .smooth3 import Smooth3

__all__ = [
    "APERTURE_OPTIONS",
    "MODELS",
    "Model",
    "ModelError",
    "Parameter",
    "Parameters",
    "get",
    "names",
    "option_names",
]

#: name -> Model subclass
MODELS: dict[str, type[Model]] = {
    "smooth3": Smooth3,
    "five_param": FiveParam,
    "microfacet": Microfacet,
    "layered": Layered,
    "rayleigh_rice": RayleighRice,
    "abg": ABg,
    "harvey_shack": HarveyShack,
}


#: options any registry model takes: the instrument's aperture half-angles [deg]; with
#: either, :func:`get` returns the model seen through it (:class:`~.aperture.Apertured`)
APERTURE_OPTIONS = ("detector_deg", "beam_deg")


def get(name: str, **options: Any) -> Model:
    """A new model instance by registry name, with model-specific options.

    ``detector_deg`` / ``beam_deg`` (:data:`APERTURE_OPTIONS`) wrap the model in
    :class:`~labbrdf.models.aperture.Apertured`, so that a fit's recorded options rebuild
    the model it fitted.
    """
    try:
        cls = MODELS[name]
    except KeyError:
        raise ModelError(f"unknown model {name!r}; models are {sorted(MODELS)}") from None
    aperture = {k: options.pop(k) for k in APERTURE_OPTIONS if k in options}
    model = cls(**options)
    return Apertured(model, **aperture) if aperture else model


def names() -> list[str]:
    """The registry names, sorted."""
    return sorted(MODELS)


def option_names(name: str) -> set[str]:
    """The options a registry model takes (its constructor's keywords: the contract).

    Raises
    ------
    ModelError
        Not a registry name.
    """
    if name not in MODELS:
        raise ModelError(f"unknown model {name!r}; models are {names()}")
    sig = inspect.signature(MODELS[name].__init__)
    return {
        k
        for k, v in sig.parameters.items()
        if k != "self" and v.kind not in (v.VAR_KEYWORD, v.VAR_POSITIONAL)
    }
