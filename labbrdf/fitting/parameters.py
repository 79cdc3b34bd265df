"""The parameters of a fit: the model's, with the caller's values and fixes, checked.

``_params`` applies ``params`` and ``fix`` to a copy of the model's parameters
and refuses what cannot be searched; ``_apply_guess`` starts the free ones at the
model's data-driven guess; ``_check_design`` refuses data that cannot identify them;
``_seed`` checks the optimiser's seed.
"""

from __future__ import annotations

import copy
import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from ..models import Model, ModelError, Parameters
from .data import FitData, FitError
from .defaults import MAX_SEED

__all__ = ["check_seed", "setup_params"]


def check_seed(seed: Any) -> int:
    """``seed`` as an int, if it is an integer in ``[0, MAX_SEED]``; else :class:`FitError`."""
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)):
        raise FitError(f"seed must be an integer in [0, {MAX_SEED}]; got {seed!r}")
    if not 0 <= seed <= MAX_SEED:
        raise FitError(f"seed must be an integer in [0, {MAX_SEED}]; got {seed}")
    return int(seed)


def _copy_params(p: Parameters) -> Parameters:
    """A copy whose Parameter objects are new (fields are immutable or replaced, not mutated)."""
    return Parameters({k: copy.copy(q) for k, q in p.items()})


def setup_params(
    model: Model, params: Parameters | Mapping[str, float] | None, fix: Mapping[str, float] | None
) -> Parameters:
    """The model's parameters with ``params`` (values or Parameters) and ``fix`` applied.

    Internal API of :mod:`labbrdf.fitting`; raises :class:`FitError` naming unknown or
    inconsistent parameter names, and a value given in ``params`` or ``fix`` that is not
    finite or lies outside the parameter's bounds (:meth:`Parameter.check
    <labbrdf.models.Parameter.check>`: the model's, or those given in ``params``).
    """
    p = _copy_params(model.params)
    given: list[tuple[str, str, Any]] = []  # (argument, name, value) to check in bounds
    if params is not None:
        for k, v in params.items():
            if k not in p:
                raise FitError(
                    f"params: model {model.name!r} has no parameter {k!r}; "
                    f"parameters are {list(p)}"
                )
            if isinstance(v, Mapping) or hasattr(v, "vary"):
                src = v if isinstance(v, Mapping) else v.__dict__
                for a in ("value", "min", "max", "vary", "log"):
                    if a in src:
                        setattr(p[k], a, src[a])
                if "value" in src:
                    given.append(("params", k, src["value"]))
            else:
                given.append(("params", k, v))
    for k, v in (fix or {}).items():
        if k not in p:
            raise FitError(
                f"fix: model {model.name!r} has no parameter {k!r}; parameters are {list(p)}"
            )
        given.append(("fix", k, v))
        p[k].vary = False
    for arg, k, v in given:
        try:
            p[k].value = p[k].check(v)
        except ModelError as exc:
            raise FitError(f"{arg}: model {model.name!r}: {exc}") from None
    for k, q in p.items():
        if not math.isfinite(q.value):
            raise FitError(f"parameter {k!r}: initial value {q.value!r} is not finite")
        if q.vary:
            if q.min >= q.max:
                raise FitError(f"parameter {k!r}: min {q.min} must be < max {q.max} to vary")
            if q.log and not q.min > 0:
                raise FitError(f"parameter {k!r}: a log-scale search needs min > 0, got {q.min}")
            q.value = min(max(q.value, q.min), q.max)
    return p


def _apply_guess(model: Model, fd: FitData, p: Parameters, given: set[str]) -> bool:
    """Start varying parameters not set by the caller at the model's own guess."""
    with np.errstate(all="ignore"):
        g = model.guess(
            np.radians(np.asarray(fd.theta_i_deg, dtype=float)),
            np.radians(np.asarray(fd.theta_r_deg, dtype=float)),
            np.asarray(fd.value, dtype=float),
        )
    if not g:
        return False
    used = False
    for k, v in g.items():
        q = p[k]
        if q.vary and k not in given and math.isfinite(v) and q.min < v < q.max:
            q.value = float(v)
            used = True
    return used


def _check_design(model: Model, fd: FitData, varying: list[str]) -> None:
    """Refuse designs that cannot identify the free parameters."""
    if not varying:
        raise FitError("nothing to fit: every parameter is fixed")
    n_pts, nvarys = len(fd), len(varying)
    if n_pts <= nvarys:
        raise FitError(
            f"data: {n_pts} point(s) for {nvarys} free parameter(s) {varying}; "
            f"need at least {nvarys + 1} to fit and estimate uncertainties"
        )
    shape = [k for k in model.specular_line_shape if k in varying]
    on_line = np.abs(np.asarray(fd.theta_r_deg) - np.asarray(fd.theta_i_deg)) < 1e-9
    if shape and on_line.all():
        raise FitError(
            f"data: all {n_pts} points lie on the specular line theta_r == theta_i, where "
            f"{model.name} identifies only k1 exp(-k2^2/k3^2) (docs/models.md 1.1); "
            f"add off-specular points or fix {list(model.specular_line_shape)}, "
            "e.g. fix={'k2': 0.0, 'k3': 0.4}"
        )
