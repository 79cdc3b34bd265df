"""Reflectance and BRDF models with a plain-dict registry.

>>> from labbrdf import models
>>> m = models.get("smooth3")            # doctest: +SKIP
>>> m.evaluate(0.785, 0.785)             # doctest: +SKIP
"""

from __future__ import annotations

from typing import Any

from .base import Model, ModelError, Parameter, Parameters

__all__ = ["MODELS", "Model", "ModelError", "Parameter", "Parameters", "get", "names"]

#: name -> Model subclass (filled below)
MODELS: dict[str, type[Model]] = {}


def get(name: str, **options: Any) -> Model:
    """A new model instance by registry name, with model-specific options."""
    try:
        cls = MODELS[name]
    except KeyError:
        raise ModelError(f"unknown model {name!r}; models are {sorted(MODELS)}") from None
    return cls(**options)


def names() -> list[str]:
    return sorted(MODELS)


from .smooth3 import Smooth3  # noqa: E402

MODELS["smooth3"] = Smooth3

from .five_param import FiveParam  # noqa: E402

MODELS["five_param"] = FiveParam

from .microfacet import Microfacet  # noqa: E402

MODELS["microfacet"] = Microfacet
