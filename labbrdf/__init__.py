"""labbrdf: instrument exports to one dataset, BRDF fits, physical checks, a polarization tracer.

Everything a user needs is reachable from here; the names are imported lazily, on first use,
so that ``import labbrdf`` stays cheap, and ``dir(labbrdf)`` lists them all:

- reading: :func:`read`, :func:`read_many`, :class:`Measurement`, :func:`select`,
  :func:`formats`; :func:`read_inputs` reads a list of optical exports and height maps
  (each file once) into :class:`Inputs`
- optical constants: :func:`nk_table`, :func:`combined_table` (pseudo-constants from
  psi/Delta with propagated sigmas), :func:`read_nk`, :func:`bulk_index_at` (a file's bulk
  n, k at one wavelength), :func:`model_with_nk` (a model with that index)
- models and fits: :mod:`models` (:func:`labbrdf.models.get`), :func:`fit`,
  :func:`fit_many`, :func:`fit_many_nk` (an index per wavelength from an ellipsometer
  file), :func:`fit_records` (a batch as JSON records), :class:`FitResult`,
  :func:`hemispherical_reflectance`
- films: :class:`Stack`, :class:`Layer`, :func:`fit_film`, :class:`FilmFit` (thin-film
  stacks fitted to psi/Delta and reflectance), :func:`fit_film_samples` (several samples),
  :func:`fit_film_map` (wafer maps)
- roughness: :func:`read_height_map`, :func:`roughness_statistics`, :func:`psd` (power
  spectra of height maps, their composite and a PSD model fit)
- the tracer: :func:`trace`, :class:`TraceConfig`, :class:`Substrate`, :class:`Coating`,
  :class:`TraceResult`, :func:`trace_config_from_inputs` (a run from values and files)
- reports: :func:`user_report` (the validation report: :func:`labbrdf.report.validate`)
- errors: :class:`LabbrdfError`, the base of every labbrdf error, and the errors of each
  layer (:class:`AdapterError`, :class:`DatasetError`, :class:`FitError`,
  :class:`ModelError`, :class:`NkError`), and :class:`SetupError` (arguments that do not fit
  together, named in the message)

The subpackages and modules (``labbrdf.optics``, ``labbrdf.nk``, ...) are attributes too.
The public face is written once, in the tables ``_LAZY`` (names) and ``_MODULES``
(modules) below: ``__all__``, ``dir(labbrdf)`` and the attribute look-up follow from them.
The plumbing modules (``_PLUMBING``: ``cli``, ``figstyle``, ``jsonsafe``, ``outputs``,
``progress``, ``provenance``, ``richrepr``) are not offered; import them by path.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

__version__ = "0.1.0.dev0"

#: public name -> (module, attribute): what ``import labbrdf`` offers, imported on first use
_LAZY: dict[str, tuple[str, str]] = {
    "read": ("labbrdf.adapters", "read"),
    "read_many": ("labbrdf.adapters", "read_many"),
    "read_inputs": ("labbrdf.adapters", "read_inputs"),
    "Inputs": ("labbrdf.adapters", "Inputs"),
    "formats": ("labbrdf.adapters", "formats"),
    "Measurement": ("labbrdf.dataset", "Measurement"),
    "select": ("labbrdf.selection", "select"),
    "nk_table": ("labbrdf.nk", "nk_table"),
    "combined_table": ("labbrdf.nk", "combined_table"),
    "read_nk": ("labbrdf.nk", "read_nk"),
    "bulk_index_at": ("labbrdf.nk", "bulk_index_at"),
    "model_with_nk": ("labbrdf.nk", "model_with_nk"),
    "fit": ("labbrdf.fitting", "fit"),
    "fit_many": ("labbrdf.fitting", "fit_many"),
    "fit_many_nk": ("labbrdf.fitting", "fit_many_nk"),
    "fit_records": ("labbrdf.fitting", "fit_records"),
    "FitResult": ("labbrdf.fitting", "FitResult"),
    "hemispherical_reflectance": ("labbrdf.integrate", "hemispherical_reflectance"),
    "Stack": ("labbrdf.films", "Stack"),
    "Layer": ("labbrdf.films", "Layer"),
    "fit_film": ("labbrdf.fitting.film", "fit_film"),
    "FilmFit": ("labbrdf.fitting.film", "FilmFit"),
    "fit_film_samples": ("labbrdf.fitting.film_multi", "fit_film_samples"),
    "fit_film_map": ("labbrdf.fitting.film_map", "fit_film_map"),
    "read_height_map": ("labbrdf.adapters.topography", "read_height_map"),
    "roughness_statistics": ("labbrdf.roughness.topography", "roughness_statistics"),
    "psd": ("labbrdf.roughness.psd_result", "psd"),
    "trace": ("labbrdf.tracer", "trace"),
    "TraceConfig": ("labbrdf.tracer", "TraceConfig"),
    "TraceResult": ("labbrdf.tracer", "TraceResult"),
    "Substrate": ("labbrdf.tracer", "Substrate"),
    "Coating": ("labbrdf.tracer", "Coating"),
    "trace_config_from_inputs": ("labbrdf.sample", "trace_config_from_inputs"),
    "user_report": ("labbrdf.report", "user_report"),
    "LabbrdfError": ("labbrdf.errors", "LabbrdfError"),
    "AdapterError": ("labbrdf.adapters", "AdapterError"),
    "DatasetError": ("labbrdf.dataset", "DatasetError"),
    "FitError": ("labbrdf.fitting", "FitError"),
    "ModelError": ("labbrdf.models", "ModelError"),
    "NkError": ("labbrdf.nk", "NkError"),
    "SetupError": ("labbrdf.errors", "SetupError"),
}

#: subpackages and modules offered as attributes of the package
_MODULES = (
    "adapters",
    "bsdf_geometry",
    "dataset",
    "ellipsometry",
    "errors",
    "films",
    "fitting",
    "integrate",
    "microfacet",
    "models",
    "nk",
    "optics",
    "parallel",
    "prediction",
    "report",
    "roughness",
    "rr_prediction",
    "sample",
    "samples",
    "selection",
    "specular_dop",
    "tracer",
    "writers",
)

#: modules that moved into a subpackage, still offered by their old name
_MOVED = {
    "smoothness": "roughness.smoothness",
    "surface": "roughness.synthetic",
    "topography": "roughness.topography",
    "tracer_setup": "sample.run",
    "bsdf_export": "writers.zemax",
}

#: plumbing the modules above share (the command line, JSON sanitising, output safety,
#: the figure style, the progress line, provenance, rich displays): importable by path
#: (``import labbrdf.cli``), not offered
_PLUMBING = ("cli", "figstyle", "jsonsafe", "outputs", "progress", "provenance", "richrepr")

#: the public face, derived from the tables above; ``dir(labbrdf)`` lists it
__all__ = ["__version__", *_LAZY, *_MODULES, *_MOVED]

# What a type checker and an IDE see of the two tables (at run time __getattr__ imports);
# tests/test_public_api.py checks that it mirrors them entry for entry.
if TYPE_CHECKING:
    from . import (
        adapters,
        bsdf_geometry,
        dataset,
        ellipsometry,
        errors,
        films,
        fitting,
        integrate,
        microfacet,
        models,
        nk,
        optics,
        parallel,
        prediction,
        report,
        roughness,
        rr_prediction,
        sample,
        samples,
        selection,
        specular_dop,
        tracer,
        writers,
    )
    from .adapters import AdapterError, Inputs, formats, read, read_inputs, read_many
    from .adapters.topography import read_height_map
    from .dataset import DatasetError, Measurement
    from .errors import LabbrdfError, SetupError
    from .films import Layer, Stack
    from .fitting import FitError, FitResult, fit, fit_many, fit_many_nk, fit_records
    from .fitting.film import FilmFit, fit_film
    from .fitting.film_map import fit_film_map
    from .fitting.film_multi import fit_film_samples
    from .integrate import hemispherical_reflectance
    from .models import ModelError
    from .nk import NkError, bulk_index_at, combined_table, model_with_nk, nk_table, read_nk
    from .report import user_report
    from .roughness import smoothness, topography
    from .roughness import synthetic as surface
    from .roughness.psd_result import psd
    from .roughness.topography import roughness_statistics
    from .sample import run as tracer_setup
    from .sample import trace_config_from_inputs
    from .selection import select
    from .tracer import Coating, Substrate, TraceConfig, TraceResult, trace
    from .writers import zemax as bsdf_export


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        module, attr = _LAZY[name]
        value = getattr(importlib.import_module(module), attr)
    elif name in _MODULES:
        value = importlib.import_module(f"labbrdf.{name}")
    elif name in _MOVED:
        value = importlib.import_module(f"labbrdf.{_MOVED[name]}")
    else:
        raise AttributeError(f"module 'labbrdf' has no attribute {name!r}")
    globals()[name] = value  # later look-ups skip this function
    return value


def __dir__() -> list[str]:
    """The public face (:data:`__all__`), sorted."""
    return sorted(__all__)
