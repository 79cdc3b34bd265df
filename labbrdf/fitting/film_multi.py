"""Several samples in one film fit: shared parameters and each sample's own.

Labs fit several wafers of one process with shared optical constants and their own
thicknesses, or one wafer before and after a treatment. :func:`fit_film_samples` builds
one residual vector from every sample's rows (as :func:`labbrdf.fitting.film.fit_film`
does for one sample) and fits one parameter set through the one fitting core: a
parameter named in ``per_sample`` becomes one parameter per sample,
``"<layer>.<parameter>[<sample>]"`` (``"film.thickness_nm[wafer2]"``); every other free
parameter is shared. Intervals, correlations and flags are the core's, for each of them.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from scipy import special

from ..films import FilmError, FilmModel, Stack, load_model, load_samples
from ..jsonsafe import jsonable
from ..models import Model, Parameters
from ..nk.reading import tabulated_from_file
from .core import METHOD, fit
from .data import FitData, FitError
from .film import FilmFit, _check_coverage, _film_rows, _FilmFitModel, woollam_mse
from .result import FitResult

__all__ = ["MultiFilmFit", "fit_film_samples", "per_sample_name"]


def per_sample_name(name: str, sample: str) -> str:
    """The fitted name of the per-sample parameter ``name`` of ``sample``: ``name[sample]``."""
    return f"{name}[{sample}]"


class _MultiFilmModel(Model):
    """One film model over the rows of several samples (each sample's rows a slice)."""

    name = "film (several samples)"
    quantities = _FilmFitModel.quantities
    reference = _FilmFitModel.reference
    least_squares_local = _FilmFitModel.least_squares_local

    def __init__(
        self,
        fm: FilmModel,
        per_sample: Sequence[str],
        parts: Mapping[str, tuple[slice, _FilmFitModel]],
    ) -> None:
        self.fm = fm
        self.per_sample = tuple(per_sample)
        self.parts = dict(parts)
        self.n_rows = max(sl.stop for sl, _ in self.parts.values())
        super().__init__()

    def default_params(self) -> Parameters:
        one = _FilmFitModel(self.fm, np.zeros(0), np.zeros(0)).default_params()
        p = Parameters()
        for k in one:
            q = one[k]
            names = [per_sample_name(k, s) for s in self.parts] if k in self.per_sample else [k]
            for n in names:
                p.add(n, q.value, q.min, q.max, q.vary, q.units)
        return p

    def sample_values(self, p: Mapping[str, float], sample: str) -> dict[str, float]:
        """The ``"<layer>.<parameter>"`` values of one sample from the fitted names."""
        return {
            k: p[per_sample_name(k, sample) if k in self.per_sample else k] for k in self.fm.free
        }

    def _evaluate(self, p, theta_i, theta_r, phi_r, wavelength):
        if wavelength is None or np.shape(theta_i) != (self.n_rows,):
            raise FitError("film model: evaluated on rows other than the fitted data")
        ti, wl = np.degrees(theta_i), np.asarray(wavelength, float)
        out = np.empty(self.n_rows)
        try:
            for s, (sl, part) in self.parts.items():
                out[sl] = part.rows(self.sample_values(p, s), ti[sl], wl[sl])
        except ValueError:  # parameters outside the physical domain
            out[:] = np.nan
        return out


@dataclass
class MultiFilmFit:
    """A fit of several samples: the core's :class:`~labbrdf.FitResult` and each stack.

    Attributes
    ----------
    result : FitResult
        Shared parameters under their own names, per-sample ones as ``name[sample]``.
    model : FilmModel
        The model (starting values and boxes) every sample shares.
    per_sample : tuple of str
        The ``"<layer>.<parameter>"`` names fitted per sample.
    stacks : dict
        Sample name -> its best-fit :class:`labbrdf.Stack`.
    data : pandas.DataFrame
        The fitted rows, with a ``fit_sample`` column naming each row's sample.
    sources : dict
        Sample name -> the files of its rows.
    """

    result: FitResult
    model: FilmModel
    per_sample: tuple[str, ...]
    stacks: dict[str, Stack]
    data: pd.DataFrame
    sources: dict[str, list[str]]

    @property
    def samples(self) -> list[str]:
        """The sample names, in the order given."""
        return list(self.stacks)

    @property
    def mse(self) -> float:
        """Woollam's MSE over all samples (:func:`~labbrdf.fitting.film.woollam_mse`)."""
        return woollam_mse(self.result.chisqr, self.result.ndata, self.result.nvarys)

    @property
    def misfit_scale(self) -> float | None:
        """``sqrt(chi2/nu)`` when chi-square rejects the model at the 1 % level, else None.

        As :attr:`labbrdf.FilmFit.misfit_scale`: ``*_scaled`` intervals are
        the stderr times this factor.
        """
        res = self.result
        if res.nfree <= 0 or not math.isfinite(res.chisqr):
            return None
        if special.chdtrc(res.nfree, res.chisqr) >= 0.01:
            return None
        return math.sqrt(res.redchi)

    @property
    def verdict(self) -> str | None:
        """Words saying that the model is wrong (MSE above ``MSE_WRONG_MODEL``), or None.

        As :attr:`labbrdf.FilmFit.verdict`, on the MSE over all samples.
        """
        from .film_verdict import material_label, wrong_model_verdict

        return wrong_model_verdict(self.mse, material_label(self.model.stack.substrate))

    def notes(self) -> list[str]:
        """Plain-language notes: misfit, trade-offs, bounds (as a one-sample fit's)."""
        return FilmFit.notes(self)  # type: ignore[arg-type]  # uses result, misfit_scale

    def sample_stats(self) -> dict[str, dict[str, float]]:
        """Per sample: its rows and its own ``chi2/N`` (how well the shared model fits it).

        ``chi2/N = sum(((y - f) / sigma)^2) / N`` over the sample's N rows; near 1 for
        every sample when the shared parameters suit them all.
        """
        z = np.asarray(self.result.residual, float) / self.data["sigma"].to_numpy(float)
        out = {}
        for s in self.samples:
            m = (self.data["fit_sample"] == s).to_numpy()
            n = int(m.sum())
            out[s] = {"n": n, "chi2_per_point": float(np.sum(z[m] ** 2) / n)}
        return out

    def summary(self) -> dict[str, Any]:
        """A JSON-safe dict: every parameter with stderr, 95 % intervals, flags, the fit."""
        res = self.result
        scale = self.misfit_scale
        tq = float(special.stdtrit(max(res.nfree, 1), 0.975))

        def param(k: str) -> dict[str, Any]:
            q = res.params[k]
            d: dict[str, Any] = {"value": q.value, "vary": True, "units": q.units}
            d["stderr"] = q.stderr
            d["ci95"] = list(q.ci95) if q.ci95 is not None else None
            if scale is not None and q.stderr is not None:
                se = q.stderr * scale
                d["stderr_scaled"] = se
                d["ci95_scaled"] = [max(q.value - tq * se, q.min), min(q.value + tq * se, q.max)]
            d["bounds"] = [q.min, q.max]
            d["flags"] = res.flags.get(k, [])
            return d

        shared = [k for k in res.var_names if k in self.model.free]
        return jsonable(
            {
                "kind": "labbrdf film fit of several samples",
                "samples": {
                    s: {
                        "sources": self.sources[s],
                        "parameters": {
                            k: param(per_sample_name(k, s))
                            for k in self.per_sample
                            if per_sample_name(k, s) in res.var_names
                        },
                        "stack": self.stacks[s].to_dict(),
                        **self.sample_stats()[s],
                    }
                    for s in self.samples
                },
                "per_sample": list(self.per_sample),
                "shared": {k: param(k) for k in shared},
                "ndata": res.ndata,
                "nvarys": res.nvarys,
                "nfree": res.nfree,
                "chisqr": res.chisqr,
                "redchi": res.redchi,
                "mse": self.mse,
                "success": res.success,
                "message": res.message,
                "method": res.method,
                "search": [str(st["algorithm"]) for st in res.stages],
                "seed": res.seed,
                "ci_method": res.ci_method,
                "correlations": {
                    k: res.params[k].correl for k in res.var_names if res.params[k].correl
                },
                "notes": self.notes(),
                "warnings": list(res.warnings),
                "verdict": self.verdict,
            }
        )

    def fit_report(self) -> str:
        """Text report: shared parameters, each sample's own, the fit, notes."""
        from .film_multi_display import multi_fit_report

        return multi_fit_report(self.summary())

    def __str__(self) -> str:
        return self.fit_report()

    def _repr_html_(self) -> str:
        import html

        return f"<pre>{html.escape(self.fit_report())}</pre>"

    def save_json(self, path: str | os.PathLike[str]) -> Path:
        """Write :meth:`summary` as JSON, atomically (a new file or a complete replacement)."""
        from ..outputs import atomic_output

        p = Path(path)
        text = json.dumps(self.summary(), indent=2, allow_nan=False) + "\n"
        with atomic_output(p) as tmp:
            Path(tmp).write_text(text)
        return p


# --------------------------------------------------------------------------------------
# the fit
# --------------------------------------------------------------------------------------


def _as_model(stack_or_model: Any) -> FilmModel:
    if isinstance(stack_or_model, Stack):
        return FilmModel.default(stack_or_model)
    if isinstance(stack_or_model, FilmModel):
        return stack_or_model
    if isinstance(stack_or_model, (str, os.PathLike)):
        return load_model(stack_or_model, tabulated_from_file)
    raise FilmError(
        f"expected a Stack, a FilmModel or a model file, got {type(stack_or_model).__name__}"
    )


def _per_sample_names(fm: FilmModel, per_sample: Sequence[str]) -> tuple[str, ...]:
    """The per-sample names, each a free parameter (``thickness`` may stand for ``_nm``)."""
    out = []
    for k in per_sample:
        name = k if k in fm.free or f"{k}_nm" not in fm.free else f"{k}_nm"
        if name not in fm.free:
            raise FilmError(
                f"{fm.source}: per-sample parameter {k!r} is not a free parameter of the "
                f"model; free parameters: {sorted(fm.free)}"
            )
        out.append(name)
    return tuple(dict.fromkeys(out))


def _read_sample(files: Any) -> list[Any]:
    """The Measurements of one sample's file(s)."""
    from ..adapters import read

    return [read(f) for f in ([files] if isinstance(files, (str, os.PathLike)) else files)]


def _sample_rows(
    fm: FilmModel,
    samples: Mapping[str, Any],
    wl_range: tuple[float, float] | None,
    default_sigma: Mapping[str, float] | None,
) -> tuple[pd.DataFrame, dict[str, tuple[slice, _FilmFitModel]]]:
    """Every sample's rows, one after another, and each sample's slice and row model."""
    frames, parts, start = [], {}, 0
    for s, data in samples.items():
        try:
            rows, codes = _film_rows(data, wl_range, default_sigma)
        except FilmError as exc:
            raise FilmError(f"sample {s!r}: {exc}") from None
        rows["fit_sample"] = s
        sl = slice(start, start + len(rows))
        parts[s] = (sl, _FilmFitModel(fm, codes, rows["value"].to_numpy(float)))
        frames.append(rows)
        start = sl.stop
    return pd.concat(frames, ignore_index=True), parts


def fit_film_samples(
    stack_or_model: Stack | FilmModel | str | os.PathLike[str],
    samples: Mapping[str, Any] | None = None,
    *,
    per_sample: Sequence[str] | None = None,
    wavelength_range_nm: tuple[float, float] | None = None,
    default_sigma: Mapping[str, float] | None = None,
    method: str = METHOD,
    seed: int = 0,
    ci: str = "wald",
    maxeval: int | Sequence[int | None] | None = None,
) -> MultiFilmFit:
    """Fit one film model to several samples, with shared and per-sample parameters.

    Parameters
    ----------
    stack_or_model : Stack, FilmModel or path
        As :func:`labbrdf.fitting.film.fit_film`. A model file with a ``[samples]`` table
        (:mod:`labbrdf.films.modelsamples`) gives the samples' files and ``per_sample``.
    samples : mapping, optional
        Sample name -> its data (a Measurement, a DataFrame, a list of them, or a list of
        file paths, read with :func:`labbrdf.adapters.read`). At least two samples; a
        sample's several files are that one sample (no sample-name check). Default: the
        model file's ``[samples]``.
    per_sample : sequence of str, optional
        Free ``"<layer>.<parameter>"`` names fitted per sample (``"film.thickness"``
        stands for ``"film.thickness_nm"``); the others are shared. Default: the model
        file's ``per_sample``, else none.
    wavelength_range_nm, default_sigma, method, seed, ci, maxeval
        As :func:`labbrdf.fitting.film.fit_film`.

    Returns
    -------
    MultiFilmFit
        Per-sample parameters are named ``"<layer>.<parameter>[<sample>]"``.

    Raises
    ------
    FilmError
        Fewer than two samples, a per-sample name that is not a free parameter, and the
        errors of :func:`~labbrdf.fitting.film.fit_film` (each naming its sample).
    """
    fm = _as_model(stack_or_model)
    spec = load_samples(stack_or_model) if isinstance(stack_or_model, (str, os.PathLike)) else None
    if samples is None:
        if spec is None:
            raise FilmError(f"{fm.source}: no samples given and no [samples] table in the model")
        samples = {s: _read_sample(files) for s, files in spec.files.items()}
    if per_sample is None:
        per_sample = spec.per_sample if spec is not None else ()
    samples = {str(s): _read_sample(d) if _are_paths(d) else d for s, d in samples.items()}
    if len(samples) < 2:
        raise FilmError(
            f"{len(samples)} sample(s): a fit of several samples needs at least two "
            "(one sample: labbrdf.fit_film)"
        )
    names = _per_sample_names(fm, per_sample)
    rows, parts = _sample_rows(fm, samples, wavelength_range_nm or fm.wavelength_range_nm,
                               default_sigma)  # fmt: skip
    wl = rows["wavelength_nm"].to_numpy(float)
    _check_coverage(fm, wl)
    model = _MultiFilmModel(fm, names, parts)
    theta = rows["theta_i_deg"].to_numpy(float)
    fd = FitData(theta, theta, rows["value"].to_numpy(float), rows["sigma"].to_numpy(float),
                 180.0, wl, "film", "mixed")  # fmt: skip
    res = fit(model, fd, method=method, seed=seed, ci=ci, maxeval=maxeval, guess=False,
              weighting="sigma", mask_zeros=False)  # fmt: skip
    best = {k: q.value for k, q in res.params.items()}
    stacks = {s: fm.stack.with_values(model.sample_values(best, s)) for s in samples}
    sources = {
        s: sorted(set(g["source"].astype(str))) if "source" in g else []
        for s, g in rows.groupby("fit_sample", sort=False)
    }
    return MultiFilmFit(res, fm, names, stacks, rows, {s: sources.get(s, []) for s in samples})


def _are_paths(d: Any) -> bool:
    items = d if isinstance(d, (list, tuple)) else [d]
    return bool(items) and all(isinstance(x, (str, os.PathLike)) for x in items)
