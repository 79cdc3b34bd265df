"""Dispersion models: a material's complex index ``N = n + ik`` as a function of wavelength.

Physics layer: NumPy only, and no file is read here (a table from a file or an ellipsometer
export is built by :func:`labbrdf.nk.tabulated_from_file`). One module per model, each a
small frozen dataclass (:class:`Dispersion`, :mod:`~labbrdf.nk.dispersion.base`) of named
parameters with

* ``.nk(wavelength_nm) -> complex ndarray`` (``n + ik``, ``k >= 0``, vacuum wavelength in
  nm) and ``.eps(wavelength_nm)`` (``eps = N^2``);
* ``.params`` (name -> value) and ``Model.from_params(mapping)``;
* ``.bounds()`` (name -> (min, max)): the default search box of a fit;
* ``.to_dict()`` / :func:`from_dict` (JSON-safe, used by model files and fit results).

:data:`MODELS` (:mod:`~labbrdf.nk.dispersion.registry`) maps registry names to the classes:
a new model is its module and one line there (docs/howto-dispersion.md). Photon energy
``E [eV] = HC_EV_NM / lambda [nm]``. The time dependence is ``exp(-i omega t)`` (labbrdf's
convention), so a passive medium has ``Im(eps) >= 0``; oscillator formulas written for
``exp(+i omega t)`` in their papers are conjugated here (each docstring says so).
"""

from __future__ import annotations

from .base import HC_EV_NM, Dispersion, DispersionError
from .bspline import BSpline
from .cauchy import Cauchy
from .cody_lorentz import CodyLorentz
from .composite import Sum
from .constant import Constant
from .drude import Drude
from .gaussian import Gaussian
from .lorentz import Lorentz
from .registry import MODELS, from_dict
from .sellmeier import Sellmeier
from .tabulated import REFERENCE_TABLES, Tabulated, parse_nk_table
from .tauc_lorentz import TaucLorentz

__all__ = [
    "HC_EV_NM",
    "MODELS",
    "REFERENCE_TABLES",
    "BSpline",
    "Cauchy",
    "CodyLorentz",
    "Constant",
    "Dispersion",
    "DispersionError",
    "Drude",
    "Gaussian",
    "Lorentz",
    "Sellmeier",
    "Sum",
    "Tabulated",
    "TaucLorentz",
    "from_dict",
    "parse_nk_table",
]
