"""Thin films as objects: layers of materials in a stack, model files, fit JSON.

Physics at the bottom, objects above it, no workflow: :mod:`~labbrdf.films.matrices` (the
transfer matrices, the one coherent multilayer) and :mod:`~labbrdf.films.onefilm` (one film
on a substrate, coherent and incoherent) build on :mod:`labbrdf.optics`;
:mod:`~labbrdf.films.materials` and :mod:`~labbrdf.films.layers` make the
:class:`Stack` (:mod:`~labbrdf.films.stack`), which computes psi/Delta, reflectance and
transmittance from :mod:`labbrdf.nk.dispersion` materials; :mod:`~labbrdf.films.model` adds the
search box of a fit, :mod:`~labbrdf.films.modelfile` reads it from TOML,
:mod:`~labbrdf.films.fitjson` checks a fit's JSON, and :mod:`~labbrdf.films.limits` holds
the caps all of them check (a fitted one-layer stack becomes the tracer's coating in
:mod:`labbrdf.sample.coating`). The film fit, a workflow above these objects, is
:func:`labbrdf.fitting.film.fit_film` (also ``labbrdf.fit_film``).

Thick layers and a finite substrate add in intensity (:mod:`~labbrdf.films.incoherent`,
``Layer(..., coherent=False)``, ``Stack(..., substrate_thickness_nm=...)``); interface layers
are Bruggeman mixtures of two or three materials (:class:`Ema`), a graded layer varies a
parameter through its thickness (:class:`Graded`), and a thickness spread over the spot
depolarizes (:mod:`~labbrdf.films.nonuniform`, ``Stack(..., thickness_spread=...)``), as
the instrument's bandwidth and angle spread do (:mod:`~labbrdf.films.spreads`,
``Stack(..., bandwidth_nm=..., angle_spread_deg=...)``).

Parameter names are ``"<layer>.<parameter>"``: ``"oxide.thickness_nm"``, ``"oxide.A"``,
``"substrate.omega_p"``, ``"rough.fraction"``, ``"stack.thickness_spread"``.

>>> from labbrdf.films import Layer, Stack
>>> s = Stack([Layer("sio2", 2.0, name="oxide")], substrate="si")
>>> psi, delta = s.psi_delta(633.0, 70.0)
"""

from __future__ import annotations

from .ema import Ema
from .graded import Graded
from .layers import Layer
from .limits import (
    FILM_QUANTITIES,
    MAX_FIT_JSON_BYTES,
    MAX_INDEX,
    MAX_LAYERS,
    MAX_MODEL_BYTES,
    MAX_TABLE_POINTS,
    MAX_THICKNESS_NM,
    NK_REPORT_NM,
    WAVELENGTH_LIMITS_NM,
    FilmError,
    check_wavelength_range,
)
from .materials import Material, Roughness, as_material
from .model import FilmModel
from .modelfile import load_model, load_samples, named_inputs
from .stack import Stack, read_fit_json

__all__ = [
    "FILM_QUANTITIES",
    "MAX_FIT_JSON_BYTES",
    "MAX_INDEX",
    "MAX_LAYERS",
    "MAX_MODEL_BYTES",
    "MAX_TABLE_POINTS",
    "MAX_THICKNESS_NM",
    "NK_REPORT_NM",
    "WAVELENGTH_LIMITS_NM",
    "Ema",
    "FilmError",
    "FilmModel",
    "Graded",
    "Layer",
    "Material",
    "Roughness",
    "Stack",
    "as_material",
    "check_wavelength_range",
    "load_model",
    "load_samples",
    "named_inputs",
    "read_fit_json",
]
