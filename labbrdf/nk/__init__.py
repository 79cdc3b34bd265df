"""Optical constants from a dataset's psi/Delta rows: tables, reading, lookup, comparisons, plots.

:mod:`~labbrdf.nk.tables` inverts every psi/Delta point to the two-phase pseudo-index
``<N> = n + ik`` and combines the angles of incidence per wavelength (:func:`nk_table`,
:func:`combined_table`, :func:`angle_verdict`, :func:`nk_json`);
:mod:`~labbrdf.nk.reading` reads n, k from files (:func:`read_nk`,
:func:`tabulated_from_file`); :mod:`~labbrdf.nk.lookup` finds a sample's bulk n, k at one
wavelength (:func:`nk_at`, :func:`bulk_index_at`, :func:`model_with_nk`);
:mod:`~labbrdf.nk.compare` predicts reflectances from them to compare with measured rows
(:func:`compare_reflectance`, :func:`microfacet_hemispherical`); :mod:`~labbrdf.nk.plots`
draws them (:func:`nk_panels`, :func:`plot_table`). Dispersion models are
:mod:`labbrdf.dispersion`; a fitted film stack's coating is :mod:`labbrdf.films.coating`.
"""

from __future__ import annotations

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

__all__ = [
    "MAX_TABLE_BYTES",
    "POSITION_TOL_MM",
    "AngleVerdict",
    "NkError",
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
