"""Microfacet distributions, defined once: GGX, Beckmann and tabulated (measured) slopes.

Physics layer: numpy and scipy only, no file reading. Each analytic distribution is one
module (:mod:`~labbrdf.microfacet.ggx`, :mod:`~labbrdf.microfacet.beckmann`) registered in
:data:`DISTRIBUTIONS`; the models, the tracer and the slope fits of height maps read them
from there. :class:`TabulatedNDF` is a distribution given by a table of its slope density
(a measured height map's slopes, or an analytic P22); :mod:`~labbrdf.microfacet.height`
holds the Smith height walk the tracer's multiple scattering uses.
"""

from __future__ import annotations

from . import beckmann, ggx, height
from .registry import DISTRIBUTIONS, get, names
from .tabulated import TabulatedNDF

__all__ = ["DISTRIBUTIONS", "TabulatedNDF", "beckmann", "get", "ggx", "height", "names"]
