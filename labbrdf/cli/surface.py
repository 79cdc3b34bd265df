"""``labbrdf surface``: roughness statistics of a height map or profile."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from .. import progress
from ._options import UsageError, _add_geometry, _channel, _emit_json, _pixel_size, _warn
from ._paths import InputPath, OutputPath, _add_overwrite


def _height_map(path: str, channel: str | None, args: argparse.Namespace) -> Any:
    """Read a height map; ``--pixel-size`` / ``--unit`` of ``args`` state its geometry."""
    from ..adapters import read_inputs

    pixel = _pixel_size(args)
    try:
        (hm,) = read_inputs(
            [path],
            kind="height_map",
            channel=_channel(channel),
            unit=args.unit,
            pixel_size=pixel,
            on_error="raise",
        ).height_maps
    except MemoryError:
        raise UsageError(f"{path}: out of memory while reading the height map") from None
    for w in hm.warnings:
        _warn(f"{path}: {w}")
    return hm


def _report_pass(done: int, total: int) -> None:
    """The statistics' passes on the command's progress line."""
    progress.report(phase="leave-one-block-out passes", done=done, total=total)


def cmd_surface(args: argparse.Namespace) -> int:
    """Print (or ``--json``) the roughness statistics of a height map."""
    from ..adapters.topography import length_m
    from ..microfacet import DISTRIBUTIONS
    from ..outputs import check_file_output, check_input_files
    from ..topography import level, on_measured_points, roughness_statistics

    check_input_files([args.file])
    if args.png:
        check_file_output(args.png, inputs=[args.file], suffixes=(".png",), option="--png")
    cutoff = None
    if args.short_cutoff is not None:
        try:
            cutoff = length_m(args.short_cutoff, args.unit)
        except ValueError as exc:
            raise UsageError(f"--short-cutoff: {exc}") from None
    if args.erode_mask < 0:
        raise UsageError(f"--erode-mask {args.erode_mask}: expected pixels >= 0")
    hm = _height_map(args.file, args.channel, args)
    try:
        st = roughness_statistics(
            hm.heights,
            hm.pixel_size,
            degree=args.degree,
            blocks=args.blocks,
            short_cutoff=cutoff,
            erode=args.erode_mask,
            progress=_report_pass,
        )
        st = on_measured_points(st, hm.points, args.degree)
        if args.png:
            from ..report.figures import save_png, surface_figure

            z = level(hm.heights, args.degree)
            title = f"{Path(args.file).name} ({hm.channel})"
            save_png(surface_figure(z, hm.pixel_size, st, title=title), args.png)
    except MemoryError:
        shape = " x ".join(map(str, hm.heights.shape))
        raise UsageError(
            f"{args.file}: out of memory for the statistics of a {shape} map"
            f" ({hm.heights.nbytes / 2**20:.0f} MiB of heights; the statistics need about"
            " 14 times that)"
        ) from None
    except ValueError as exc:
        raise UsageError(f"{args.file}: {exc}") from None
    d = st.to_dict()
    d["file"] = str(args.file)
    d["channel"] = hm.channel
    d["geometry_warnings"] = list(hm.warnings)
    if args.json:
        _emit_json(d)
        return 0
    u = d.get("uncertainty") or {}

    def row(label: str, key: str, scale: float, unit: str) -> None:
        v = d.get(key)
        if v is None:
            print(f"{label:<38} undefined")
            return
        e = u.get(key)
        err = f" +- {e * scale:.3g}" if e is not None else ""
        print(f"{label:<38} {v * scale:.4g}{err} {unit}")

    print(f"{args.file} ({d['kind']}, channel {hm.channel}, {d['levelling']})")
    print(f"bandwidth: {d['bandwidth']}")
    row("sigma (RMS height)", "sigma", 1e9, "nm")
    row("RMS slope", "slope_rms", 1.0, "")
    row("correlation length c", "c", 1e6, "um")
    row("alpha_gaussian_acf = sqrt(2) sigma/c", "alpha_gaussian_acf", 1.0, "")
    row("alpha_ggx_ml (used by trace)", "alpha_ggx_ml", 1.0, "")
    if d["kind"] == "areal":
        row("anisotropy c_major/c_minor", "anisotropy_ratio", 1.0, "")
    fits = d["slope_fits"]
    for name in DISTRIBUTIONS:
        f = fits[name]
        print(f"{name + ' alpha (ML)':<38} {f['alpha']:.4g}  KS {f['ks']:.3g}  AIC {f['aic']:.6g}")
    print(f"best description of the slopes: {fits['best']}")
    if fits.get("warning"):
        print(f"warning: {fits['warning']}")
    for note in d.get("notes") or ():
        if note != fits.get("warning"):
            print(f"note: {note}")
    return 0


def add_parser(sub: Any) -> None:
    """The ``surface`` subcommand's options."""
    s = sub.add_parser("surface", help="roughness statistics of a height map or profile")
    s.add_argument("file", action=InputPath, metavar="FILE")
    s.add_argument("--channel", default=None, help="channel name or index (default: height)")
    s.add_argument("--degree", type=int, default=1, help="levelling polynomial (1 = plane)")
    s.add_argument("--blocks", type=int, default=None, help="tiles per axis for uncertainties")
    s.add_argument(
        "--png",
        action=OutputPath,
        suffixes=(".png",),
        default=None,
        help="write map, ACF and slope histogram (.png)",
    )
    _add_overwrite(s)
    s.add_argument(
        "--short-cutoff",
        default=None,
        metavar="LENGTH",
        help="Gaussian S-filter cut-off (ISO 16610-61), e.g. 2um: slopes and alphas then refer"
        " to longer wavelengths (default: none, down to the pixel)",
    )
    s.add_argument(
        "--erode-mask",
        type=int,
        default=0,
        metavar="N",
        help="drop the points within N pixels of a dropout (their rims often carry spikes)",
    )
    _add_geometry(s)
    s.add_argument("--json", action="store_true")
    s.set_defaults(func=cmd_surface)
