"""The registry of microfacet distributions: name -> the module that defines it.

Every distribution module defines the same names (:data:`REQUIRED`): ``NAME``, ``LABEL``,
``TABLE_EXTENT``, ``TRACED_IN_CLOSED_FORM``, the distribution of normals ``d``, the Smith
``smith_lambda`` and ``smith_g1``, the slope densities ``p22``, ``p2`` and
``radial_density``, and what the slope fit of a height map needs (``ml_s``,
``log_likelihood``, ``ks_cdf``, ``fisher_information``). A distribution the tracer samples
in closed form (``TRACED_IN_CLOSED_FORM``) also defines ``sample_visible``; the others are
traced through their slope table (:meth:`labbrdf.microfacet.TabulatedNDF.of`).

A new distribution is its module plus one line in :data:`DISTRIBUTIONS`; what does not
depend on its formulas (G1 from Lambda, Lambda below the horizon, the root of a score
equation) it takes from :mod:`labbrdf.microfacet.parts`.
"""

from __future__ import annotations

from types import ModuleType

from . import beckmann, ggx

__all__ = ["DISTRIBUTIONS", "REQUIRED", "get", "names"]

#: name -> distribution module, in the order the fits and reports list them
DISTRIBUTIONS: dict[str, ModuleType] = {
    "ggx": ggx,
    "beckmann": beckmann,
}

#: names every distribution module defines
REQUIRED = (
    "NAME",
    "LABEL",
    "TABLE_EXTENT",
    "TRACED_IN_CLOSED_FORM",
    "d",
    "smith_lambda",
    "smith_g1",
    "p22",
    "p2",
    "radial_density",
    "ml_s",
    "log_likelihood",
    "ks_cdf",
    "fisher_information",
)


def get(name: str) -> ModuleType:
    """The distribution module registered as ``name``.

    Raises
    ------
    KeyError
        An unknown name; the message lists the registered ones.
    """
    try:
        return DISTRIBUTIONS[name]
    except KeyError:
        raise KeyError(
            f"unknown microfacet distribution {name!r}; expected one of {', '.join(names())}"
        ) from None


def names() -> tuple[str, ...]:
    """The registered names, in registry order."""
    return tuple(DISTRIBUTIONS)
