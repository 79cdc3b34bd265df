"""``labbrdf report``: the HTML report of the user's own files."""

from __future__ import annotations

import argparse
import os
from typing import Any

from ._executor import _add_scheduler, _executor, _executor_errors
from ._options import (
    UsageError,
    _add_selection,
    _selection,
    _split_params,
    _wavelength_value,
)
from ._paths import InputPath, OutputPath, _add_overwrite


@_executor_errors
def cmd_report(args: argparse.Namespace) -> int:
    """Write the HTML report of the files; exit 1 if a check failed."""
    from ..report import user_report
    from ..report.sections.film import default_film_model
    from ..samples import split_same_sample

    film_files = None
    if args.film_files is not None:
        film_files = split_same_sample(args.film_files, args.files)
        inputs = {os.path.realpath(p) for p in args.files}
        stray = [str(f) for f in film_files if os.path.realpath(f) not in inputs]
        if stray:
            raise UsageError(
                f"--film-files: {', '.join(stray)} is not among the input files (give the "
                "files of the coated sample as they are given as DATA)"
            )
    executor = _executor(args, progress=not args.quiet)
    options, start = _split_params(args.model, args.param)
    selection = _selection(args)
    return int(
        user_report(
            args.files,
            args.model,
            args.output,
            options=options,
            start=start,
            selection=selection,
            progress=not args.quiet,
            film_model=default_film_model() if args.film_default else args.film_model,
            executor=executor,
            same_sample=[split_same_sample(v, args.files) for v in args.same_sample or ()],
            prediction_slopes=args.prediction_slopes,
            nk_from=args.nk_from,
            film_files=film_files,
            wavelength_nm=args.wavelength,
        )
    )


def add_parser(sub: Any) -> None:
    """The ``report`` subcommand's options."""
    s = sub.add_parser("report", help="HTML report for your own files")
    s.add_argument(
        "files",
        nargs="+",
        action=InputPath,
        metavar="DATA",
        help="instrument exports, .bsdf files, datasets and height maps (.di, .opdx, ...)",
    )
    s.add_argument("--model", default="smooth3")
    s.add_argument(
        "--param",
        action="append",
        metavar="NAME=VALUE",
        help="a model option (microfacet n=, k=, diffuse=true) or a parameter's start value",
    )
    s.add_argument("-o", "--output", action=OutputPath, kind="dir", required=True, metavar="DIR")
    _add_overwrite(s)
    film = s.add_mutually_exclusive_group()
    film.add_argument(
        "--film-model",
        default=None,
        action=InputPath,
        inside="model",
        metavar="FILE.toml",
        help="fit this film stack to psi/Delta files whose angles disagree",
    )
    film.add_argument(
        "--film-default",
        action="store_true",
        help="... or the stated default: one transparent Cauchy layer on c-Si, thickness free",
    )
    s.add_argument(
        "--film-files",
        default=None,
        metavar="A[,B...]",
        help="the psi/Delta DATA inputs the film model is of (default: those of the sample "
        "group holding them; never the model's own substrate table)",
    )
    s.add_argument(
        "--same-sample",
        action="append",
        # not an InputPath: every name must be one of the DATA inputs (refused otherwise)
        metavar="A,B[,...]",
        help="these DATA inputs are one sample (repeatable; inputs stating one sample name "
        "are paired anyway)",
    )
    s.add_argument(
        "--prediction-slopes",
        choices=("ggx", "measured"),
        default="ggx",
        help="roughness of the section prediction: the GGX alpha of the height map's slopes "
        "(default) or their measured table (as trace --surface)",
    )
    s.add_argument(
        "--nk-from",
        action=InputPath,
        default=None,
        metavar="FILE",
        help="substrate n, k of the tracer maps from this psi/Delta file (as trace --nk-from; "
        "default: the psi/Delta file of each height map's sample, else a stated aluminium)",
    )
    s.add_argument(
        "--wavelength",
        type=_wavelength_value,
        default=None,
        metavar="NM",
        help="[nm] the wavelength of the files that state none (a .bsdf has no field for "
        "it; 555 nm is then a label, and the prediction and smoothness sections need it)",
    )
    s.add_argument("--quiet", action="store_true", help="no progress lines")
    _add_selection(s, wavelength_taken=True)
    _add_scheduler(s)
    s.set_defaults(func=cmd_report)
