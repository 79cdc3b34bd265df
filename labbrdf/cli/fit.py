"""``labbrdf fit``: fit a model per group (sample, wavelength), refusing bad values first."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from typing import Any

from ._aperture import (
    aperture_columns,
    aperture_records,
    aperture_value,
    apertured_options,
    chosen_aperture,
    print_comparisons,
)
from ._executor import _add_scheduler, _executor, _executor_errors
from ._options import (
    UsageError,
    _add_selection,
    _emit_json,
    _fit_seed,
    _open_fraction,
    _option_errors,
    _parse_assignments,
    _Renamed,
    _selected,
    _split_params,
    _wavelength_value,
)
from ._paths import InputPath, OutputPath, _add_overwrite


def _fit_settings(args: argparse.Namespace) -> tuple[Any, dict[str, Any], dict[str, Any]]:
    """The model (None with ``--nk-from``), its options and the fit keywords of the options.

    Everything that can be refused without the data is refused here, before any work:
    counts, names, and every ``--fix`` and ``--param`` value outside the bounds the model
    declares (:meth:`labbrdf.models.Model.check_value`).
    """
    from .. import models
    from ..fitting.replicates import MAX_REPLICATES

    if args.replicates is not None and not 1 <= args.replicates <= MAX_REPLICATES:
        raise UsageError(
            f"--replicates must be an integer in [1, {MAX_REPLICATES}]; got {args.replicates}"
        )
    if args.wavelength is not None and not args.nk_from:
        raise UsageError(
            "--wavelength NM is the wavelength of --nk-from's n, k; select a range of "
            "rows with --wavelength-range MIN:MAX"
        )
    fix = _parse_assignments(args.fix, "--fix")
    options, start = _split_params(args.model, args.param)
    model = None
    if args.nk_from:
        bounds = _bounds_model(args.model, options, start)
    else:
        try:
            model = bounds = _starts_taken(args.model, options, start)
        except models.ModelError as exc:
            raise UsageError(f"--model {args.model}: {exc} (give options with --param)") from None
        if (args.replicates or 1) > 1 and not model.stochastic:
            raise UsageError(
                f"--replicates {args.replicates}: model {args.model!r} is deterministic (no "
                "Monte Carlo seed), every replicate would be the same fit; leave --replicates out"
            )
    if args.ci != "wald" and (args.replicates or getattr(model, "default_replicates", 1)) > 1:
        raise UsageError(
            f"--ci {args.ci}: seed replicates combine Wald errors; use --ci wald, or "
            "--replicates 1 for one seed with profile intervals"
        )
    _check_values(bounds, fix, start, args.free)
    params: dict[str, Any] = {k: {"value": v} for k, v in start.items()}
    for name in args.free or ():
        params.setdefault(name, {})["vary"] = True
    kw: dict[str, Any] = {"fix": fix or None, "params": params or None, "ci": args.ci}
    if args.replicates is not None:
        kw["replicates"] = args.replicates
    return model, options, kw


def _starts_taken(name: str, options: dict[str, Any], start: dict[str, float]) -> Any:
    """The model ``name`` built with ``options``, less the names it has as parameters.

    A name can be both an option and, with other options, a parameter (layered's
    ``thickness_nm``: the incoherent coating's thickness, and a fitted parameter with
    ``coherent=true``, when the option is unused): there it is the parameter's start value,
    moved from ``options`` into ``start`` (checked against its bounds like any other),
    never an option that is silently ignored. Raises :class:`labbrdf.models.ModelError`
    as the model does.
    """
    from .. import models

    taken = [k for k in options if k in _parameter_names(name, options)]
    for k in taken:
        v = options.pop(k)
        if not isinstance(v, float):
            raise UsageError(f"--param {k}={v}: a parameter of this model: expected a number")
        start[k] = v
    return models.get(name, **options)


def _parameter_names(name: str, options: dict[str, Any]) -> set[str]:
    """The parameters of the model ``name`` with ``options`` (empty if none can be built).

    The words and flags among the options (``coherent``, ``base``, ``diffuse``) choose the
    parameters, not the numbers; so where the numbers are refused (a start value given as
    an option), the model is built without them, with a stand-in index if it needs one.
    """
    from .. import models

    words = {k: v for k, v in options.items() if not isinstance(v, float)}
    for opts in (options, words, {**words, "n": 1.5, "k": 0.0}):
        try:
            return set(models.get(name, **opts).params)
        except (models.ModelError, TypeError):
            continue
    return set()


def _bounds_model(name: str, options: dict[str, Any], start: dict[str, float]) -> Any:
    """The model of ``--nk-from`` with a stand-in index, for its parameters' bounds.

    A model's parameters and bounds do not depend on the index n, k (only on options such
    as ``diffuse`` or ``base``); None where even that model cannot be built (the fit says
    why, per wavelength, before any group is fitted).
    """
    from .. import models

    stand_in = {**options, "n": 1.5, "k": 0.0}
    try:
        model = _starts_taken(name, stand_in, start)
    except (models.ModelError, TypeError):
        return None
    for k in [k for k in options if k not in stand_in]:
        del options[k]
    return model


def _check_values(
    model: Any, fix: dict[str, float], start: dict[str, float], free: Sequence[str] | None
) -> None:
    """Every ``--fix``, ``--param`` value and ``--free`` name checked against ``model``."""
    from ..models import ModelError

    if model is None:
        return
    for option, values in (("--fix", fix), ("--param", start)):
        for name, v in values.items():
            try:
                model.check_value(name, v)
            except ModelError as exc:
                raise UsageError(f"{option} {name}={v:g}: {exc}") from None
    for name in free or ():
        if name not in model.params:
            raise UsageError(
                f"--free {name}: model {model.name!r} has no parameter {name!r}; parameters "
                f"are {list(model.params)}"
            )


def _residual_groups(args: argparse.Namespace, data: Any, by: list[str]) -> None:
    """``--residual-maps`` draws one group: refuse several before any fit runs."""
    from ..fitting.batch import group_keys

    if not args.residual_maps:
        return
    keys = group_keys(data, [*by, "wavelength_nm"] if args.nk_from else by)
    if len(keys) == 1:
        return
    shown = "; ".join(", ".join(f"{k}={v}" for k, v in key.items()) for key in keys[:4])
    more = f" and {len(keys) - 4} more" if len(keys) > 4 else ""
    raise UsageError(
        f"--residual-maps {args.residual_maps}: draws one fitted group; the data hold "
        f"{len(keys)} ({shown}{more}); select one, e.g. with --sample and --wavelength-range, "
        "or leave --residual-maps out"
    )


@_executor_errors
def cmd_fit(args: argparse.Namespace) -> int:
    """Fit ``--model`` to each group of the files; exit 3 if a group fails."""
    from .. import adapters
    from ..fitting import fit_records

    model, options, settings = _fit_settings(args)
    by = [c.strip() for c in args.by.split(",") if c.strip()]
    data = _selected(args, adapters.read_many(args.files))
    _residual_groups(args, data, by)
    aperture = chosen_aperture(args, data)
    plain_model, plain_options = model, options
    if aperture is not None and aperture.active:
        model, options = apertured_options(args, model, options, aperture)
    executor = _executor(args, progress=not args.json)
    kw: dict[str, Any] = {
        **settings,
        "by": by,
        "method": args.method,
        "seed": args.seed,
        "executor": executor,
        "return_results": True,
        "mask_zeros": not args.keep_zeros,
        "relative_floor": args.relative_floor,
        "weighting": args.weighting,
    }
    table, results = _fits(args, data, model, options, kw)
    comparisons: list = []
    if aperture is not None and aperture.active:
        from ..fitting.aperture import compare_groups

        _, plain = _fits(args, data, plain_model, plain_options, kw)
        comparisons = compare_groups(plain, results, aperture)
    if aperture is not None:
        table = aperture_columns(table, aperture)
    if args.output:
        from ..outputs import atomic_output, csv_safe_frame

        with atomic_output(args.output) as tmp:
            csv_safe_frame(table).to_csv(tmp, index=False)
    if args.residual_maps:
        _residual_maps(args, data, results)
    failed = [r for r in table.to_dict("records") if not r["success"]]
    if args.json:
        records = _with_stated(fit_records(table, results, by), data)
        if aperture is not None:
            records = aperture_records(records, aperture, comparisons)
        _emit_json(records)
    else:
        import pandas as pd

        with pd.option_context("display.width", 200, "display.max_columns", 50):
            print(table.to_string(index=False))
        if aperture is not None:
            print_comparisons(aperture, comparisons)
    for r in failed:
        group = ", ".join(f"{b}={r[b]}" for b in by)
        print(f"labbrdf fit: group {group} FAILED: {r['message']}", file=sys.stderr)
    return 3 if failed else 0


def _fits(
    args: argparse.Namespace, data: Any, model: Any, options: dict[str, Any], kw: dict[str, Any]
) -> tuple[Any, list]:
    """The table and results of one model fitted to every group (``--nk-from``: per index)."""
    from ..fitting import fit_many, fit_many_nk

    if args.nk_from:
        with _option_errors():
            return fit_many_nk(
                data,
                args.model,
                args.nk_from,
                options=options,
                wavelength_nm=args.wavelength,
                **kw,
            )
    return fit_many(data, model, **kw)


def _with_stated(records: list[dict[str, Any]], data: Any) -> list[dict[str, Any]]:
    """Each record with ``wavelength_stated``: False where a file of its group states none.

    A ``.bsdf`` states no wavelength; its 555 nm is a label (``export --from-fit`` then
    records the wavelength given with ``--wavelength``, not the label).
    """
    import numpy as np

    parts = data.meta.get("parts")
    if parts:
        unstated = {
            str(p.get("source"))
            for p in parts
            if (p.get("meta") or {}).get("wavelength_stated") is False
        }
    elif data.meta.get("wavelength_stated") is False:  # one file: every row is its
        unstated = set(data.data["source"].astype(str))
    else:
        unstated = set()
    rows = data.data
    for rec in records:
        keep = np.ones(len(rows), bool)
        for col, v in (rec.get("group") or {}).items():
            keep &= (rows[col] == v).to_numpy()
        sources = set(rows.loc[keep, "source"].astype(str))
        rec["wavelength_stated"] = not (sources & unstated)
    return records


def _residual_maps(args: argparse.Namespace, data: Any, results: list) -> None:
    """``--residual-maps PNG``: the maps of the one group (checked before the fit).

    A group that could not be fitted has no maps: said on stderr (the exit code is 3).
    """
    from .. import models
    from ..report.figures import fit_maps_figure, save_png

    if not results:
        print(
            f"labbrdf fit: --residual-maps {args.residual_maps}: not drawn, the group was "
            "not fitted",
            file=sys.stderr,
        )
        return
    key, res = results[0]
    rows = data.data
    for col, v in key.items():
        rows = rows[rows[col] == v]
    rows = rows[rows["quantity"] == res.quantity]
    if res.nmasked:
        rows = rows[rows["value"] != 0]
    model = models.get(res.model, **res.options)
    title = f"{res.model}: " + ", ".join(f"{k}={v}" for k, v in key.items())
    save_png(fit_maps_figure(model, res.values, rows, title=title), args.residual_maps)


def add_parser(sub: Any) -> None:
    """The ``fit`` subcommand's options."""
    from ..fitting.defaults import METHOD

    s = sub.add_parser("fit", help="fit a model per group (sample, wavelength)")
    s.add_argument("files", nargs="+", action=InputPath, metavar="FILE_OR_DATASET")
    s.add_argument("--model", required=True)
    s.add_argument("--by", default="sample,wavelength_nm", help="comma-separated group columns")
    s.add_argument("--method", default=METHOD, help="nlopt GLOBAL[+LOCAL]")
    s.add_argument("--seed", type=_fit_seed, default=0, help="the optimiser's seed")
    s.add_argument(
        "--replicates",
        type=int,
        default=None,
        metavar="R",
        help="fit a Monte Carlo model (layered) with R model seeds and report their mean, "
        "with the seed spread in the standard error (default: the model's, 3 for layered)",
    )
    s.add_argument(
        "--ci",
        choices=("wald", "auto", "profile"),
        default="wald",
        help="95%% intervals: wald (default, from the covariance); auto: wald, then the "
        "profile of chi2 where it can change an interval (at a bound, correlated, chi2 not "
        "quadratic); profile: every parameter's",
    )
    s.add_argument("--fix", action="append", metavar="NAME=VALUE", help="fix a parameter")
    s.add_argument(
        "--param",
        action="append",
        metavar="NAME=VALUE",
        help="a model option (microfacet n=, k=, diffuse=true, distribution=beckmann; "
        "five_param shadowing=mb; "
        "layered base=diffuse, rays=, floor=true) or a parameter's starting value",
    )
    s.add_argument(
        "--free", action="append", metavar="NAME", help="vary a parameter fixed by default"
    )
    s.add_argument(
        "--nk-from",
        action=InputPath,
        default=None,
        metavar="FILE",
        help="n, k from psi/Delta (microfacet)",
    )
    s.add_argument(
        "--wavelength",
        type=_wavelength_value,
        default=None,
        metavar="NM",
        help="[nm] take --nk-from's n, k at this wavelength for every group (needed for "
        "files that state none); default: each group's own",
    )
    s.add_argument("--nk-wavelength", action=_Renamed, new="say --wavelength NM")
    s.add_argument(
        "--weighting",
        choices=["auto", "sigma", "relative", "uniform"],
        default="auto",
        help="auto (the default everywhere: labbrdf.fit, the report): 1/sigma^2 where every "
        "point has sigma, else relative",
    )
    s.add_argument(
        "--relative-floor",
        type=_open_fraction,
        default=1e-3,
        help="floor of --weighting relative, a fraction of the largest absolute value",
    )
    s.add_argument("--keep-zeros", action="store_true", help="fit points with value 0 too")
    s.add_argument(
        "--aperture",
        type=aperture_value,
        default=None,
        metavar="DETECTOR_DEG[,BEAM_DEG]",
        help="fit the model averaged over the detector's cone and the beam's divergence "
        "(half-angles [deg]; default: the aperture the files state, else none; 0: none), and "
        "report how far each parameter moves against the fit without it",
    )
    s.add_argument(
        "-o",
        "--output",
        action=OutputPath,
        suffixes=(".csv",),
        default=None,
        help="write the parameter table (CSV)",
    )
    s.add_argument(
        "--residual-maps",
        action=OutputPath,
        suffixes=(".png",),
        default=None,
        metavar="PNG",
        help="draw measured, model and relative residual per incidence (one fitted group)",
    )
    _add_overwrite(s)
    s.add_argument("--json", action="store_true")
    _add_selection(s, wavelength_taken=True)
    _add_scheduler(s)
    s.set_defaults(func=cmd_fit)
