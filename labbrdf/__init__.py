"""labbrdf: instrument exports to one dataset, BRDF fits, physical checks, a polarization tracer.

The public API is imported lazily so that ``import labbrdf`` stays cheap:

- :func:`read`, :func:`read_many` (instrument adapters), :class:`Measurement`
- :func:`fit`, :func:`fit_many` (nlopt fitting core, from :mod:`labbrdf.fitting`)
- :func:`hemispherical_reflectance` (directional-hemispherical reflectance of a model)
- :func:`trace` (Monte Carlo polarization ray tracer)
- :class:`LabbrdfError`, the base of every labbrdf error
"""

from __future__ import annotations

import importlib
from typing import Any

__version__ = "0.1.0.dev0"

_LAZY = {
    "read": ("labbrdf.adapters", "read"),
    "read_many": ("labbrdf.adapters", "read_many"),
    "Measurement": ("labbrdf.dataset", "Measurement"),
    "DatasetError": ("labbrdf.dataset", "DatasetError"),
    "AdapterError": ("labbrdf.adapters", "AdapterError"),
    "LabbrdfError": ("labbrdf.errors", "LabbrdfError"),
    "fit": ("labbrdf.fitting", "fit"),
    "fit_many": ("labbrdf.fitting", "fit_many"),
    "FitResult": ("labbrdf.fitting", "FitResult"),
    "hemispherical_reflectance": ("labbrdf.integrate", "hemispherical_reflectance"),
    "trace": ("labbrdf.tracer", "trace"),
    "TraceConfig": ("labbrdf.tracer", "TraceConfig"),
}

__all__ = ["__version__", *_LAZY]


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        mod, attr = _LAZY[name]
        return getattr(importlib.import_module(mod), attr)
    if name in {
        "adapters",
        "dataset",
        "optics",
        "models",
        "fitting",
        "errors",
        "jsonsafe",
        "integrate",
        "tracer",
        "surface",
        "parallel",
        "cli",
        "report",
    }:
        return importlib.import_module(f"labbrdf.{name}")
    raise AttributeError(f"module 'labbrdf' has no attribute {name!r}")
