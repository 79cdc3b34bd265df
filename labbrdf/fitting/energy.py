"""The energy constraint of a fit: the hemispherical reflectance rho(theta_i) <= 1.

Either an nlopt inequality constraint on the search vector (``_energy_cons``) or, when
one profiled amplitude carries it, an upper bound on that amplitude (``_energy_bound``:
rho is linear in it); ``_energy_check`` records the constraint at the answer
(docs/models.md 5.5).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..models import Model
from .data import FitError
from .objective import Objective


def _energy_rho(
    model: Model, energy: bool | Callable[..., ArrayLike]
) -> Callable[[dict[str, float], NDArray], NDArray]:
    if callable(energy):
        return lambda vals, th: np.asarray(energy(vals, th), float)
    try:
        from ..integrate import hemispherical_reflectance
    except ImportError as exc:  # pragma: no cover - integrate ships with labbrdf
        raise FitError("energy_constraint=True needs labbrdf.integrate") from exc
    return lambda vals, th: np.asarray(hemispherical_reflectance(model, vals, th), float)


def _energy_cons(
    obj: Objective, rho_fn: Callable[[dict[str, float], NDArray], NDArray], th_grid: NDArray
) -> Callable[[NDArray], float]:
    """The nlopt inequality constraint ``max rho(theta) - 1 <= 0`` on the search vector."""

    def cons(xx: NDArray) -> float:
        return float(np.max(rho_fn(obj.from_vector(xx), th_grid)) - 1.0)

    return cons


def _energy_check(
    rho_fn: Callable[[dict[str, float], NDArray], NDArray],
    vals: dict[str, float],
    th_grid: NDArray,
    success: bool,
    message: str,
) -> tuple[dict[str, Any], bool, str]:
    """The energy record of a constrained fit; a violated constraint makes it fail."""
    rho_max = float(np.max(rho_fn(vals, th_grid)))
    info = {"theta_i_deg": th_grid.tolist(), "max_rho": rho_max, "active": rho_max > 1 - 1e-6}
    if rho_max > 1 + 1e-6:
        return info, False, f"energy constraint violated (max rho {rho_max:.6g}); " + message
    return info, success, message


def _energy_bound(
    rho_fn: Callable[[dict[str, float], NDArray], NDArray], k_lin: str, th_grid: NDArray
) -> Callable[[dict[str, float]], float]:
    """Upper bound on the one profiled amplitude from rho(theta) <= 1 (rho is linear in it)."""

    def upper(vals: dict[str, float]) -> float:
        r1 = rho_fn({**vals, k_lin: 1.0}, th_grid)
        r0 = rho_fn({**vals, k_lin: 0.0}, th_grid)
        if not (np.all(np.isfinite(r1)) and np.all(np.isfinite(r0))):
            return 0.0
        slope = r1 - r0
        with np.errstate(divide="ignore", invalid="ignore"):
            ub = np.where(slope > 0, (1.0 - r0) / slope, np.inf)
        return float(np.min(ub))

    return upper
