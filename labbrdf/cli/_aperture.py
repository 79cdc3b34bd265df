"""``labbrdf fit --aperture``: which aperture a fit uses, and the fit without it beside.

The aperture is ``--aperture DETECTOR_DEG[,BEAM_DEG]`` when given, else the one the files
state (:func:`labbrdf.fitting.aperture.stated_aperture`); ``--aperture 0`` fits without
one even where a file states one. With an aperture the model is fitted through it
(:class:`labbrdf.models.aperture.Apertured`) and also without it, and the report says how
far each parameter moves.
"""

from __future__ import annotations

import argparse
import math
from typing import Any

from ._options import UsageError


def aperture_value(text: str) -> tuple[float, float]:
    """The argparse type of ``--aperture DETECTOR_DEG[,BEAM_DEG]``: two half-angles [deg]."""
    from ..models.aperture import MAX_APERTURE_DEG

    parts = text.split(",")
    try:
        values = [float(p) for p in parts]
    except ValueError:
        values = []
    if not 1 <= len(parts) == len(values) <= 2:
        raise argparse.ArgumentTypeError(
            f"{text!r}: expected DETECTOR_DEG or DETECTOR_DEG,BEAM_DEG (half-angles [deg])"
        )
    for v in values:
        if not (math.isfinite(v) and 0.0 <= v <= MAX_APERTURE_DEG):
            raise argparse.ArgumentTypeError(
                f"{text!r}: each half-angle must be in [0, {MAX_APERTURE_DEG:g}] deg"
            )
    return values[0], values[1] if len(values) == 2 else 0.0


def chosen_aperture(args: argparse.Namespace, data: Any) -> Any:
    """The :class:`~labbrdf.fitting.aperture.Aperture` of the fit, or None (no aperture).

    ``--aperture`` wins over what the files state (and says so); files that state
    different apertures are refused unless ``--aperture`` is given.
    """
    from ..fitting.aperture import Aperture, ApertureError, stated_aperture

    given = getattr(args, "aperture", None)
    try:
        stated = stated_aperture(data)
    except ApertureError as exc:
        if given is None:
            raise UsageError(str(exc)) from None
        stated = None
    if given is None:
        return stated
    source = "--aperture"
    if stated is not None:
        source += f", overriding {stated.detector_deg:g}, {stated.beam_deg:g} deg {stated.source}"
    return Aperture(given[0], given[1], source=source)


def apertured_options(
    args: argparse.Namespace, model: Any, options: dict[str, Any], aperture: Any
) -> tuple[Any, dict[str, Any]]:
    """The model and options that fit through ``aperture``; a model that cannot is refused.

    ``model`` is None with ``--nk-from`` (built per wavelength from ``options``, which then
    carry the aperture); the check is made on a stand-in index before any fit runs.
    """
    from .. import models
    from ..models.aperture import Apertured

    opts = {**options, **aperture.options()}
    try:
        if model is not None:
            model = Apertured(model, aperture.detector_deg, aperture.beam_deg)
        else:
            models.get(args.model, **{**opts, "n": 1.5, "k": 0.0})
    except models.ModelError as exc:
        raise UsageError(f"--aperture: {exc}") from None
    return model, opts


def aperture_columns(table: Any, aperture: Any) -> Any:
    """The parameter table with the aperture's columns (half-angles and source)."""
    table = table.copy()
    table["aperture_detector_deg"] = aperture.detector_deg
    table["aperture_beam_deg"] = aperture.beam_deg
    table["aperture_source"] = aperture.source
    return table


def aperture_records(
    records: list[dict[str, Any]], aperture: Any, comparisons: list[tuple[dict, Any]]
) -> list[dict[str, Any]]:
    """Each JSON record with ``aperture``: half-angles, source, and the parameters' moves."""
    moves = {repr(sorted(k.items())): c.shifts() for k, c in comparisons}
    redchi = {repr(sorted(k.items())): c.plain.redchi for k, c in comparisons}
    for rec in records:
        key = repr(sorted((rec.get("group") or {}).items()))
        rec["aperture"] = {
            "detector_deg": aperture.detector_deg,
            "beam_deg": aperture.beam_deg,
            "source": aperture.source,
            "redchi_without": redchi.get(key),
            "moves": moves.get(key, {}),
        }
    return records


def print_comparisons(aperture: Any, comparisons: list[tuple[dict, Any]]) -> None:
    """The aperture used and, per group, the parameters with and without it (stdout)."""
    import pandas as pd

    print()
    print(aperture)
    for key, cmp in comparisons:
        group = ", ".join(f"{k}={v}" for k, v in key.items())
        print(
            f"{group}: chi2/nu without the aperture {cmp.plain.redchi:.4g}, with "
            f"{cmp.apertured.redchi:.4g}; parameter moves (without - with, in standard "
            "errors of the apertured fit):"
        )
        with pd.option_context("display.width", 200, "display.max_columns", 20):
            print(cmp.table().to_string(float_format=lambda v: f"{v:.5g}"))
