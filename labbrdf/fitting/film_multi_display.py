"""How a fit of several film samples shows itself: its text report.

Reads a :meth:`labbrdf.fitting.film_multi.MultiFilmFit.summary`, as
:mod:`labbrdf.fitting.film_display` reads a one-sample fit's.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from .film_display import _param_text, _search_text

__all__ = ["multi_fit_report"]


def multi_fit_report(s: Mapping[str, Any]) -> str:
    """The text ``labbrdf film --per-sample`` prints: shared, per sample, the fit, notes."""
    lines = [f"Film fit of {len(s['samples'])} samples (shared model, per-sample parameters)"]
    lines.append("shared:")
    for k, p in s["shared"].items():
        lines.append(f"  {k} = {_param_text(p)}")
    if not s["shared"]:
        lines.append("  (none)")
    for name, smp in s["samples"].items():
        lines.append(f"sample {name} ({', '.join(smp['sources']) or 'data'}):")
        for k, p in smp["parameters"].items():
            lines.append(f"  {k} = {_param_text(p)}")
        lines.append(f"  {smp['n']} points, chi2/N = {smp['chi2_per_point']:.4g}")
    lines.append(
        f"fit: {s['ndata']} points, {s['nvarys']} parameters, chi2/nu = {s['redchi']:.4g}, "
        f"MSE = {s['mse']:.4g}, {_search_text(s)} (seed {s['seed']}), "
        f"intervals: {s['ci_method']}"
    )
    if not s["success"]:
        lines.append(f"  optimiser: {s['message']}")
    lines += [f"note: {n}" for n in s["notes"]]
    lines += [f"warning: {w}" for w in s["warnings"]]
    if s.get("verdict"):
        lines.append(f"VERDICT: {s['verdict']}")
    return "\n".join(lines)
