"""``labbrdf export``: a model's BRDF or a trace's S0 as a BSDF file (Zemax or Speos)."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from ._options import UsageError, _angle_value, _model_from_args, _wavelength_value
from ._paths import InputPath, OutputPath, _add_overwrite

#: the file each --format writes
_SUFFIX = {"zemax-bsdf": ".bsdf", "speos-bsdf": ".anisotropicbsdf", "astm-brdf": ".astm"}


def cmd_export(args: argparse.Namespace) -> int:
    """Write ``--model``'s BRDF or ``--trace``'s S0 as a Zemax BSDF file."""
    import numpy as np

    from ..writers.zemax import model_to_bsdf

    if args.format not in _SUFFIX:
        raise UsageError(f"--format {args.format!r}: export writes {' or '.join(_SUFFIX)}")
    if not str(args.output).lower().endswith(_SUFFIX[args.format]):
        raise UsageError(f"--format {args.format} writes a {_SUFFIX[args.format]} file (-o)")
    if sum(x is not None for x in (args.model, args.trace, args.from_fit)) != 1:
        raise UsageError(
            "export a model (--model NAME --param ...), a fit (--from-fit FIT.json) or a "
            "trace (--trace RUN.npz)"
        )
    if args.trace is not None:
        if args.format == "astm-brdf":
            raise UsageError("--trace is written as zemax-bsdf or speos-bsdf")
        return _export_trace(args)
    if args.theta_i is None:
        raise UsageError(
            f"{'--model' if args.model else '--from-fit'} needs --theta-i DEG [DEG ...]"
        )
    model, values, wl, comments = _from_fit(args) if args.from_fit else _from_model(args)
    out = Path(args.output)  # checked with the inputs by _checked_outputs
    if args.format == "astm-brdf":
        from ..writers.astm import model_to_astm

        if wl is None:
            raise UsageError("--format astm-brdf needs --wavelength NM (its value column)")
        model_to_astm(
            model,
            values,
            out,
            theta_i_deg=np.asarray(args.theta_i, float),
            wavelength_nm=wl,
        )
        print(f"wrote {out}")
        return 0
    if args.format == "speos-bsdf":
        from ..writers.speos import model_to_speos

        model_to_speos(
            model,
            values,
            out,
            theta_i_deg=np.asarray(args.theta_i, float),
            wavelength_nm=wl,
        )
        print(f"wrote {out}")
        return 0
    model_to_bsdf(
        model,
        values,
        out,
        theta_i_deg=np.asarray(args.theta_i, float),
        radial_deg=_grid(args.radial, "--radial"),
        azimuth_deg=_grid(args.azimuth, "--azimuth"),
        wavelength_nm=wl,
        comments=comments,
        overwrite=args.overwrite,
    )
    print(f"wrote {out}" + (f" (wavelength {wl:g} nm)" if wl else " (no wavelength: none given)"))
    return 0


def _from_model(args: argparse.Namespace) -> tuple[Any, dict[str, float], float | None, tuple]:
    """``--model NAME --param ...``: the model, its values, ``--wavelength`` [nm]."""
    model, values = _model_from_args(args)
    unknown = [k for k in values if k not in model.params]
    if unknown:
        raise UsageError(f"--param {unknown}: {args.model} parameters are {list(model.params)}")
    return model, values, args.wavelength, ()


def _from_fit(args: argparse.Namespace) -> tuple[Any, dict[str, float], float | None, tuple]:
    """``--from-fit FIT.json``: the fitted model, its values and its group's wavelength [nm]."""
    from .. import models
    from ._fit_record import fit_record

    if args.param or args.nk_from:
        raise UsageError("--from-fit takes the model and its values from the fit; drop --param")
    rec = fit_record(args.from_fit, args.wavelength)
    # a fit through the instrument's aperture estimates the sample: the file describes the
    # sample's model, without the instrument's average
    aperture = {k: rec["options"].pop(k) for k in models.APERTURE_OPTIONS if k in rec["options"]}
    try:
        model = models.get(rec["model"], **rec["options"])
        for k, v in rec["values"].items():
            model.check_value(k, v)
    except ValueError as exc:
        raise UsageError(f"--from-fit {args.from_fit}: {exc}") from None
    note = f"labbrdf fit of {rec['model']} from {Path(args.from_fit).name}"
    if any(aperture.values()):
        note += (
            f", fitted through a {aperture.get('detector_deg', 0):g} deg detector and "
            f"{aperture.get('beam_deg', 0):g} deg beam aperture (half-angles); the sample's "
            "model, without it"
        )
    return model, rec["values"], rec["wavelength_nm"], (note,)


def _export_trace(args: argparse.Namespace) -> int:
    """``export --trace RUN.npz``: the tracer's unpolarized S0 on the scatter grid."""
    from ..tracer import TraceResult
    from ..writers.zemax import binned_to_bsdf

    out = Path(args.output)  # checked with the inputs by _checked_outputs
    if args.theta_i is not None or args.param or args.nk_from:
        raise UsageError(
            "--trace takes its angle and material from the run; drop --theta-i/--param"
        )
    try:
        res = TraceResult.load(args.trace)
    except (OSError, KeyError, ValueError) as exc:
        raise UsageError(f"--trace {args.trace}: not a labbrdf trace file ({exc})") from None
    cfg = res.config
    if args.format == "speos-bsdf":
        from ..writers.speos import binned_to_speos

        binned_to_speos(
            out,
            theta_i_deg=cfg.theta_i_deg,
            values=res.s0(),
            theta_edges_deg=res.theta_r_edges_deg,
            phi_edges_deg=res.phi_r_edges_deg,
            wavelength_nm=cfg.wavelength_nm,
            comment=f"labbrdf trace S0 (unpolarized), {res.rays} rays, seed {cfg.seed}",
        )
        print(f"wrote {out}")
        return 0
    binned_to_bsdf(
        out,
        theta_i_deg=cfg.theta_i_deg,
        values=res.s0(),
        theta_edges_deg=res.theta_r_edges_deg,
        phi_edges_deg=res.phi_r_edges_deg,
        radial_deg=_grid(args.radial, "--radial"),
        azimuth_deg=_grid(args.azimuth, "--azimuth"),
        wavelength_nm=cfg.wavelength_nm,
        symmetry="Asymmetrical",
        comments=(f"labbrdf trace S0 (unpolarized), {res.rays} rays, seed {cfg.seed}",),
        overwrite=args.overwrite,
    )
    print(f"wrote {out}")
    return 0


def _grid(text: str, option: str) -> Any:
    """``--radial`` or ``--azimuth``: :func:`labbrdf.writers.zemax.angle_grid` of the text."""
    from ..writers.zemax import angle_grid

    try:
        return angle_grid(text)
    except ValueError as exc:
        raise UsageError(f"{option} {text!r}: {exc}") from None


def add_parser(sub: Any) -> None:
    """The ``export`` subcommand's options."""
    s = sub.add_parser("export", help="write a model BRDF in an exchange format")
    s.add_argument(
        "--format",
        default="zemax-bsdf",
        help="zemax-bsdf, speos-bsdf (a model on theta 0:90:1, phi 0:360:5 from the normal) "
        "or astm-brdf (the plane of incidence, theta_r 0:89:1; needs --wavelength)",
    )
    s.add_argument("--model", default=None, help="a model (with --param) ...")
    s.add_argument(
        "--trace", action=InputPath, default=None, metavar="RUN.npz", help="... or a trace's S0"
    )
    s.add_argument(
        "--from-fit",
        action=InputPath,
        default=None,
        metavar="FIT.json",
        help="... or the model and values of a fit (what `labbrdf fit --json` prints; with "
        "several groups choose one with --wavelength); its wavelength is recorded",
    )
    s.add_argument("--param", action="append", metavar="NAME=VALUE")
    s.add_argument("--nk-from", action=InputPath, default=None, metavar="FILE")
    s.add_argument(
        "--wavelength",
        type=_wavelength_value,
        default=None,
        metavar="NM",
        help="[nm] for --nk-from, the group of --from-fit; recorded in the output (the "
        "wavelength speos-bsdf and astm-brdf write)",
    )
    s.add_argument("--theta-i", type=_angle_value, nargs="+", default=None, metavar="DEG")
    s.add_argument("--radial", default="0:80:2", help="START:STOP:STEP [deg] about specular")
    s.add_argument("--azimuth", default="0:180:5", help="START:STOP:STEP [deg]")
    s.add_argument(
        "-o", "--output", action=OutputPath, suffixes=tuple(_SUFFIX.values()), required=True
    )
    _add_overwrite(s)
    s.set_defaults(func=cmd_export)
