"""Tracer runs as the report's sections make them: on the report's executor, and their maps.

Shared by the sections that trace (``tracer_*``, ``surface``, ``prediction``,
``model_measurement``); the sections themselves do not import each other.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from typing import Any

import numpy as np

from ..prediction import DEFAULT_RAYS
from ..tracer import TraceConfig, TraceResult, trace
from ..tracer.result import MIN_COUNT
from .context import Context

__all__ = ["maps", "rays_of", "robust_max", "run_trace", "tracer_map"]


def robust_max(res: TraceResult, s0: np.ndarray) -> float | None:
    """Largest S0 [sr^-1] over the bins with at least ``MIN_COUNT`` rays (None if none)."""
    ok = res.counts >= MIN_COUNT
    return float(s0[ok].max()) if ok.any() else None


def tracer_map(ctx: Context) -> Callable[..., Iterable[Any]]:
    """The ordered ``map`` that runs tracer work units on the report's executor (no bar)."""
    return ctx.executor.with_progress(False)


def run_trace(ctx: Context, config: TraceConfig) -> TraceResult:
    """:func:`labbrdf.tracer.trace` of ``config`` on the report's executor."""
    return trace(config, map=tracer_map(ctx))


def maps(result: TraceResult) -> dict[str, np.ndarray]:
    """S0 [sr^-1] and DOP [1] maps for unpolarized input, bin edges and centres [deg]."""
    return {
        "s0": result.s0(),
        "dop": result.dop(),
        "theta_edges": result.theta_r_edges_deg,
        "phi_edges": result.phi_r_edges_deg,
        "theta": result.theta_r_deg,
        "phi": result.phi_r_deg,
    }


def rays_of(ctx: Context) -> int:
    """Tracer rays per run: the report's ``scale["prediction"]`` (validation), else the default."""
    return int(ctx.scale.get("prediction", DEFAULT_RAYS))
