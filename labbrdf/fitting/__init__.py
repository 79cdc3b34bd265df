"""Fitting core: data selection, an Objective, the nlopt global+local fitter, FitResult, batches.

>>> import labbrdf
>>> res = labbrdf.fit("smooth3", measurement)          # doctest: +SKIP
>>> print(res.fit_report())                            # doctest: +SKIP
>>> table = labbrdf.fit_many(dataset, "smooth3")       # doctest: +SKIP

The parts follow refnx's split: a :class:`~labbrdf.models.base.Model` is
a pure forward function; :class:`Objective` turns the varying parameters into a flat vector
and gives weighted residuals and chi-square (profiling out linear amplitudes by bounded
linear least squares); :func:`fit` drives nlopt, one stage per algorithm name, global then
local; :class:`FitResult` reports itself with lmfit's attribute names (``params``,
``chisqr``, ``redchi``, ``nfev``, ``fit_report()``).

Conventions: angles in degrees in every table and :class:`FitData`, radians into the model;
``phi_r = 180 deg`` is the specular half-plane. Workflow layer (b): imports numpy, scipy,
pandas and nlopt; the physics layer never imports this module.

Modules: :mod:`~labbrdf.fitting.data` (FitData, row selection),
:mod:`~labbrdf.fitting.objective` (Objective, profiling, starting points),
:mod:`~labbrdf.fitting.core` (:func:`fit`: set-up, search, result),
:mod:`~labbrdf.fitting.stages` (the nlopt stages and the polish),
:mod:`~labbrdf.fitting.parameters` (checked parameters and start),
:mod:`~labbrdf.fitting.energy` (rho <= 1), :mod:`~labbrdf.fitting.profiles` (profile
intervals),
:mod:`~labbrdf.fitting.uncertainty` (covariance and flags), :mod:`~labbrdf.fitting.result`
(FitResult), :mod:`~labbrdf.fitting.batch` (:func:`fit_many`).

Internal API: names without an underscore that the modules share but this package does not
re-export (``data.as_fit_data``, ``data.clean_fit_data``, ``data.select_rows``,
``data.several_groups_message``, ``FitData.from_arrays``, ``parameters.setup_params``,
``uncertainty.jacobian``, ``uncertainty.uncertainties``); each module lists its functions
among them in its own ``__all__``. They may change without notice.

``labbrdf.fit`` and ``labbrdf.fit_many`` are these functions, re-exported by ``labbrdf``.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

#: name -> the module of this package that defines it, imported on first use: the command
#: line reads ``fitting.defaults`` without paying for nlopt, scipy and pandas
_LAZY: dict[str, str] = {
    "auto_weighting": "batch",
    "fit_many": "batch",
    "fit_many_nk": "batch",
    "fit_records": "batch",
    "ALGORITHMS": "stages",
    "CONSTRAINED": "stages",
    "fit": "core",
    "fit_replicates": "core",
    "parse_method": "stages",
    "METHOD": "defaults",
    "FITTABLE_QUANTITIES": "data",
    "FitData": "data",
    "FitError": "data",
    "Objective": "objective",
    "combine_replicates": "replicates",
    "FitResult": "result",
    "AT_BOUND_FRAC": "uncertainty",
    "COND_MAX": "uncertainty",
    "CORREL_MAX": "uncertainty",
    "REL_STDERR_MAX": "uncertainty",
    "REL_STDERR_POOR": "uncertainty",
}

if TYPE_CHECKING:
    from .batch import auto_weighting, fit_many, fit_many_nk, fit_records
    from .core import fit, fit_replicates
    from .data import FITTABLE_QUANTITIES, FitData, FitError
    from .defaults import METHOD
    from .objective import Objective
    from .replicates import combine_replicates
    from .result import FitResult
    from .stages import ALGORITHMS, CONSTRAINED, parse_method
    from .uncertainty import AT_BOUND_FRAC, COND_MAX, CORREL_MAX, REL_STDERR_MAX, REL_STDERR_POOR

__all__ = [
    "ALGORITHMS",
    "AT_BOUND_FRAC",
    "COND_MAX",
    "CONSTRAINED",
    "CORREL_MAX",
    "FITTABLE_QUANTITIES",
    "METHOD",
    "REL_STDERR_MAX",
    "REL_STDERR_POOR",
    "FitData",
    "FitError",
    "FitResult",
    "Objective",
    "auto_weighting",
    "combine_replicates",
    "fit",
    "fit_many",
    "fit_many_nk",
    "fit_replicates",
    "fit_records",
    "parse_method",
]


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        value = getattr(importlib.import_module(f"{__name__}.{_LAZY[name]}"), name)
    elif name.startswith("__"):
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    else:
        try:  # a module of the package, as after ``import labbrdf.fitting.<name>``
            value = importlib.import_module(f"{__name__}.{name}")
        except ModuleNotFoundError as exc:
            if exc.name != f"{__name__}.{name}":
                raise
            raise AttributeError(f"module {__name__!r} has no attribute {name!r}") from None
    globals()[name] = value  # later look-ups skip this function
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *__all__})
