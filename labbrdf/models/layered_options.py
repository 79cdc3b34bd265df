"""The checked options of the ``layered`` model: distribution, scattering, flags.

Each check raises :class:`~labbrdf.models.base.ModelError` with the option's name, the
value given and what is accepted, so a CLI user gets one line (exit 2).
"""

from __future__ import annotations

import math
from typing import Any

from .base import ModelError

__all__ = ["check_distribution", "check_scattering", "flag", "is_real"]


def check_distribution(name: Any, base: str, coherent: bool) -> str:
    """The checked ``distribution`` option: a registered name, GGX where only GGX is written."""
    from ..microfacet import DISTRIBUTIONS

    if name not in DISTRIBUTIONS:
        raise ModelError(
            f"layered option 'distribution' must be one of {list(DISTRIBUTIONS)}; got {name!r}"
        )
    if name != "ggx" and (base == "diffuse" or coherent):
        reason = (
            "the closed form of a coated Lambertian base is written for GGX"
            if base == "diffuse"
            else "the coherent mode's facets are GGX"
        )
        raise ModelError(
            f"layered option distribution={name!r} needs base='conductor' without "
            f"coherent: {reason}"
        )
    return str(name)


def check_scattering(
    name: Any, base: str, coherent: bool = False, distribution: str = "ggx"
) -> bool:
    """The checked ``scattering`` option; True for multiple scattering on the top.

    Over a conductor, multiple scattering is traced with the evaluated estimator
    (``docs/tracer.md``), which needs the incoherent coating's GGX top.
    """
    if name not in ("single", "multiple"):
        raise ModelError(
            f"layered option 'scattering' must be 'single' or 'multiple'; got {name!r}"
        )
    if name == "multiple" and base != "diffuse" and (coherent or distribution != "ggx"):
        raise ModelError(
            "layered option scattering='multiple' over a conductor needs the incoherent "
            "coating with distribution='ggx' (its single events have closed forms there; "
            "docs/tracer.md)"
        )
    return name == "multiple"


def flag(v: Any, name: str) -> bool:
    """A true/false option given as a bool or as the text "true" / "false"."""
    if isinstance(v, bool):
        return v
    if isinstance(v, str) and v.lower() in ("true", "false"):
        return v.lower() == "true"
    raise ModelError(f"layered option {name!r} must be true or false; got {v!r}")


def is_real(v: Any) -> bool:
    """Whether ``v`` is a finite real number (not a bool)."""
    return isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v)
