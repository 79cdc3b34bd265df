"""The report for a user's own files (``labbrdf report DATA --model NAME -o DIR``).

The same kind of page as the validation report: what was ingested, a figure of every
measured quantity per file, optical constants from psi/Delta with the Fresnel reflectance
compared with measured reflectance, the fits (per sample and
wavelength, with uncertainties, intervals, flags and RMSE), measured points with the model
curves and residuals, parameter spectra, energy and reciprocity of every fit, and the sample
colour when spectrophotometer reflectance is among the files, and, for a sample with a
height map, psi/Delta and a measured ``.bsdf``, the tracer's prediction beside the BRDF.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from .. import __version__, models
from ..films import FilmModel
from ..fitting import METHOD
from ..parallel import Executor, as_executor
from ..provenance import versions
from ..sample import bulk_index
from . import html
from .builder import Builder, Unavailable, write_report
from .context import Context
from .inputs import ingest_inputs
from .pairing import sample_groups
from .sections import Section, run
from .sections.brdf import brdf_section
from .sections.colour import colour_section
from .sections.film import film_model_of, film_section
from .sections.fits import fits_section
from .sections.measured import measured_section
from .sections.nk import nk_section
from .sections.physics import physics_section
from .sections.prediction import SLOPES, prediction_section
from .sections.psd import psd_section
from .sections.scans import scans_section
from .sections.scatter import scatter_section
from .sections.smoothness import smoothness_section
from .sections.spectra import spectra_section
from .sections.surface import TRACE_WAVELENGTH_NM, surface_section

__all__ = ["user_report"]


#: fewest points of one (sample, wavelength) scan that a BRDF model is fitted to
MIN_SCAN_POINTS = 4


def _brdf_scans(ctx: Context) -> bool:
    """True when there are BRDF scans to fit; else :class:`Unavailable` with the reason."""
    try:
        scans = ctx.scans()
    except Unavailable as exc:
        raise Unavailable(f"no BRDF rows: no BRDF fit ({exc})") from None
    sizes = scans.groupby(["sample", "wavelength_nm"]).size()
    if int(sizes.max()) < MIN_SCAN_POINTS:
        q = ", ".join(sorted(set(scans["quantity"].astype(str))))
        raise Unavailable(
            f"no BRDF scans: the {q} rows have at most {int(sizes.max())} point(s) per "
            f"(sample, wavelength), e.g. an ellipsometer's intensity at one angle; a fit "
            f"needs {MIN_SCAN_POINTS} or more: no BRDF fit"
        )
    return True


def _fitted(results: Mapping[str, Any]) -> bool:
    """Whether a fit section ran: the specular fits or the BRDF fits."""
    return any(s["id"] in ("fits", "brdf") and s["status"] == "ok" for s in results["sections"])


def user_report(
    paths: Sequence[str | os.PathLike[str]],
    model: str,
    out: str | os.PathLike[str],
    *,
    options: Mapping[str, Any] | None = None,
    method: str = METHOD,
    seed: int = 0,
    progress: bool = True,
    executor: Executor | str | None = None,
    workers: int | None = None,
    scheduler: str | None = None,
    title: str | None = None,
    start: Mapping[str, float] | None = None,
    selection: Mapping[str, Any] | None = None,
    film_model: str | os.PathLike[str] | FilmModel | None = None,
    same_sample: Sequence[Sequence[str | os.PathLike[str]]] = (),
    prediction_slopes: str = "ggx",
    nk_from: str | os.PathLike[str] | None = None,
    film_files: Sequence[str | os.PathLike[str]] | None = None,
    wavelength_nm: float | None = None,
    **kw: Any,
) -> int:
    """Build a report for the given files and write it (atomically) to ``out``.

    Parameters
    ----------
    paths : sequence of path-like
        Instrument export files (any format :func:`labbrdf.read` knows), and topography
        files (height maps, profiles) for the section ``surface``.
    model : str
        Registry name of the model to fit (``smooth3``, ``five_param``, ``microfacet``).
    out : path-like
        Output folder (``index.html``, ``results.json``, ``tables/*.csv``).
    options : mapping, optional
        Model options, e.g. ``{"shadowing": "mb"}`` for five_param.
    method, seed :
        Optimiser (nlopt names joined by ``+``) and seed, as for :func:`labbrdf.fitting.fit`.
    progress : bool
        Progress lines on stderr.
    executor : Executor or str, optional
        Where the fits and tracer runs go (:class:`labbrdf.parallel.Executor`, or a
        scheduler name); default ``labbrdf.parallel.DEFAULT_SCHEDULER``.
    workers : int, optional
        Worker processes, with a scheduler name or the default executor.
    scheduler : str, optional
        The older keyword for a scheduler name (not together with ``executor``).
    title : str, optional
        Page title (default: "labbrdf report: <model> fits", or "... nothing fitted"
        when no section could fit the model).
    start : mapping, optional
        Starting values of model parameters (name -> value) for every fit.
    selection : mapping, optional
        Rows to keep, as :func:`labbrdf.selection.select` takes them (``wavelength``,
        ``theta_i``, ``quantity``, ``sample``); applied to every file after reading.
    film_model : path-like or FilmModel, optional
        A film model (a TOML file, :func:`labbrdf.films.load_model`, or a
        :class:`~labbrdf.films.FilmModel`, e.g. :func:`.sections.film.default_film_model`)
        fitted to the psi/Delta files whose angles disagree (section ``film``).
    film_files, wavelength_nm : optional
        The film model's files (section ``film``); the [nm] of files that state none.
    same_sample : sequence of sequences of path-like
        Files that are one sample, one sequence per sample (each file among ``paths``),
        in addition to the sample names the files state (:func:`labbrdf.samples.pair_samples`);
        the section ``ingest`` shows the groups and why.
    prediction_slopes : {"ggx", "measured"}
        The roughness the section ``prediction`` traces: the GGX alpha of the height map's
        slopes (default), or their measured table
        (:mod:`labbrdf.report.sections.prediction` says why GGX is the default).
    nk_from : path-like, optional
        An ellipsometer file of the substrate: its bulk n, k at the traced wavelength are
        the substrate of the section ``surface``'s tracer maps (as ``labbrdf trace
        --nk-from``). Default: the psi/Delta file of each map's sample group, else a stated
        default (:func:`labbrdf.report.sections.surface.substrate_index`).
    **kw :
        ``quick``: accepted as :func:`~labbrdf.report.validate` takes it (no effect).

    Returns
    -------
    int
        0 when every check passed or was skipped, 1 when one failed (e.g. a file that
        cannot be read).

    Raises
    ------
    ValueError
        No paths, an unknown model name or option, a film model file with an error
        (naming the file and the line), a ``same_sample`` mapping that cannot hold
        (:class:`labbrdf.samples.PairingError`), a ``start`` value outside its parameter's
        bounds, an unknown ``prediction_slopes``, an ``nk_from`` file that gives no bulk
        index at the traced wavelength (:class:`labbrdf.NkError`), or an
        output folder that is refused
        (:class:`labbrdf.outputs.OutputError`), all before any work.
    """
    unknown = set(kw) - {"quick"}
    if unknown:
        raise TypeError(f"user_report() got unexpected keyword argument(s) {sorted(unknown)}")
    if prediction_slopes not in SLOPES:
        raise ValueError(
            f"prediction_slopes: expected one of {', '.join(SLOPES)}, got {prediction_slopes!r}"
        )
    paths, model_file, opts = _refused_early(
        paths, model, options, out, film_model, same_sample, nk_from
    )
    _check_start(model, opts, start)
    substrate = (
        None if nk_from is None else (str(nk_from), bulk_index(nk_from, TRACE_WAVELENGTH_NM))
    )
    film, film_how = film_model_of(film_model)
    meta = {"model": model, "options": opts, "method": method, "seed": seed}
    meta.update(files=[str(p) for p in paths], film_model=film_how or None)
    meta.update(prediction_slopes=prediction_slopes)
    if nk_from is not None:
        meta.update(nk_from=str(nk_from))
    b = Builder(title or f"labbrdf report: {model} fits", progress=progress, meta=_meta(meta))
    ctx = Context(
        b,
        executor=as_executor(executor, scheduler=scheduler, workers=workers, progress=progress),
        method=method,
        seed=seed,
        fit_options={"params": dict(start)} if start else {},
        wavelength_nm=wavelength_nm,
    )

    film_of = (film, film_how, film_files)
    sections = _sections(
        model, opts, film_of, paths, selection, same_sample, prediction_slopes, substrate
    )
    run(ctx, sections)
    if title is None and not _fitted(b.results):
        b.results["title"] = f"labbrdf report: {len(paths)} file(s), nothing fitted"
    code = b.finish()
    page = html.render(b.results, b.images, b.swatches)
    nk_file = [] if nk_from is None else [Path(nk_from)]
    write_report(out, b.results, page, inputs=[*paths, *model_file, *nk_file], files=b.files)
    b.log(f"wrote {Path(out).resolve() / 'index.html'}: {b.results['summary']}")
    return code


def _meta(run: dict[str, Any]) -> dict[str, Any]:
    """The page's meta: the version, the mode, what was run, the environment."""
    return {"labbrdf_version": __version__, "mode": "user", **run, "environment": versions()}


def _refused_early(
    paths: Sequence[str | os.PathLike[str]] | str | os.PathLike[str],
    model: str,
    options: Mapping[str, Any] | None,
    out: str | os.PathLike[str],
    film_model: str | os.PathLike[str] | FilmModel | None,
    same_sample: Sequence[Sequence[str | os.PathLike[str]]],
    nk_from: str | os.PathLike[str] | None = None,
) -> tuple[list[Path], list[str | os.PathLike[str]], dict[str, Any]]:
    """Refuse bad arguments before any work: the paths, the model file, the options.

    Returns the paths, the model file as an input (never inside the replaced folder) and
    the model options; raises ValueError (see :func:`user_report`).
    """
    from ..outputs import check_report_dir
    from ..samples import pair_samples

    files = [Path(p) for p in ([paths] if isinstance(paths, (str, os.PathLike)) else paths)]
    if not files:
        raise ValueError("paths: expected at least one data file")
    model_file: list[str | os.PathLike[str]] = (
        [Path(film_model)] if isinstance(film_model, (str, os.PathLike)) else []
    )
    nk_file = [] if nk_from is None else [Path(nk_from)]
    check_report_dir(out, inputs=[*files, *model_file, *nk_file])  # refused before any work
    pair_samples(files, same_sample)  # a mapping that cannot hold
    opts = dict(options or {})
    try:
        models.get(model, **opts)
    except Exception as exc:
        raise ValueError(f"model: {exc}") from None
    return files, model_file, opts


def _check_start(model: str, opts: Mapping[str, Any], start: Mapping[str, float] | None) -> None:
    """Refuse a start value outside its parameter's bounds before any work (ValueError)."""
    m = models.get(model, **opts)
    for name, value in (start or {}).items():
        try:
            m.check_value(name, value)
        except ValueError as exc:
            raise ValueError(f"start: {exc}") from None


def _ingest(
    ctx: Context,
    paths: Sequence[str | os.PathLike[str]],
    selection: Mapping[str, Any] | None,
    same_sample: Sequence[Sequence[str | os.PathLike[str]]] = (),
) -> None:
    """Read every file (optical data or height maps), then apply the row selection.

    A file that cannot be read is named with its reason and left out: the rest of the report
    is what it would be without it (its sample groups too).
    """
    ctx.b.text(
        f"{len(paths)} file(s) given; each was read once with labbrdf.read_inputs: an "
        "optical export into the common dataset, a topography file (height map or profile) "
        "with SurfaceTopography."
    )
    read = ingest_inputs(ctx, paths)
    if ctx.wavelength_nm is not None:
        _given_wavelength(ctx, ctx.wavelength_nm)
    sample_groups(ctx, read, _among(same_sample, read))
    if selection:
        from ..selection import SelectionError, select

        kept = []
        for f in ctx.frames:
            try:
                kept.append(select(f, **selection))
            except SelectionError:
                continue
        ctx.b.text(
            "Selection applied to every file: "
            + ", ".join(f"{k} {v}" for k, v in selection.items())
            + f"; {sum(len(f) for f in kept)} of {sum(len(f) for f in ctx.frames)} rows kept."
        )
        ctx.frames[:] = [f for f in kept if len(f)]


def _given_wavelength(ctx: Context, wl: float) -> None:
    """The rows of every file that states no wavelength get ``wl`` [nm]; the page says so."""
    given, stated = [], []
    for rec in ctx.files:
        meta = rec.get("meta") or {}
        if meta.get("wavelength_stated") is not False:
            stated.append(str(rec["file"]))
            continue
        given.append(str(rec["file"]))
        for j, f in enumerate(ctx.frames):
            mine = (f["source"].astype(str) == rec["file"]).to_numpy()
            if mine.any():
                ctx.frames[j] = f.assign(wavelength_nm=f["wavelength_nm"].where(~mine, wl))
        rec["meta"] = {**meta, "wavelength_nm": wl, "wavelength_stated": True,
                       "wavelength_given": True}  # fmt: skip
    ctx.b.text(
        f"Wavelength given with --wavelength: {wl:g} nm, for the files that state none ("
        + (", ".join(given) or "none of the files")
        + ")"
        + (f"; the others keep their own ({', '.join(stated)})." if stated else ".")
    )


def _among(
    groups: Sequence[Sequence[str | os.PathLike[str]]], paths: Sequence[str | os.PathLike[str]]
) -> list[list[str | os.PathLike[str]]]:
    """The given sample groups restricted to ``paths`` (the files read).

    A group left with fewer than two files is no group.
    """
    keep = {os.path.normcase(os.path.realpath(os.fspath(p))) for p in paths}
    out = []
    for g in groups:
        left = [p for p in g if os.path.normcase(os.path.realpath(os.fspath(p))) in keep]
        if len(left) >= 2:
            out.append(left)
    return out


def _sections(
    model: str,
    opts: dict[str, Any],
    film_of: tuple[Any, str, Sequence[str | os.PathLike[str]] | None],
    paths: Sequence[str | os.PathLike[str]],
    selection: Mapping[str, Any] | None,
    same_sample: Sequence[Sequence[str | os.PathLike[str]]] = (),
    prediction_slopes: str = "ggx",
    substrate: tuple[str, complex] | None = None,
) -> list[Section]:
    """The user report's sections, in order, bound to its model, film model and files.

    ``film_of``: the film model, how it was given, and the files it is of (or None).
    """
    film, film_how, film_files = film_of
    names = None if film_files is None else [Path(f).name for f in film_files]
    return [
        ("ingest", "Ingested files", lambda ctx: _ingest(ctx, paths, selection, same_sample)),
        ("measured", "Measured data, file by file", measured_section),
        ("nk", "Optical constants and cross-instrument comparison", nk_section),
        (
            "film",
            "Film stacks fitted to angle-dependent psi/Delta",
            lambda ctx: film_section(ctx, film, how=film_how, film_files=names),
        ),
        (
            "fits",
            f"Fitted {model} parameters per sample and wavelength",
            lambda ctx: fits_section(ctx, [(model, opts)]) if _brdf_scans(ctx) else None,
        ),
        ("scans", "Measured points and model curves", lambda ctx: scans_section(ctx, [model])),
        (
            "spectra",
            "Parameter spectra against wavelength",
            lambda ctx: spectra_section(ctx, model),
        ),
        ("physics", "Energy conservation and reciprocity of every fit", physics_section),
        (
            "brdf",
            f"Measured BRDF: {model} per angle of incidence, maps, energy, reciprocity",
            lambda ctx: brdf_section(ctx, model, opts),
        ),
        (
            "scatter",
            "Measured BSDF for the designer: ABg and Harvey-Shack beside the physical models",
            lambda ctx: scatter_section(ctx, model, opts),
        ),
        ("colour", "Sample colour from spectrophotometer reflectance", colour_section),
        (
            "surface",
            "Measured surface topography",
            lambda ctx: surface_section(ctx, nk_from=substrate),
        ),
        ("psd", "Surface power spectral density", psd_section),
        (
            "smoothness",
            "Roughness against wavelength: Rayleigh criterion and specular loss",
            smoothness_section,
        ),
        (
            "prediction",
            "Predict, then measure: the tracer or Rayleigh-Rice beside the BRDF",
            lambda ctx: prediction_section(ctx, slopes=prediction_slopes),
        ),
    ]
