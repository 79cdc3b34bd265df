"""``labbrdf validate``: the validation workflow behind ``make report``.

It ingests the bundled fixtures, fits smooth3 and five_param per sample and wavelength,
compares the hemispherical integrals with the spectrophotometer data, runs the tracer
validations and the 2022 factor studies at report scale, runs the model-against-measurement
sections of the user report (roughness against wavelength, the tracer's no-fit prediction
beside a measured BRDF) on the bundled consistent set with a wrong-index control, and
writes (atomically) one self-contained ``index.html``, ``results.json`` (every number on the
page) and the tables as CSV. The exit code is 1 when a check fails, else 0.

Scale
-----
``quick`` (tests, previews) and ``full`` (``make report``, budget 5 minutes on 2 cores) differ
only in the number of rays of the tracer runs (:data:`SCALES`); the fits are the same.
"""

from __future__ import annotations

import os
import platform
from collections.abc import Callable, Mapping, Sequence
from importlib import resources
from pathlib import Path
from typing import Any, Literal

from .. import __version__
from ..parallel import Executor, as_executor
from ..provenance import versions
from . import html
from .builder import Builder, write_report
from .context import Context
from .sections import Section, run
from .sections.colour import colour_section
from .sections.compare import compare_section
from .sections.errata import errata_section
from .sections.fits import fits_section
from .sections.hemispherical import hemispherical_section
from .sections.ingest import fixture_files, fixtures_section
from .sections.model_measurement import model_measurement_section
from .sections.physics import physics_section
from .sections.prediction import prediction_section
from .sections.scans import scans_section
from .sections.smoothness import smoothness_section
from .sections.spectra import spectra_section
from .sections.surface import gaussian_acf_section
from .sections.tracer import factor_maps_section, validation_section

__all__ = [
    "SCALES",
    "SECTIONS",
    "SECTION_IDS",
    "default_fixtures_dir",
    "default_shared_dir",
    "fixture_files",
    "validate",
]

#: rays per tracer run and the grid of the factor-study maps. ``factor``: each of the 15
#: factor-study runs (the 2022 paper used 2e5 rays; 5e5 here so that the broad alpha = 0.6
#: map still has bins with the >= 20 rays the claims checker reads, on the paper's 1-degree
#: grid); ``validation``: each tracer-validation run (albedo statistical error <=
#: 0.5/sqrt(N): 1.6e-3 quick, 5e-4 full); ``prediction``: each run of the model-against-
#: measurement section (the tracer's specular DOP and BRDF of the bundled sample; a bare
#: substrate's single scattering is closed form, so rays set only the batch statistics).
#: Quick mode maps use 6-degree bins.
SCALES: dict[str, dict[str, int]] = {
    "quick": {"factor": 20_000, "validation": 100_000, "grid_step_deg": 6, "prediction": 16_384},
    "full": {
        "factor": 500_000,
        "validation": 1_000_000,
        "grid_step_deg": 1,
        "prediction": 131_072,
    },
}


def _fits(ctx: Context) -> None:
    fits_section(
        ctx,
        [("smooth3", {}), ("five_param", {})],
        published_check=True,
        chi2_models=["smooth3"],
    )


def _scans(ctx: Context) -> None:
    scans_section(ctx, ["smooth3", "five_param"])


def _spectra(ctx: Context) -> None:
    spectra_section(ctx, "smooth3")
    spectra_section(ctx, "five_param")


def _hemispherical(ctx: Context) -> None:
    hemispherical_section(ctx, "OSR")


def _physics(ctx: Context) -> None:
    physics_section(ctx, angles_deg=(0.0, 30.0, 45.0, 60.0))


def _compare(ctx: Context) -> None:
    compare_section(ctx, 45.0, sample="OSR")


def _model_measurement(ctx: Context) -> None:
    model_measurement_section(ctx, smoothness_section, prediction_section)


#: the validation report's sections in page order: (id, title, function of the Context)
SECTIONS: list[Section] = [
    ("ingest", "Ingested files", fixtures_section),
    ("fits", "Fitted parameters per sample and wavelength (Tables 1-2 style)", _fits),
    ("scans", "Measured points and model curves (Figs. 2-3 style)", _scans),
    ("spectra", "Parameter spectra against wavelength", _spectra),
    (
        "hemispherical",
        "Hemispherical integral against the spectrophotometer (Table 3)",
        _hemispherical,
    ),
    ("physics", "Energy conservation and reciprocity of every fitted model", _physics),
    ("compare", "3- vs 5-parameter model (Fig. 4 style)", _compare),
    ("colour", "Sample colour from the spectrophotometer reflectance", colour_section),
    (
        "tracer_maps",
        "Tracer S0 and DOP hemisphere maps: the 2022 factor studies",
        factor_maps_section,
    ),
    (
        "tracer_validation",
        "Tracer validation: analytic limits and oracles",
        validation_section,
    ),
    (
        "surface",
        "Gaussian random surfaces: ACF of eq. (1) from the corrected PSD eq. (2) (2022)",
        gaussian_acf_section,
    ),
    (
        "model_measurement",
        "Model against measurement: roughness, specular DOP and BRDF predicted with no fit",
        _model_measurement,
    ),
    ("errata", "Paper errata this report depends on", errata_section),
]

#: section ids in page order
SECTION_IDS = tuple(sid for sid, _, _ in SECTIONS)

#: the source tree's root when labbrdf runs from a checkout (its parent may hold ../shared)
_ROOT = Path(__file__).resolve().parents[2]


def default_fixtures_dir() -> Path:
    """The fixtures shipped in the package, ``labbrdf/data/fixtures`` (or ``$LABBRDF_FIXTURES``).

    Found through :mod:`importlib.resources`, so that an installed wheel finds them too.
    """
    env = os.environ.get("LABBRDF_FIXTURES")
    if env:
        return Path(env)
    # a wheel installs as plain files, so the resource folder is a real directory
    return Path(str(resources.files("labbrdf") / "data" / "fixtures"))


def default_shared_dir() -> Path | None:
    """``../shared`` next to the project (or ``$LABBRDF_SHARED``), None when absent."""
    p = Path(os.environ.get("LABBRDF_SHARED", _ROOT.parent / "shared"))
    return p if p.is_dir() else None


def validate(
    out: str | os.PathLike[str] = "reports/validation",
    quick: bool = False,
    progress: bool = True,
    executor: Executor | str | None = None,
    workers: int | None = None,
    *,
    scheduler: str | None = None,
    fixtures_dir: str | os.PathLike[str] | None = None,
    shared_dir: str | os.PathLike[str] | Literal[False] | None = None,
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
    executor : Executor or str, optional
        Where the fits and the tracer runs go (:class:`labbrdf.parallel.Executor`, or a
        scheduler name); default ``labbrdf.parallel.DEFAULT_SCHEDULER``.
    workers : int, optional
        Worker processes, with a scheduler name or the default executor.
    scheduler : str, optional
        The older keyword for a scheduler name (not together with ``executor``).
    fixtures_dir : path-like, optional
        The fixture folder (default: :func:`default_fixtures_dir`).
    shared_dir : path-like, False or None
        ``../shared`` with the oracles; None finds it next to the project; False: act as if
        it were absent (oracle checks SKIPPED with the reason).
    sections_to_run : sequence of str, optional
        A subset of :data:`SECTION_IDS` (tests); the others are listed as not run.
    extra_checks : sequence of callables
        ``f(builder)`` each adding checks to a final "extra checks" section (tests inject a
        failing check here).
    fit_options : mapping, optional
        Further :func:`labbrdf.fitting.fit` keywords for every fit (tests starve ``maxeval`` to
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
    # a bad scheduler name or missing dask fails here, not per section
    ex = as_executor(executor, scheduler=scheduler, workers=workers, progress=progress)
    todo = list(SECTION_IDS if sections_to_run is None else sections_to_run)
    unknown = [s for s in todo if s not in SECTION_IDS]
    if unknown:
        raise ValueError(f"unknown section(s) {unknown}; sections are {list(SECTION_IDS)}")
    b = Builder(
        "labbrdf validation report",
        progress=progress,
        meta={
            "labbrdf_version": __version__,
            "mode": scale_name,
            "scale": SCALES[scale_name],
            "fixtures_dir": str(fx),
            "shared_dir": str(shared) if shared else None,
            "python": platform.python_version(),
            "environment": versions(),
            "scheduler": ex.scheduler,
            "workers": ex.workers,
            "sections_run": todo,
        },
    )
    ctx = Context(
        b,
        quick=quick,
        executor=ex,
        fit_options=dict(fit_options or {}),
        scale=SCALES[scale_name],
        fixtures=fx,
        shared=shared,
    )
    # ingest always runs: every other section reads what it ingested
    run(ctx, SECTIONS, only={"ingest", *todo})
    if extra_checks:
        with b.section("extra", "Extra checks"):
            for f in extra_checks:
                f(b)
    skipped = [s for s in SECTION_IDS if s not in todo]
    if skipped:
        b.results["meta"]["sections_not_run"] = skipped
    code = b.finish()
    page = html.render(b.results, b.images, b.swatches)
    write_report(out, b.results, page, inputs=[fx])
    b.log(f"wrote {Path(out).resolve() / 'index.html'}: {b.results['summary']}")
    return code
