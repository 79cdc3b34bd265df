"""Figures of the report: matplotlib (Agg backend), returned as base64 PNG data URIs.

Every function takes plain arrays and labels (never file text into code paths other than
labels, which matplotlib draws as text), labels its axes with units, and returns a
``data:image/png;base64,...`` string. Figures are closed after rendering.

One module per figure family; this package holds their names:

* ``_common``: the Agg backend, layout, :func:`to_uri`,
  :func:`save_png`;
* :mod:`~labbrdf.report.figures.scans`: measured scans beside fitted models;
* :mod:`~labbrdf.report.figures.spectra`: curves against wavelength and plain x-y curves;
* :mod:`~labbrdf.report.figures.panels`: grids of panels of measured data, stage maps;
* :mod:`~labbrdf.report.figures.brdf_maps`: measured hemispherical BRDF against a model;
* :mod:`~labbrdf.report.figures.surface`: a measured surface's map, ACF and slopes;
* :mod:`~labbrdf.report.figures.tracer`: the tracer's S0 and DOP hemisphere maps.
"""

from __future__ import annotations

from ._common import save_png, to_uri
from .brdf_maps import (
    brdf_cuts_figure,
    brdf_maps_figure,
    brdf_residual_grid_figure,
    fit_maps_figure,
)
from .panels import map_figure, panels_figure, reflectance_comparison_figure
from .scans import compare_models_figure, scan_figure
from .spectra import hemispherical_figure, spectra_figure, spectrum_figure, xy_figure
from .surface import height_map_image, surface_figure
from .tracer import polar_maps_figure, save_trace_maps_png

__all__ = [
    "brdf_cuts_figure",
    "brdf_maps_figure",
    "brdf_residual_grid_figure",
    "compare_models_figure",
    "fit_maps_figure",
    "height_map_image",
    "hemispherical_figure",
    "map_figure",
    "panels_figure",
    "polar_maps_figure",
    "reflectance_comparison_figure",
    "save_png",
    "save_trace_maps_png",
    "scan_figure",
    "spectra_figure",
    "spectrum_figure",
    "surface_figure",
    "to_uri",
    "xy_figure",
]
