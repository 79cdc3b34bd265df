"""``labbrdf psd``: power spectral density of height maps, their composite and a model fit."""

from __future__ import annotations

import argparse
from typing import Any

from ._options import (
    UsageError,
    _add_geometry,
    _channel,
    _emit_json,
    _fit_seed,
    _pixel_size,
    _warn,
)
from ._paths import InputPath, OutputPath, _add_overwrite

#: the models ``--fit`` offers (labbrdf.roughness.psd_models.PSD_MODELS, kept import-free)
FIT_MODELS = ("k-correlation", "gaussian", "exponential", "fractal")


def _band(text: str | None) -> tuple[float | None, float | None]:
    """``--fit-band F_MIN:F_MAX`` [1/m]; either side may be empty."""
    if text is None:
        return None, None
    lo, sep, hi = text.partition(":")
    try:
        if not sep:
            raise ValueError
        band = (float(lo) if lo.strip() else None, float(hi) if hi.strip() else None)
    except ValueError:
        raise UsageError(
            f"--fit-band {text!r}: expected F_MIN:F_MAX in 1/m, e.g. 1e4:1e7"
        ) from None
    if band[0] is not None and band[1] is not None and not 0 <= band[0] < band[1]:
        raise UsageError(f"--fit-band {text!r}: expected 0 <= F_MIN < F_MAX")
    return band


def cmd_psd(args: argparse.Namespace) -> int:
    """Print (or ``--json``) the PSD of each map, the composite and the fit; write CSV / PNG."""
    from ..outputs import check_input_files
    from ..roughness.psd_result import psd

    check_input_files(args.files)
    f_min, f_max = _band(args.fit_band)
    if args.fit_band and not args.fit:
        raise UsageError("--fit-band needs --fit MODEL")
    if args.per_decade < 1 or args.degree < 0:
        raise UsageError("--per-decade must be >= 1 and --degree >= 0")
    read_kw: dict[str, Any] = {"unit": args.unit, "pixel_size": _pixel_size(args)}
    res = psd(
        args.files,
        kind=args.kind,
        fit=args.fit,
        f_min=f_min,
        f_max=f_max,
        window=args.window,
        degree=args.degree,
        per_decade=args.per_decade,
        channel=_channel(args.channel),
        seed=args.seed,
        **{k: v for k, v in read_kw.items() if v is not None},
    )
    if args.output:
        res.to_csv(args.output)
    if args.png:
        _save_png(res, args.png)
    if args.json:
        _emit_json(res.to_dict())
        for w in res.warnings:
            _warn(w)
    else:
        print(res)
    return 0


def _save_png(res: Any, path: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    from ..outputs import atomic_output

    fig = res.plot()
    with atomic_output(path) as tmp:
        fig.savefig(tmp, format="png", dpi=120)


def add_parser(sub: Any) -> None:
    """The ``psd`` subcommand's options."""
    s = sub.add_parser(
        "psd",
        help="power spectral density of height maps (composite over maps, model fit)",
        description="PSD of each height map (2-D azimuthal average or 1-D profiles), the "
        "composite over their bands with the overlaps checked, and optionally a fitted "
        "model. Spatial frequency f in 1/m; 2-D PSD [m^4], 1-D (two-sided) PSD [m^3].",
    )
    s.add_argument("files", action=InputPath, nargs="+", metavar="MAP")
    s.add_argument(
        "--kind",
        choices=("auto", "2d", "1d"),
        default="auto",
        help="2d: azimuthal average of the 2-D PSD (areal maps); 1d: profile PSD (map rows "
        "averaged); auto: 2d unless one of the maps is a profile",
    )
    s.add_argument("--fit", choices=FIT_MODELS, default=None, help="PSD model to fit")
    s.add_argument(
        "--fit-band",
        default=None,
        metavar="F_MIN:F_MAX",
        help="spatial frequencies fitted [1/m] (default: the composite's band)",
    )
    s.add_argument("--window", default="hann", choices=("hann", "none"), help="window")
    s.add_argument("--degree", type=int, default=1, help="detrending polynomial (1 = plane)")
    s.add_argument("--per-decade", type=int, default=10, help="frequency bins per decade")
    s.add_argument("--channel", default=None, help="channel name or index (default: height)")
    s.add_argument("--seed", type=_fit_seed, default=0, help="the fit's random seed")
    s.add_argument(
        "-o", "--output", action=OutputPath, suffixes=(".csv",), default=None,
        help="write every bin of every PSD (and the model) as CSV",
    )  # fmt: skip
    s.add_argument(
        "--png", action=OutputPath, suffixes=(".png",), default=None,
        help="write the log-log PSD figure",
    )  # fmt: skip
    _add_overwrite(s)
    _add_geometry(s)
    s.add_argument("--json", action="store_true")
    s.set_defaults(func=cmd_psd)
