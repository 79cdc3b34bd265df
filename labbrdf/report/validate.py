"""``labbrdf validate``: the validation workflow behind ``make report``.

It ingests the bundled fixtures, fits smooth3 and five_param per sample and wavelength,
compares the hemispherical integrals with the spectrophotometer data, runs the tracer
validations and the 2022 factor studies at report scale, and writes (atomically) one
self-contained ``index.html``, ``results.json`` (every number on the page) and the tables as
CSV. The exit code is 1 when a check fails, else 0.

Scale
-----
``quick`` (tests, previews) and ``full`` (``make report``, budget 5 minutes on 2 cores) differ
only in the number of rays of the tracer runs (:data:`SCALES`); the fits are the same.
"""

from __future__ import annotations

import os
import platform
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

from ..provenance import versions
from . import figure_sections, html, paper, properties, sections, tracer_sections
from ._common import Builder, Unavailable, write_report

__all__ = ["SCALES", "SECTIONS", "default_fixtures_dir", "default_shared_dir", "validate"]

#: rays per tracer run and the grid of the factor-study maps. ``factor``: each of the 15
#: factor-study runs (the 2022 paper used 2e5 rays; 5e5 here so that the broad alpha = 0.6
#: map still has bins with the >= 20 rays the claims checker reads, on the paper's 1-degree
#: grid); ``validation``: each tracer-validation run (albedo statistical error <=
#: 0.5/sqrt(N): 1.6e-3 quick, 5e-4 full). Quick mode maps use 6-degree bins.
SCALES: dict[str, dict[str, int]] = {
    "quick": {"factor": 20_000, "validation": 100_000, "grid_step_deg": 6},
    "full": {"factor": 500_000, "validation": 1_000_000, "grid_step_deg": 1},
}

#: section ids in page order
SECTIONS = (
    "ingest",
    "fits",
    "scans",
    "spectra",
    "hemispherical",
    "physics",
    "compare",
    "colour",
    "tracer_maps",
    "tracer_validation",
    "errata",
)

_ROOT = Path(__file__).resolve().parents[2]


def default_fixtures_dir() -> Path:
    """The bundled ``fixtures/`` folder of the source tree (or ``$LABBRDF_FIXTURES``)."""
    return Path(os.environ.get("LABBRDF_FIXTURES", _ROOT / "fixtures"))


def default_shared_dir() -> Path | None:
    """``../shared`` next to the project (or ``$LABBRDF_SHARED``), None when absent."""
    p = Path(os.environ.get("LABBRDF_SHARED", _ROOT.parent / "shared"))
    return p if p.is_dir() else None


def fixture_files(folder: Path) -> list[Path]:
    """Every data file under ``folder`` except ``published/``, docs and the generator."""
    skip_dirs = {"published", "__pycache__"}
    out = []
    for p in sorted(folder.rglob("*")):
        rel = p.relative_to(folder)
        if not p.is_file() or any(part in skip_dirs or part.startswith(".") for part in rel.parts):
            continue
        if p.suffix.lower() in (".md", ".py", ".txt", ".pyc") or p.name.startswith("."):
            continue
        out.append(p)
    return out


def validate(
    out: str | os.PathLike[str] = "reports/validation",
    quick: bool = False,
    progress: bool = True,
    scheduler: str | None = None,
    workers: int | None = None,
    *,
    fixtures_dir: str | os.PathLike[str] | None = None,
    shared_dir: str | os.PathLike[str] | None | bool = None,
    sections_to_run: Sequence[str] | None = None,
    extra_checks: Sequence[Callable[[Builder], Any]] = (),
    fit_options: Mapping[str, Any] | None = None,
) -> int:
    """Run the validation and write the report folder ``out``.

    Parameters
    ----------
    out : str or path-like
        Output folder; replaced atomically (built in a temporary sibling, then renamed in).
    quick : bool
        Small tracer scale (:data:`SCALES`) for tests and previews.
    progress : bool
        Progress lines on stderr.
    scheduler, workers :
        Executor for the fits and the tracer runs (see :mod:`labbrdf.parallel`); None runs
        in this process.
    fixtures_dir : path-like, optional
        The fixture folder (default: the bundled ``fixtures/``).
    shared_dir : path-like, False or None
        ``../shared`` with the oracles; None finds it next to the project; False: act as if
        it were absent (oracle checks SKIPPED with the reason).
    sections_to_run : sequence of str, optional
        A subset of :data:`SECTIONS` (tests); the others are listed as not run.
    extra_checks : sequence of callables
        ``f(builder)`` each adding checks to a final "extra checks" section (tests inject a
        failing check here).
    fit_options : mapping, optional
        Further :func:`labbrdf.fit` keywords for every fit (tests starve ``maxeval`` to
        show that the fits' success check can fail).

    Returns
    -------
    int
        0 when every check passed or was skipped, 1 when one failed.
    """
    scale_name = "quick" if quick else "full"
    fx = Path(fixtures_dir) if fixtures_dir is not None else default_fixtures_dir()
    from ..outputs import check_report_dir

    check_report_dir(out, inputs=[fx], option="out")  # refused before the run, not after
    if shared_dir is False:
        shared = None
    elif shared_dir is None:
        shared = default_shared_dir()
    else:
        shared = Path(shared_dir) if Path(shared_dir).is_dir() else None
    if scheduler is not None:
        from labbrdf.parallel import check_scheduler

        check_scheduler(scheduler)  # a bad name or missing dask fails here, not per section
    todo = list(SECTIONS if sections_to_run is None else sections_to_run)
    unknown = [s for s in todo if s not in SECTIONS]
    if unknown:
        raise ValueError(f"unknown section(s) {unknown}; sections are {list(SECTIONS)}")
    import labbrdf

    b = Builder(
        "labbrdf validation report",
        progress=progress,
        meta={
            "labbrdf_version": labbrdf.__version__,
            "mode": scale_name,
            "scale": SCALES[scale_name],
            "fixtures_dir": str(fx),
            "shared_dir": str(shared) if shared else None,
            "python": platform.python_version(),
            "environment": versions(),
            "scheduler": scheduler or "serial",
            "workers": workers,
            "sections_run": todo,
        },
    )
    ctx = sections.Context(
        b,
        quick=quick,
        scheduler=scheduler,
        workers=workers,
        progress=progress,
        fit_options=dict(fit_options or {}),
    )
    ctx.extra.update({"scale": SCALES[scale_name], "shared": shared, "fixtures": fx})

    def want(sid: str) -> bool:
        return sid in todo

    with b.section("ingest", "Ingested files"):
        b.text(
            f"Fixture folder: {fx}. Every file below was read with labbrdf.read (format "
            "from the extension and the header) into the common dataset. The fixtures are "
            "SYNTHETIC files in real export formats, see fixtures/README.md."
        )
        pub = paper.load_published(ctx, fx / "published")
        b.text("Published tables read: " + (", ".join(pub) if pub else "none found") + ".")
        if not fx.is_dir():
            raise Unavailable(f"fixture folder {fx} not found")
        files = fixture_files(fx)
        sections.ingest(ctx, files, root=fx)
    steps: list[tuple[str, str, Callable[[], None]]] = [
        (
            "fits",
            "Fitted parameters per sample and wavelength (Tables 1-2 style)",
            lambda: sections.fits_section(
                ctx,
                [("smooth3", {}), ("five_param", {})],
                published_check=True,
                chi2_models=["smooth3"],
            ),
        ),
        (
            "scans",
            "Measured points and model curves (Figs. 2-3 style)",
            lambda: figure_sections.scans_section(ctx, ["smooth3", "five_param"]),
        ),
        (
            "spectra",
            "Parameter spectra against wavelength",
            lambda: [
                figure_sections.spectra_section(ctx, "smooth3"),
                figure_sections.spectra_section(ctx, "five_param"),
            ],
        ),
        (
            "hemispherical",
            "Hemispherical integral against the spectrophotometer (Table 3)",
            lambda: paper.hemispherical_section(ctx, "OSR"),
        ),
        (
            "physics",
            "Energy conservation and reciprocity of every fitted model",
            lambda: properties.physics_section(ctx, angles_deg=(0.0, 30.0, 45.0, 60.0)),
        ),
        (
            "compare",
            "3- vs 5-parameter model (Fig. 4 style)",
            lambda: figure_sections.compare_section(ctx, 45.0, sample="OSR"),
        ),
        (
            "colour",
            "Sample colour from the spectrophotometer reflectance",
            lambda: properties.colour_section(ctx),
        ),
        (
            "tracer_maps",
            "Tracer S0 and DOP hemisphere maps: the 2022 factor studies",
            lambda: tracer_sections.factor_maps_section(ctx),
        ),
        (
            "tracer_validation",
            "Tracer validation: analytic limits and oracles",
            lambda: tracer_sections.validation_section(ctx),
        ),
        ("errata", "Paper errata this report depends on", lambda: paper.errata_section(ctx)),
    ]
    for sid, title, fn in steps:
        if not want(sid):
            continue
        with b.section(sid, title):
            fn()
    if extra_checks:
        with b.section("extra", "Extra checks"):
            for f in extra_checks:
                f(b)
    skipped = [s for s in SECTIONS if s not in todo]
    if skipped:
        b.results["meta"]["sections_not_run"] = skipped
    code = b.finish()
    page = html.render(b.results, b.images, b.swatches)
    write_report(out, b.results, page, inputs=[fx])
    b.log(f"wrote {Path(out).resolve() / 'index.html'}: {b.results['summary']}")
    return code
