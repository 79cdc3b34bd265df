"""Optical constants from a dataset's psi/Delta rows: tables, reading, lookup, comparisons, plots.

:mod:`~labbrdf.nk.tables` inverts every psi/Delta point to the two-phase pseudo-index
``<N> = n + ik`` and combines the angles of incidence per wavelength (:func:`nk_table`,
:func:`combined_table`, :func:`angle_verdict`, :func:`nk_json`);
:mod:`~labbrdf.nk.reading` reads n, k from files (:func:`read_nk`,
:func:`tabulated_from_file`); :mod:`~labbrdf.nk.lookup` finds a sample's bulk n, k at one
wavelength (:func:`nk_at`, :func:`bulk_index_at`, :func:`model_with_nk`);
:mod:`~labbrdf.nk.compare` predicts reflectances from them to compare with measured rows
(:func:`compare_reflectance`, :func:`microfacet_hemispherical`); :mod:`~labbrdf.nk.plots`
draws them (:func:`nk_panels`, :func:`plot_table`); :mod:`~labbrdf.nk.dispersion` holds the
dispersion models, one module each behind a registry. A fitted film stack's coating is
:mod:`labbrdf.sample.coating`.

The names are imported on first use (PEP 562), so the physics below, the dispersion models,
imports without pandas or the file readers.
"""

from __future__ import annotations

from importlib import import_module
from typing import TYPE_CHECKING, Any

#: public name -> the module of this package that defines it
_LAZY = {
    "MAX_TABLE_BYTES": "reading",
    "NkError": "reading",
    "read_nk": "reading",
    "tabulated_from_file": "reading",
    "POSITION_TOL_MM": "tables",
    "AngleVerdict": "tables",
    "angle_verdict": "tables",
    "combined_table": "tables",
    "nk_json": "tables",
    "nk_table": "tables",
    "ordinary_psi_delta": "tables",
    "bulk_index_at": "lookup",
    "model_with_nk": "lookup",
    "nk_at": "lookup",
    "compare_reflectance": "compare",
    "microfacet_hemispherical": "compare",
    "nk_panels": "plots",
    "plot_table": "plots",
    "series_members": "plots",
}
_SUBMODULES = ("compare", "dispersion", "lookup", "plots", "reading", "tables")

__all__ = [
    "AngleVerdict",
    "MAX_TABLE_BYTES",
    "NkError",
    "POSITION_TOL_MM",
    "angle_verdict",
    "bulk_index_at",
    "combined_table",
    "compare_reflectance",
    "microfacet_hemispherical",
    "model_with_nk",
    "nk_at",
    "nk_json",
    "nk_panels",
    "nk_table",
    "ordinary_psi_delta",
    "plot_table",
    "read_nk",
    "series_members",
    "tabulated_from_file",
]

if TYPE_CHECKING:
    from .compare import compare_reflectance, microfacet_hemispherical
    from .lookup import bulk_index_at, model_with_nk, nk_at
    from .plots import nk_panels, plot_table, series_members
    from .reading import MAX_TABLE_BYTES, NkError, read_nk, tabulated_from_file
    from .tables import (
        POSITION_TOL_MM,
        AngleVerdict,
        angle_verdict,
        combined_table,
        nk_json,
        nk_table,
        ordinary_psi_delta,
    )


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        value = getattr(import_module(f"{__name__}.{_LAZY[name]}"), name)
        globals()[name] = value
        return value
    if name in _SUBMODULES:
        return import_module(f"{__name__}.{name}")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted({*globals(), *_LAZY, *_SUBMODULES})
