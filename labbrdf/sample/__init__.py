"""A sample built from its files: substrate index, facets, coating and tracer run.

The one place where a lab's files of one sample (an ellipsometer file, a height map, a film
fit) become the tracer's :class:`~labbrdf.Substrate`, :class:`~labbrdf.Coating` and
:class:`~labbrdf.TraceConfig`. ``labbrdf trace``, the report's tracer maps and the prediction
(:mod:`labbrdf.prediction`) build theirs here. The layered BRDF model, which reads no file,
builds its runs from values with the same constructors; it sits below this package, which
reads files through the optical-constant tables (:mod:`labbrdf.nk`) above the models.

- :mod:`.index`: the bulk ``n + ik`` of psi/Delta at a wavelength (:func:`bulk_index`,
  :func:`substrate_nk`);
- :mod:`.slopes`: a height map read for the tracer, its GGX alpha and slope table, a
  substrate with its facets (:func:`roughness_alpha`, :func:`slope_table`,
  :func:`measured_substrate`);
- :mod:`.coating`: the coating of a one-layer film fit (:func:`coating_from_fit`,
  :func:`coating_of_stack`, :func:`film_coating`);
- :mod:`.run`: a whole run from values and files (:func:`trace_config_from_inputs`).

Errors of files that cannot make a sample are :class:`labbrdf.errors.SampleError` (naming
the file); arguments that do not fit together :class:`labbrdf.errors.SetupError`.
"""

from __future__ import annotations

from .coating import coating_from_fit, coating_of_stack, film_coating
from .index import bulk_index, substrate_nk
from .run import trace_config_from_inputs
from .slopes import measured_substrate, roughness_alpha, slope_table

__all__ = [
    "bulk_index",
    "coating_from_fit",
    "coating_of_stack",
    "film_coating",
    "measured_substrate",
    "roughness_alpha",
    "slope_table",
    "substrate_nk",
    "trace_config_from_inputs",
]
