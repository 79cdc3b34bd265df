"""``labbrdf film``: fit a thin-film stack to psi/Delta, R and T of one sample."""

from __future__ import annotations

import argparse
import math
import os
from typing import Any

from ._options import (
    UsageError,
    _add_selection,
    _emit_json,
    _fit_seed,
    _parse_assignments,
    _selected,
)
from ._paths import InputPath, OutputPath, _add_overwrite

#: --dpol's words -> fit_film's depolarization
_DPOL: dict[str, bool | str] = {"auto": "auto", "on": True, "off": False}


def _film_model(args: argparse.Namespace) -> Any:
    """The FilmModel of --model FILE, or of --substrate and --layer, or the default."""
    from .. import films
    from ..nk import tabulated_from_file

    written = {opt: getattr(args, opt[2:].replace("-", "_")) for opt in films.layers.STACK_OPTIONS}
    if args.model is not None:
        if args.layer or args.substrate:
            raise UsageError("give --model FILE or --substrate/--layer, not both")
        given = [opt for opt, v in written.items() if v is not None]
        if given:
            raise UsageError(
                f"{given[0]} with --model: give it in the model file (thickness_spread, "
                "bandwidth_nm, angle_spread_deg, [substrate] thickness_nm)"
            )
        return films.load_model(args.model, tabulated_from_file)
    try:
        beam, beam_free = films.layers.parse_stack_values(written)
    except films.FilmError as exc:
        raise UsageError(str(exc)) from None
    if not args.layer:
        if args.substrate not in (None, "si"):
            raise UsageError("--substrate without --layer: give the layers with --layer")
        fm = films.FilmModel.cauchy_on_silicon()
        if not beam:
            return fm
        stack = films.Stack(fm.stack.layers, fm.stack.substrate, **beam)
        return films.FilmModel(stack, {**fm.free, **beam_free}, fm.wavelength_range_nm, fm.source)
    sub_text = args.substrate or "si"
    try:
        sub = (
            films.as_material(sub_text)
            if not os.path.exists(sub_text)
            else tabulated_from_file(sub_text)
        )
    except ValueError as exc:
        raise UsageError(f"--substrate {sub_text}: {exc}") from None

    def material_of(text: str) -> Any:  # a table file is an input (_layer_files checks it)
        return tabulated_from_file(text) if os.path.exists(text) else films.as_material(text)

    layers, free = [], {}
    for j, spec in enumerate(args.layer, 1):
        try:  # the grammar and the rule of free parameters: labbrdf.films.layers
            layer, layer_free = films.layers.parse_layer(spec, j, material_of)
        except films.FilmError as exc:
            raise UsageError(f"--layer {exc}") from None
        layers.append(layer)
        free.update(layer_free)
    try:
        stack = films.Stack(layers, sub, **beam)
    except ValueError as exc:
        raise UsageError(f"--layer: {exc}") from None
    return films.FilmModel(stack, {**free, **beam_free}, None, "--layer")


def _at_wavelengths(text: str | None) -> list[float]:
    """The wavelengths [nm] of ``--at 550[,633...]``: positive finite numbers."""
    if text is None:
        return []
    out = []
    for item in text.split(","):
        try:
            w = float(item)
        except ValueError:
            w = math.nan
        if not (math.isfinite(w) and w > 0):
            raise UsageError(f"--at {text}: expected wavelengths [nm] > 0, e.g. --at 550,633")
        out.append(w)
    return out


def _one_sample(args: argparse.Namespace, parts: list[Any], data: Any) -> bool:
    """Whether the files of a film fit are one sample: refused (exit 2) when they are not.

    Files that state different sample names in the selected rows are one sample only by
    ``--same-sample``; every ``--same-sample`` value is checked against the inputs first
    (:func:`labbrdf.samples.pair_samples`), whether or not it is needed.
    """
    from pathlib import Path

    from ..films import FILM_QUANTITIES
    from ..fitting.film import stated_samples
    from ..samples import SampleFile, pair_samples, split_same_sample

    def said(rows: Any) -> dict[str, None]:  # the names of the rows a film fit uses
        rows = rows[rows["quantity"].astype(str).isin(FILM_QUANTITIES)]
        return dict.fromkeys(n for names in stated_samples(rows).values() for n in names)

    selected = said(data.data)
    files = []
    for path, m in zip(args.files, parts, strict=True):  # each file's own, still selected
        own = said(m.data)
        files.append(SampleFile(Path(path), tuple(n for n in own if n in selected)))
    groups = pair_samples(
        files,
        [split_same_sample(v, args.files) for v in args.same_sample or ()],
        given_as="given with --same-sample",
    )
    stating = [g for g in groups if any(f.names and f.path in g.paths for f in files)]
    if len(stating) < 2:
        return True
    listing = "; ".join(
        f"{f.path} states {', '.join(map(repr, f.names))}" for f in files if f.names
    )
    spelt = ",".join(str(f.path) for f in files if f.names)
    raise UsageError(
        f"the files state different samples ({listing}); a film fit is of one sample: fit "
        f"each on its own (or select one with --sample), or, if they are one sample, say "
        f"so with --same-sample {spelt}"
    )


def _wald_first(args: argparse.Namespace, at_nm: list[float]) -> Any:
    """On a terminal (no --json), a callback printing the Wald answer before the profile."""
    import sys

    if args.json or not sys.stdout.isatty():
        return None

    def show(fit: Any) -> None:
        from .. import progress
        from ..fitting.film_display import film_fit_report

        progress.clear()  # the Wald answer starts on a clean line
        try:
            text = film_fit_report(fit.summary(at_nm))
        except ValueError:  # an --at outside the tables: said once, with the final answer
            text = film_fit_report(fit.summary())
        names = ", ".join(fit.result.ci_reasons)
        print(f"{text}\n\nWald intervals above; computing the profile intervals of {names} ...")
        sys.stdout.flush()

    return show


def cmd_film(args: argparse.Namespace) -> int:
    """Fit the film model of the options to the files; print the layers and the fit."""
    from .. import adapters, films
    from ..dataset import concat
    from ..films import FilmError
    from ..fitting.film import fit_film
    from ..fitting.film_display import film_fit_report
    from ..outputs import atomic_output, csv_safe_frame

    fm = _film_model(args)
    at_nm = _at_wavelengths(args.at)
    sigma = _parse_assignments(args.sigma, "--sigma")
    wl_range = None
    if args.wavelength_range is not None:  # the rows, and the range that replaces the file's
        from ..selection import parse_range

        r = parse_range(args.wavelength_range, "--wavelength-range")
        if not 0 <= r.lo < r.hi:
            raise UsageError(
                f"--wavelength-range {args.wavelength_range}: expected MIN:MAX with "
                "0 <= MIN < MAX [nm]"
            )
        wl_range = (r.lo, r.hi)
    spec = films.load_samples(args.model) if args.model is not None else None
    if args.per_sample or spec is not None:  # several samples in one fit
        from .film_multi import cmd_film_samples

        return cmd_film_samples(args, fm, spec, wl_range)
    if not args.files:
        raise UsageError("give the FILE(s) to fit (or a --model with a [samples] table)")
    parts = [adapters.read(p) for p in args.files]
    data = _selected(args, concat(parts))
    res = fit_film(
        fm,
        data,
        wavelength_range_nm=wl_range,
        default_sigma=sigma or None,
        method=args.method,
        seed=args.seed,
        ci=args.ci,
        one_sample=_one_sample(args, parts, data),
        on_wald=_wald_first(args, at_nm),
        depolarization=_DPOL[args.dpol],
    )
    try:
        summary = res.summary(at_nm)
    except FilmError as exc:
        raise UsageError(f"--at {args.at}: {exc}") from None
    if args.output:
        with atomic_output(args.output) as tmp:
            csv_safe_frame(res.nk_table()).to_csv(tmp, index=False)
    if args.fit_json:
        res.save_json(args.fit_json, at_nm)
    if args.json:
        _emit_json(summary)
    else:
        print(film_fit_report(summary))
    return 0


def add_parser(sub: Any) -> None:
    """The ``film`` subcommand's options."""
    from ..fitting.defaults import METHOD

    s = sub.add_parser(
        "film",
        help="fit a thin-film stack (thicknesses, n, k) to psi/Delta, R and T of one sample",
    )
    s.add_argument(
        "files",
        nargs="*",
        action=InputPath,
        metavar="FILE",
        help="files of one sample (joint fit), or of several with --per-sample",
    )
    s.add_argument(
        "--model",
        action=InputPath,
        inside="model",
        default=None,
        metavar="MODEL.toml",
        help="a film model file",
    )
    s.add_argument(
        "--substrate",
        action=InputPath,
        default=None,
        metavar="NAME|FILE",
        help="si, sio2, a dispersion model, or an n,k or ellipsometer file (default si)",
    )
    s.add_argument(
        "--layer",
        action="append",
        default=[],
        metavar="NAME:MATERIAL:THICKNESS[:P=V|LO..HI][:KEYWORD]",
        help="a layer, top first (repeat): V is fixed, LO..HI fitted (started mid-box), and a "
        "material parameter not written is fitted in its default box (Cauchy: A, B, C; its "
        "absorption k_amp stays 0), the rule of --model TOML; e.g. oxide:cauchy:0..20:A=1.3..1.7:"
        "B=0.004 (no --model/--layer: one Cauchy layer on Si). Keywords: incoherent (a thick "
        "layer added in intensity, e.g. sheet:sio2:2e5:incoherent), graded=P (P varies from "
        "P_top to P_bottom in sublayers=N slices, default 20, e.g. "
        "f:cauchy:100..300:graded=A:A_top=1.9..2.3:A_bottom=1.9..2.3)",
    )
    s.add_argument(
        "--substrate-thickness",
        default=None,
        metavar="NM|LO..HI",
        help="a substrate of this thickness [nm] with the ambient behind it: incoherent, its "
        "backside reflection added in intensity (a film on a glass slide); default "
        "semi-infinite",
    )
    s.add_argument(
        "--thickness-spread",
        default=None,
        metavar="S|LO..HI",
        help="relative 1-sigma spread of every coherent layer's thickness over the spot, in "
        "[0, 0.1] (stack.thickness_spread)",
    )
    s.add_argument(
        "--bandwidth",
        default=None,
        metavar="NM|LO..HI",
        help="spectral bandwidth of the instrument, FWHM of a Gaussian, in [0, 20] nm "
        "(stack.bandwidth_nm)",
    )
    s.add_argument(
        "--angle-spread",
        default=None,
        metavar="DEG|LO..HI",
        help="1-sigma spread of the angle of incidence, in [0, 2] deg (stack.angle_spread_deg)",
    )
    s.add_argument(
        "--dpol",
        choices=("auto", "on", "off"),
        default="auto",
        help="fit the files' depolarization channel (WVASE dpolE), each row weighted by its "
        "own sigma, its chi2 reported apart: auto (default) when the model can depolarize "
        "(a spread, bandwidth or angle spread, an incoherent layer or a finite substrate), "
        "as a model that cannot only adds a constant to chi2; on; off",
    )
    s.add_argument(
        "--sigma",
        action="append",
        metavar="QUANTITY=VALUE",
        help="sigma for rows whose file gives none (e.g. reflectance=0.005)",
    )
    s.add_argument(
        "--same-sample",
        action="append",
        # not an InputPath: every name must be one of the FILE inputs (refused otherwise)
        metavar="A,B[,...]",
        help="these FILE inputs are one sample although they state different sample names "
        "(files that do are refused without it)",
    )
    s.add_argument(
        "--per-sample",
        action="append",
        metavar="LAYER.PARAM[,...]",
        help="each FILE is a sample of its own (named after it) and these free "
        "parameters are fitted per sample, the others shared, e.g. film.thickness_nm",
    )
    s.add_argument(
        "--ci",
        choices=("auto", "wald", "profile"),
        default="auto",
        help="95%% intervals: auto (default) prints the covariance (Wald) answer first, "
        "then profiles chi2 only for parameters where that can change the interval (at a "
        "bound, correlated, chi2 not quadratic); wald: none profiled; profile: all",
    )
    s.add_argument(
        "--at",
        default=None,
        metavar="NM[,NM...]",
        help="print every layer's and the substrate's n, k with standard errors at these "
        "wavelengths [nm] (also in --json and --fit-json)",
    )
    s.add_argument("--method", default=METHOD, help="nlopt stages")
    s.add_argument("--seed", type=_fit_seed, default=0, help="the optimiser's seed")
    s.add_argument(
        "-o",
        "--output",
        action=OutputPath,
        suffixes=(".csv",),
        default=None,
        metavar="NK.csv",
        help="write each layer's n, k and their standard errors on the fitted wavelengths",
    )
    s.add_argument(
        "--fit-json",
        action=OutputPath,
        suffixes=(".json",),
        default=None,
        metavar="FIT.json",
        help="write the fit (best-fit stack, intervals) as JSON",
    )
    _add_overwrite(s)
    s.add_argument("--json", action="store_true")
    _add_selection(s)
    s.set_defaults(func=cmd_film)
