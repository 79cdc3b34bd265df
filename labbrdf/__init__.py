"""labbrdf: instrument exports to one dataset, BRDF fits, physical checks, a polarization tracer.

Everything a user needs is reachable from here; the names are imported lazily, on first use,
so that ``import labbrdf`` stays cheap, and ``dir(labbrdf)`` lists them all:

- reading: :func:`read`, :func:`read_many`, :class:`Measurement`, :func:`select`,
  :func:`formats`
- optical constants: :func:`nk_table`, :func:`combined_table` (pseudo-constants from
  psi/Delta with propagated sigmas)
- models and fits: :mod:`models` (:func:`labbrdf.models.get`), :func:`fit`,
  :func:`fit_many`, :class:`FitResult`, :func:`hemispherical_reflectance`
- films: :class:`Stack`, :class:`Layer`, :func:`fit_film`, :class:`FilmFit` (thin-film
  stacks fitted to psi/Delta and reflectance)
- roughness: :func:`read_height_map`, :func:`roughness_statistics`
- the tracer: :func:`trace`, :class:`TraceConfig`, :class:`Substrate`, :class:`Coating`,
  :class:`TraceResult`
- reports: :func:`user_report` (the validation report: :func:`labbrdf.report.validate`)
- errors: :class:`LabbrdfError`, the base of every labbrdf error, and the errors of each
  layer (:class:`AdapterError`, :class:`DatasetError`, :class:`FitError`,
  :class:`ModelError`)

The subpackages and modules (``labbrdf.optics``, ``labbrdf.nk``, ...) are attributes too.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

__version__ = "0.1.0.dev0"

#: public name -> (module, attribute): what ``import labbrdf`` offers, imported on first use
_LAZY: dict[str, tuple[str, str]] = {
    "read": ("labbrdf.adapters", "read"),
    "read_many": ("labbrdf.adapters", "read_many"),
    "formats": ("labbrdf.adapters", "formats"),
    "Measurement": ("labbrdf.dataset", "Measurement"),
    "select": ("labbrdf.selection", "select"),
    "nk_table": ("labbrdf.nk", "nk_table"),
    "combined_table": ("labbrdf.nk", "combined_table"),
    "fit": ("labbrdf.fitting", "fit"),
    "fit_many": ("labbrdf.fitting", "fit_many"),
    "FitResult": ("labbrdf.fitting", "FitResult"),
    "hemispherical_reflectance": ("labbrdf.integrate", "hemispherical_reflectance"),
    "Stack": ("labbrdf.films", "Stack"),
    "Layer": ("labbrdf.films", "Layer"),
    "fit_film": ("labbrdf.films", "fit_film"),
    "FilmFit": ("labbrdf.fitting.film", "FilmFit"),
    "read_height_map": ("labbrdf.adapters.topography", "read_height_map"),
    "roughness_statistics": ("labbrdf.topography", "roughness_statistics"),
    "trace": ("labbrdf.tracer", "trace"),
    "TraceConfig": ("labbrdf.tracer", "TraceConfig"),
    "TraceResult": ("labbrdf.tracer", "TraceResult"),
    "Substrate": ("labbrdf.tracer", "Substrate"),
    "Coating": ("labbrdf.tracer", "Coating"),
    "user_report": ("labbrdf.report", "user_report"),
    "LabbrdfError": ("labbrdf.errors", "LabbrdfError"),
    "AdapterError": ("labbrdf.adapters", "AdapterError"),
    "DatasetError": ("labbrdf.dataset", "DatasetError"),
    "FitError": ("labbrdf.fitting", "FitError"),
    "ModelError": ("labbrdf.models", "ModelError"),
}

#: subpackages and modules reachable as attributes of the package
_MODULES = (
    "adapters",
    "bsdf_export",
    "bsdf_geometry",
    "cli",
    "dataset",
    "dispersion",
    "ellipsometry",
    "errors",
    "films",
    "fitting",
    "integrate",
    "jsonsafe",
    "models",
    "nk",
    "optics",
    "outputs",
    "parallel",
    "provenance",
    "report",
    "richrepr",
    "samples",
    "selection",
    "smoothness",
    "stack",
    "surface",
    "topography",
    "tracer",
)

__all__ = ["__version__", *_LAZY, *_MODULES]

if TYPE_CHECKING:  # what a type checker and an IDE see; at run time __getattr__ imports
    from . import (
        adapters,
        bsdf_export,
        bsdf_geometry,
        cli,
        dataset,
        dispersion,
        ellipsometry,
        errors,
        films,
        fitting,
        integrate,
        jsonsafe,
        models,
        nk,
        optics,
        outputs,
        parallel,
        provenance,
        report,
        richrepr,
        samples,
        selection,
        smoothness,
        stack,
        surface,
        topography,
        tracer,
    )
    from .adapters import AdapterError, formats, read, read_many
    from .adapters.topography import read_height_map
    from .dataset import DatasetError, Measurement
    from .errors import LabbrdfError
    from .films import Layer, Stack, fit_film
    from .fitting import FitError, FitResult, fit, fit_many
    from .fitting.film import FilmFit
    from .integrate import hemispherical_reflectance
    from .models import ModelError
    from .nk import combined_table, nk_table
    from .report import user_report
    from .selection import select
    from .topography import roughness_statistics
    from .tracer import Coating, Substrate, TraceConfig, TraceResult, trace


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        module, attr = _LAZY[name]
        value = getattr(importlib.import_module(module), attr)
    elif name in _MODULES:
        value = importlib.import_module(f"labbrdf.{name}")
    else:
        raise AttributeError(f"module 'labbrdf' has no attribute {name!r}")
    globals()[name] = value  # later look-ups skip this function
    return value


def __dir__() -> list[str]:
    return sorted(__all__)
