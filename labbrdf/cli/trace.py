"""``labbrdf trace``: Monte Carlo polarization ray tracing of one sample."""

from __future__ import annotations

import argparse
import functools
import time
from typing import Any

from ..microfacet import DISTRIBUTIONS
from ._executor import _add_scheduler, _executor, _executor_errors
from ._options import (
    UsageError,
    _add_geometry,
    _angle_value,
    _channel,
    _emit_json,
    _medium_value,
    _option_errors,
    _pixel_size,
    _warn,
    _wavelength_value,
)
from ._paths import InputPath, OutputPath, _add_overwrite


def _complex(text: str, what: str) -> complex:
    try:
        return complex(text.replace(" ", "").replace("i", "j"))
    except ValueError:
        raise UsageError(f"{what} {text!r}: expected a complex index like 1.55+7.71j") from None


@_executor_errors
def cmd_trace(args: argparse.Namespace) -> int:
    """Trace the sample of the options; print the energy balance, write the outputs."""
    from .. import tracer
    from ..sample import trace_config_from_inputs

    executor = _executor(args, progress=not args.json)  # outputs checked by _checked_outputs
    with _option_errors():
        config = trace_config_from_inputs(
            args.wavelength,
            args.theta_i,
            base_albedo=args.base_albedo,
            substrate_index=None
            if args.substrate is None
            else _complex(args.substrate, "--substrate"),
            nk_from=args.nk_from,
            alpha=args.alpha,
            surface=args.surface,
            coating_index=None if args.coating is None else _complex(args.coating, "--coating"),
            coating_from=args.coating_from,
            thickness_nm=args.thickness,
            coating_alpha=args.coating_alpha,
            coating_surface=args.coating_surface,
            medium=args.medium,
            distribution=args.distribution,
            channel=_channel(args.channel),
            unit=args.unit,
            pixel_size=_pixel_size(args),
            warn=_warn,
            rays=args.rays,
            seed=args.seed,
            scattering="single" if args.single_scattering else "multiple",
            coherent=args.coherent,
            estimator=args.estimator,
            scalar=args.scalar,
        )
    t0 = time.perf_counter()
    result = tracer.trace(config, map=functools.partial(executor.imap, desc="trace"))
    seconds = time.perf_counter() - t0
    if args.output:
        result.save(args.output)
    if args.png:
        from ..report.figures import save_trace_maps_png

        save_trace_maps_png(result, args.png)  # atomically
    summary = tracer.trace_summary(result)
    summary["seconds"] = seconds
    if args.json:
        _emit_json(summary)
    else:
        e = summary["energy"]
        print(
            f"albedo {summary['albedo']:.6f}  exited {e['exited']:.6f}  absorbed "
            f"{e['absorbed']:.6f}  terminated {e['terminated']:.6f}  rays {summary['rays']}  "
            f"{seconds:.2f} s"
        )
    return 0


def add_parser(sub: Any) -> None:
    """The ``trace`` subcommand's options."""
    s = sub.add_parser("trace", help="Monte Carlo polarization ray tracing (pBRDF)")
    s.add_argument("--substrate", default=None, help="complex index, e.g. 1.55+7.71j")
    s.add_argument(
        "--nk-from",
        action=InputPath,
        default=None,
        metavar="FILE",
        help="substrate n, k from psi/Delta",
    )
    s.add_argument("--alpha", type=float, default=None, help="GGX roughness of the substrate")
    s.add_argument(
        "--surface",
        action=InputPath,
        default=None,
        metavar="FILE",
        help="measured height map: its slope table",
    )
    s.add_argument("--channel", default=None, help="height channel of --surface")
    s.add_argument(
        "--base-albedo",
        type=float,
        default=None,
        metavar="A",
        help="a Lambertian base of albedo A in [0, 1] instead of the metal substrate "
        "(paints, plastics: with --coating and --coating-alpha)",
    )
    _add_geometry(s)
    s.add_argument("--coating", default=None, help="coating index, e.g. 1.5")
    s.add_argument(
        "--coating-from",
        default=None,
        action=InputPath,
        inside="fit",
        metavar="FIT.json",
        help="coating index at --wavelength and thickness from a one-layer film fit",
    )
    s.add_argument("--thickness", type=float, default=None, help="coating thickness [nm]")
    s.add_argument("--coating-alpha", type=float, default=None)
    s.add_argument(
        "--coating-surface",
        action=InputPath,
        default=None,
        metavar="FILE",
        help="measured height map of the coating's top: its slope table (and, for "
        "reference, its ML GGX alpha)",
    )
    s.add_argument(
        "--medium",
        type=_medium_value,
        default=None,
        metavar="TAU,SSA,G",
        help="a scattering coating: a Henyey-Greenstein medium of optical thickness TAU, "
        "single-scattering albedo SSA and asymmetry G fills the coating",
    )
    s.add_argument(
        "--distribution",
        choices=tuple(DISTRIBUTIONS),
        default="ggx",
        help="microfacet distribution of the interfaces given by an alpha (measured maps "
        "always use their own slope table)",
    )
    s.add_argument("--theta-i", type=_angle_value, required=True, help="[deg]")
    s.add_argument(
        "--wavelength", type=_wavelength_value, required=True, metavar="NM", help="[nm]"
    )
    s.add_argument("--rays", type=int, default=200_000)
    s.add_argument("--seed", type=int, default=1)
    s.add_argument("--single-scattering", action="store_true")
    s.add_argument("--coherent", action="store_true")
    s.add_argument(
        "--estimator",
        choices=("auto", "evaluated", "counting"),
        default="auto",
        help="evaluated: closed-form single events + exit operators (a rough first "
        "interface; ~50x less noise per bin at equal rays on the 2022 paper's case); "
        "counting: exits counted into bins; auto (default): evaluated where it applies, "
        "except multiple scattering under a coating, whose four operators take ~0.8 GB "
        "and tens of seconds to build on the 1-degree grid (ask with --estimator evaluated)",
    )
    s.add_argument(
        "--scalar",
        action="store_true",
        help="unpolarized Fresnel reflectance at every vertex (only M00; how scalar codes "
        "compute)",
    )
    s.add_argument(
        "-o",
        "--output",
        action=OutputPath,
        suffixes=(".npz",),
        default=None,
        help="write the pBRDF (.npz)",
    )
    s.add_argument(
        "--png",
        action=OutputPath,
        suffixes=(".png",),
        default=None,
        help="write S0/DOP hemisphere maps (.png)",
    )
    _add_overwrite(s)
    s.add_argument("--json", action="store_true")
    _add_scheduler(s)
    s.set_defaults(func=cmd_trace)
