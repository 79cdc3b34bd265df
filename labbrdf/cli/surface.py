"""``labbrdf surface``: roughness statistics of a height map or profile."""

from __future__ import annotations

import argparse
import math
from pathlib import Path
from typing import Any

from .. import progress
from ._options import (
    UsageError,
    _add_geometry,
    _angle_value,
    _channel,
    _emit_json,
    _pixel_size,
    _warn,
    _wavelength_value,
)
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


def _levelling(args: argparse.Namespace) -> int:
    """The levelling degree of ``--form NAME`` or ``--degree N`` (default 1, the plane)."""
    from ..roughness.form import FORMS

    if args.form is None:
        return 1 if args.degree is None else args.degree
    if args.degree is not None:
        raise UsageError("--form and --degree both set the levelling: give one")
    if args.form not in FORMS:
        raise UsageError(f"--form {args.form!r}: expected one of {', '.join(FORMS)}")
    return FORMS[args.form]


def _cutoff(args: argparse.Namespace) -> float | None:
    """``--short-cutoff`` in metres; the other option values checked before any reading."""
    from ..adapters.topography import length_m

    if args.theta_i is not None and args.wavelength is None:
        raise UsageError("--theta-i needs --wavelength NM (the Rayleigh verdict)")
    if args.erode_mask < 0:
        raise UsageError(f"--erode-mask {args.erode_mask}: expected pixels >= 0")
    if args.short_cutoff is None:
        return None
    try:
        return float(length_m(args.short_cutoff, args.unit))
    except ValueError as exc:
        raise UsageError(f"--short-cutoff: {exc}") from None


def _statistics(args: argparse.Namespace, hm: Any, degree: int, cutoff: float | None) -> Any:
    """The roughness statistics (and ``--png``), errors said with the file's name."""
    from ..roughness.topography import level, on_measured_points, roughness_statistics

    try:
        st = roughness_statistics(
            hm.heights,
            hm.pixel_size,
            degree=degree,
            blocks=args.blocks,
            short_cutoff=cutoff,
            erode=args.erode_mask,
            progress=_report_pass,
        )
        st = on_measured_points(st, hm.points, degree)
        if args.png:
            from ..report.figures import save_png, surface_figure

            z = level(hm.heights, degree)
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
    return st


def _rayleigh(args: argparse.Namespace, hm: Any, st: Any, degree: int) -> dict[str, Any]:
    """The Rayleigh verdict at ``--wavelength`` and ``--theta-i``, as the report judges it.

    The sigma is that of the roughness which scatters at that geometry
    (:func:`labbrdf.report.roughness.judge`: the map S-filtered at the shortest scattering
    period when the map resolves it), with the map's jackknife uncertainty.
    """
    from ..report.roughness import MapRoughness, judge
    from ..roughness.topography import level

    short = 2.0 * min(hm.pixel_size) * 1e9
    if math.isfinite(st.short_cutoff):
        short = max(short, st.short_cutoff * 1e9)
    size = max(hm.physical_sizes) * 1e9
    m = MapRoughness(hm, st, level(hm.heights, degree), short, size, {})
    return judge(m, args.wavelength, args.theta_i or 0.0)


def _rayleigh_lines(r: dict[str, Any]) -> list[str]:
    """The verdict in two lines."""
    head = (
        f"Rayleigh at {r['wavelength_nm']:g} nm, theta_i {r['theta_i']:g} deg: "
        f"periods >= {r['shortest_nm']:.4g} nm scatter (map's band: {r['coverage']})"
    )
    if "g" not in r:
        return [head, f"verdict: {r['rayleigh']}"]
    u = r.get("u_sigma_nm")
    sig = f"{r['sigma_nm']:.4g}" + (f" +- {u:.2g}" if u is not None else "")
    ug = r.get("u_g")
    g = f"{r['g']:.3g}" + (f" +- {ug:.2g}" if ug is not None else "")
    return [
        head,
        f"sigma {sig} nm, g {g}, exp(-g) {r['loss']:.4g}: {r['rayleigh']} by Rayleigh "
        f"(sigma < {r['thr_rayleigh']:.4g} nm), {r['fraunhofer']} by Fraunhofer "
        f"(sigma < {r['thr_fraunhofer']:.4g} nm); verdicts at sigma +- 2u",
    ]


def cmd_surface(args: argparse.Namespace) -> int:
    """Print (or ``--json``) the roughness statistics of a height map."""
    from ..outputs import check_file_output, check_input_files
    from ..roughness.form import check_form

    check_input_files([args.file])
    if args.png:
        check_file_output(args.png, inputs=[args.file], suffixes=(".png",), option="--png")
    degree, cutoff = _levelling(args), _cutoff(args)
    hm = _height_map(args.file, args.channel, args)
    st = _statistics(args, hm, degree, cutoff)
    d = st.to_dict()
    d["file"] = str(args.file)
    d["channel"] = hm.channel
    d["geometry_warnings"] = list(hm.warnings)
    form = check_form(hm.heights, hm.pixel_size, degree)
    d["form"] = form.to_dict() if form is not None else None
    if args.wavelength is not None:
        d["rayleigh"] = _rayleigh(args, hm, st, degree)
    if args.json:
        _emit_json(d)
        return 0
    _print(d, hm.channel, args.file)
    if form is not None and form.dominated:
        print(f"warning: {form.message()}")
    for line in _rayleigh_lines(d["rayleigh"]) if "rayleigh" in d else ():
        print(line)
    return 0


def _print(d: dict[str, Any], channel: str, file: str) -> None:
    """The statistics as a table, then the slope fits, warnings and notes."""
    from ..microfacet import DISTRIBUTIONS

    u = d.get("uncertainty") or {}

    def row(label: str, key: str, scale: float, unit: str) -> None:
        v = d.get(key)
        if v is None:
            print(f"{label:<38} undefined")
            return
        e = u.get(key)
        err = f" +- {e * scale:.3g}" if e is not None else ""
        print(f"{label:<38} {v * scale:.4g}{err} {unit}")

    print(f"{file} ({d['kind']}, channel {channel}, {d['levelling']})")
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


def add_parser(sub: Any) -> None:
    """The ``surface`` subcommand's options."""
    s = sub.add_parser("surface", help="roughness statistics of a height map or profile")
    s.add_argument("file", action=InputPath, metavar="FILE")
    s.add_argument("--channel", default=None, help="channel name or index (default: height)")
    s.add_argument(
        "--form",
        default=None,
        metavar="NAME",
        help="form removed before the statistics: mean, plane (default) or quadric (a "
        "cylinder's or a lens's curvature; a map dominated by form is flagged)",
    )
    s.add_argument(
        "--degree",
        type=int,
        default=None,
        help="levelling polynomial of any total degree (1 = plane; or --form)",
    )
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
    s.add_argument(
        "--wavelength",
        type=_wavelength_value,
        default=None,
        metavar="NM",
        help="[nm] also say whether the surface is smooth by the Rayleigh criterion at this "
        "wavelength (sigma of the roughness that scatters, with its uncertainty)",
    )
    s.add_argument(
        "--theta-i",
        type=_angle_value,
        default=None,
        metavar="DEG",
        help="[deg] angle of incidence of the Rayleigh verdict (default 0)",
    )
    s.add_argument("--json", action="store_true")
    s.set_defaults(func=cmd_surface)
