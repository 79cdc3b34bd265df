"""Fitting core: data selection, an Objective, the nlopt global+local fitter, FitResult, batches.

>>> import labbrdf
>>> res = labbrdf.fit("smooth3", measurement)          # doctest: +SKIP
>>> print(res.fit_report())                            # doctest: +SKIP
>>> table = labbrdf.fit_many(dataset, "smooth3")       # doctest: +SKIP

The parts follow refnx's split (STYLE.md item 7): a :class:`~labbrdf.models.base.Model` is
a pure forward function; :class:`Objective` turns the varying parameters into a flat vector
and gives weighted residuals and chi-square (profiling out linear amplitudes by bounded
linear least squares); :func:`fit` drives nlopt, one stage per algorithm name, global then
local; :class:`FitResult` reports itself with lmfit's attribute names (STYLE.md item 8).

Conventions: angles in degrees in every table and :class:`FitData`, radians into the model;
``phi_r = 180 deg`` is the specular half-plane. Workflow layer (b): imports numpy, scipy,
pandas and nlopt; the physics layer never imports this module.

Modules: :mod:`~labbrdf.fit.data` (FitData, row selection), :mod:`~labbrdf.fit.objective`
(Objective, profiling, starting points), :mod:`~labbrdf.fit.core` (nlopt stages, :func:`fit`),
:mod:`~labbrdf.fit.uncertainty` (covariance and flags), :mod:`~labbrdf.fit.result`
(FitResult), :mod:`~labbrdf.fit.batch` (:func:`fit_many`).
"""

from __future__ import annotations

import sys
import types
from typing import Any

from .batch import fit_many
from .core import ALGORITHMS, CONSTRAINED, SPECULAR_LINE_SHAPE, fit, parse_method
from .data import FITTABLE_QUANTITIES, FitData, FitError
from .objective import GUESSES, Objective
from .result import FitResult
from .uncertainty import AT_BOUND_FRAC, COND_MAX, CORREL_MAX, REL_STDERR_MAX, REL_STDERR_POOR

__all__ = [
    "ALGORITHMS",
    "AT_BOUND_FRAC",
    "COND_MAX",
    "CONSTRAINED",
    "CORREL_MAX",
    "FITTABLE_QUANTITIES",
    "GUESSES",
    "REL_STDERR_MAX",
    "REL_STDERR_POOR",
    "SPECULAR_LINE_SHAPE",
    "FitData",
    "FitError",
    "FitResult",
    "Objective",
    "fit",
    "fit_many",
    "parse_method",
]


class _CallableModule(types.ModuleType):
    """``labbrdf.fit(...)`` keeps working after ``import labbrdf.fit`` rebinds the name.

    Importing the submodule sets the attribute ``labbrdf.fit`` to this module, hiding the
    lazily exported function of the same name; calling the module calls :func:`fit`.
    """

    def __call__(self, *args: Any, **kwargs: Any) -> FitResult:
        return fit(*args, **kwargs)


sys.modules[__name__].__class__ = _CallableModule
