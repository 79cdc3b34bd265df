"""``labbrdf film-map``: fit one film model to every point of a wafer map."""

from __future__ import annotations

import argparse
from typing import Any

from ._executor import _add_scheduler, _executor
from ._options import UsageError, _emit_json, _fit_seed, _parse_assignments, _range
from ._paths import InputPath, OutputPath, _add_overwrite


def cmd_film_map(args: argparse.Namespace) -> int:
    """Fit the model to each listed point; print the map's table, write its CSV and PNG."""
    from ..fitting.film_map import fit_film_map

    wl_range = None
    if args.wavelength_range is not None:
        from ..selection import parse_range

        r = parse_range(args.wavelength_range, "--wavelength-range")
        if not 0 <= r.lo < r.hi:
            raise UsageError(
                f"--wavelength-range {args.wavelength_range}: expected MIN:MAX with "
                "0 <= MIN < MAX [nm]"
            )
        wl_range = (r.lo, r.hi)
    res = fit_film_map(
        args.model,
        args.listing,
        executor=_executor(args, progress=not args.json),
        wavelength_range_nm=wl_range,
        default_sigma=_parse_assignments(args.sigma, "--sigma") or None,
        method=args.method,
        seed=args.seed,
        ci=args.ci,
    )
    if args.output:
        res.save_csv(args.output)
    if args.png:
        res.save_png(args.png)
    if args.json:
        _emit_json({"points": res.table.to_dict(orient="records")})
    else:
        print(res.fit_report())
    return 0


def add_parser(sub: Any) -> None:
    """The ``film-map`` subcommand's options."""
    from ..fitting.defaults import METHOD

    s = sub.add_parser(
        "film-map", help="fit a film model to every point of a wafer map (thickness, index maps)"
    )
    s.add_argument(
        "listing",
        action=InputPath,
        inside="map",
        metavar="MAP.csv",
        help="CSV with columns file,x,y: each point's file (relative to the CSV) and its "
        "position [mm]",
    )
    s.add_argument(
        "--model",
        action=InputPath,
        inside="model",
        required=True,
        metavar="MODEL.toml",
        help="the film model file every point is fitted with",
    )
    s.add_argument(
        "--sigma",
        action="append",
        metavar="QUANTITY=VALUE",
        help="sigma for rows that have none (e.g. reflectance=0.005)",
    )
    s.add_argument(
        "--wavelength-range",
        type=_range,
        default=None,
        metavar="MIN:MAX",
        help="fit only these [nm]",
    )
    s.add_argument(
        "--ci",
        choices=("wald", "profile"),
        default="wald",
        help="95%% intervals from the covariance (default) or the profile of chi2",
    )
    s.add_argument("--method", default=METHOD, help="nlopt stages")
    s.add_argument("--seed", type=_fit_seed, default=0, help="the optimiser's seed (every point)")
    s.add_argument(
        "-o",
        "--output",
        action=OutputPath,
        suffixes=(".csv",),
        default=None,
        metavar="TABLE.csv",
        help="write the map's table (one row per point)",
    )
    s.add_argument(
        "--png",
        action=OutputPath,
        suffixes=(".png",),
        default=None,
        metavar="MAP.png",
        help="write the thickness and index maps",
    )
    _add_overwrite(s)
    s.add_argument("--json", action="store_true")
    _add_scheduler(s)
    s.set_defaults(func=cmd_film_map)
