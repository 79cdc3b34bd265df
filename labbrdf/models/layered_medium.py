"""The scattering coating of the ``layered`` model: its option and its parameters.

``medium=True`` fills the coating with a homogeneous Henyey-Greenstein medium
(:class:`labbrdf.tracer.Medium`, :mod:`labbrdf.tracer.medium`) and adds its parameters:
``medium_tau`` [1] in [0.01, 10] (log), the optical thickness along the normal;
``medium_ssa`` [1] in [0, 1], the single-scattering albedo; ``medium_g`` [1] in
[-0.5, 0.95], the HG asymmetry (> 0 forward). The medium is traced with the evaluated
estimator over either base: a diffuse base then goes through the walk (``rays``, seed
replicates, Monte Carlo error), not the renewal closed form
(:mod:`labbrdf.tracer.coated_lambert`), which holds for a clear coating only: through a
medium a ray reaches the top from below in a direction the medium chose, not with the
cosine law. Either scattering on the top (multiple: the evaluated multiple-scattering
walk); the incoherent mode only.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from .base import Model, ModelError, Parameters

__all__ = ["MEDIUM_NAMES", "add_medium_params", "medium_of", "medium_option"]

#: the parameters of a scattering coating
MEDIUM_NAMES = ("medium_tau", "medium_ssa", "medium_g")


def medium_option(model: Model, medium: Any, scattering: Any, closed: bool) -> bool:
    """Check the ``medium`` option, set ``model._medium``; whether the model stays closed.

    ``closed``: whether it is evaluated in closed form without the medium. With a medium
    the model is traced: ``stochastic``, ``fd_rel_step`` and ``default_replicates`` go
    back to the traced model's class values and the answer is False.
    """
    if isinstance(medium, str) and medium.lower() in ("true", "false"):
        medium = medium.lower() == "true"
    if not isinstance(medium, bool):
        raise ModelError(f"layered option 'medium' must be true or false; got {medium!r}")
    model._medium = medium  # type: ignore[attr-defined]  # Model has no such field
    if not medium:
        return closed
    if getattr(model, "_coherent", False):
        raise ModelError(
            "layered option medium=True needs the incoherent coating: the coherent film "
            "has no volume to scatter in"
        )
    cls = type(model)
    model.fd_rel_step = cls.fd_rel_step
    model.stochastic = True
    model.default_replicates = cls.default_replicates
    return False


def add_medium_params(p: Parameters) -> None:
    """Add the scattering coating's parameters (module docstring) to ``p``."""
    p.add(
        "medium_tau",
        0.5,
        0.01,
        10.0,
        units="1",
        log=True,
        description="optical thickness of the coating's scattering medium (normal)",
    )
    p.add(
        "medium_ssa",
        0.9,
        0.0,
        1.0,
        units="1",
        description="single-scattering albedo of the coating's medium",
    )
    p.add(
        "medium_g",
        0.3,
        -0.5,
        0.95,
        units="1",
        description="Henyey-Greenstein asymmetry of the coating's medium",
    )


def medium_of(p: Mapping[str, float]) -> Any:
    """The :class:`labbrdf.tracer.Medium` of the parameter values ``p``."""
    from ..tracer import Medium

    return Medium(float(p["medium_tau"]), float(p["medium_ssa"]), float(p["medium_g"]))
