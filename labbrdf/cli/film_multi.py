"""``labbrdf film --per-sample`` / a model with ``[samples]``: several samples in one fit.

Each FILE is one sample, named by its file name without the suffix (the path as given
where two share a name); a model file's ``[samples]`` table names the samples and their
files instead. The library does the work (:func:`labbrdf.fitting.film_multi.fit_film_samples`).
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from ._options import UsageError, _emit_json, _parse_assignments, _selected


def _per_sample(args: argparse.Namespace) -> list[str]:
    """The names of ``--per-sample P[,P...]`` (repeatable)."""
    return [k for v in args.per_sample or () for k in v.split(",") if k]


def _sample_names(files: list[str]) -> list[str]:
    """One name per file: its stem, or the path as given where two stems are the same."""
    stems = [Path(f).stem for f in files]
    return stems if len(set(stems)) == len(stems) else list(files)


def _samples(args: argparse.Namespace, spec: Any) -> dict[str, Any]:
    """Sample name -> its selected Measurements, from FILE inputs or the model's table."""
    from .. import adapters

    if spec is not None:
        if args.files:
            raise UsageError(
                f"{args.model} names the samples' files in [samples]: give no FILE as well"
            )
        files = {s: [str(p) for p in fs] for s, fs in spec.files.items()}
    else:
        files = {s: [f] for s, f in zip(_sample_names(args.files), args.files, strict=True)}
    return {s: [_selected(args, adapters.read(f)) for f in fs] for s, fs in files.items()}


def cmd_film_samples(
    args: argparse.Namespace, fm: Any, spec: Any, wl_range: tuple[float, float] | None
) -> int:
    """Fit several samples with the model ``fm``; print shared and per-sample parameters.

    ``spec``: the model file's ``[samples]`` (or None); ``wl_range``: ``--wavelength-range``.
    """
    from ..fitting.film_multi import fit_film_samples

    for opt, given in (
        ("--at", args.at),
        ("-o", args.output),
        ("--same-sample", args.same_sample),
    ):
        if given:
            raise UsageError(f"{opt} is for a fit of one sample; not with several samples")
    per = _per_sample(args) or (list(spec.per_sample) if spec is not None else [])
    samples = _samples(args, spec)
    if len(samples) < 2:
        raise UsageError(
            f"--per-sample needs the files of at least two samples, got {len(samples)}"
        )
    res = fit_film_samples(
        fm,
        samples,
        per_sample=per,
        wavelength_range_nm=wl_range,
        default_sigma=_parse_assignments(args.sigma, "--sigma") or None,
        method=args.method,
        seed=args.seed,
        ci=args.ci,
    )
    if args.fit_json:
        res.save_json(args.fit_json)
    if args.json:
        _emit_json(res.summary())
    else:
        print(res.fit_report())
    return 0
