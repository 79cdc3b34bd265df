"""Wafer maps: one film fit per measured point, run through the one executor.

A map is a list of points, each a file and its stage position (x, y) [mm], usually a CSV
listing ``file,x,y`` (:func:`read_map_listing`). :func:`fit_film_map` fits the same
:class:`~labbrdf.films.FilmModel` to every point's file with
:func:`~labbrdf.fitting.film.fit_film` through a :class:`labbrdf.parallel.Executor`
(serial, processes or dask): each point's fit is seeded and alone, and the executor
returns the results in the points' order, so the map is the same whatever the executor
and the worker count. :class:`FilmMap` holds the table (one row per point: each free
parameter with its stderr and 95 % interval, n at 633 nm, chi2/nu, MSE) and draws the
thickness and index maps.
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from ..films import NK_REPORT_NM, FilmError, FilmModel, Stack, load_model
from ..nk.reading import tabulated_from_file
from .core import METHOD

__all__ = ["FilmMap", "MapPoint", "fit_film_map", "read_map_listing"]

#: the most points a map may have (a 300 mm wafer at 1 mm pitch has ~70,000)
MAX_MAP_POINTS = 100_000


@dataclass(frozen=True)
class MapPoint:
    """One point of a map: its file and its stage position [mm]."""

    file: str
    x: float
    y: float


def read_map_listing(path: str | os.PathLike[str]) -> list[MapPoint]:
    """The points of a CSV listing with the columns ``file, x, y`` (x, y [mm]).

    A ``file`` is relative to the listing's folder.

    Raises
    ------
    FilmError
        Naming the listing and the line: a missing column, a position that is not a
        finite number, an empty listing, more than :data:`MAX_MAP_POINTS` points, a file
        listed twice.
    """
    p = Path(path)
    try:
        df = pd.read_csv(p, dtype=str, keep_default_na=False, nrows=MAX_MAP_POINTS + 1)
    except (OSError, UnicodeDecodeError, pd.errors.ParserError, pd.errors.EmptyDataError) as e:
        raise FilmError(f"{p}: not a map listing (expected CSV columns file,x,y): {e}") from None
    df.columns = [str(c).strip().lower() for c in df.columns]
    missing = [c for c in ("file", "x", "y") if c not in df.columns]
    if missing:
        raise FilmError(f"{p}, line 1: missing column(s) {missing}; expected file,x,y [mm]")
    if df.empty:
        raise FilmError(f"{p}: no points (expected rows file,x,y after the header)")
    if len(df) > MAX_MAP_POINTS:
        raise FilmError(f"{p}: more than {MAX_MAP_POINTS:,} points (MAX_MAP_POINTS)")
    points, seen = [], set()
    for i, row in enumerate(df.itertuples(index=False), 2):
        xy = []
        for c in ("x", "y"):
            try:
                v = float(getattr(row, c))
            except ValueError:
                v = math.nan
            if not math.isfinite(v):
                raise FilmError(
                    f"{p}, line {i}: {c} = {getattr(row, c)!r}; expected a finite number [mm]"
                )
            xy.append(v)
        f = Path(str(row.file).strip())
        f = f if f.is_absolute() else p.parent / f
        if str(f) in seen:
            raise FilmError(f"{p}, line {i}: {f} is listed twice")
        seen.add(str(f))
        points.append(MapPoint(str(f), xy[0], xy[1]))
    return points


def _fit_point(task: tuple[FilmModel, MapPoint, Mapping[str, Any]]) -> dict[str, Any]:
    """One point's fit as a table row (a picklable dict; runs on a worker)."""
    from ..adapters import read
    from .film import fit_film

    fm, pt, kw = task
    try:
        f = fit_film(fm, read(pt.file), one_sample=True, **kw)
    except ValueError as exc:  # every labbrdf input error: name the point's file
        msg = str(exc)
        raise FilmError(msg if pt.file in msg else f"{pt.file}: {msg}") from None
    res = f.result
    row: dict[str, Any] = {"file": pt.file, "x_mm": pt.x, "y_mm": pt.y}
    for k in res.var_names:
        q = res.params[k]
        lo, hi = q.ci95 if q.ci95 is not None else (math.nan, math.nan)
        row |= {k: q.value, f"{k}_stderr": q.stderr, f"{k}_ci95_lo": lo, f"{k}_ci95_hi": hi}
    for lay in f.stack.layers:
        try:
            row[f"{lay.name}.n_{NK_REPORT_NM:g}nm"] = float(lay.material.nk(NK_REPORT_NM).real)
        except ValueError:  # a table that does not cover 633 nm
            row[f"{lay.name}.n_{NK_REPORT_NM:g}nm"] = math.nan
    row |= {"redchi": res.redchi, "mse": f.mse, "success": bool(res.success)}
    return row


@dataclass
class FilmMap:
    """The fits of a wafer map: one row per point.

    Attributes
    ----------
    table : pandas.DataFrame
        ``file, x_mm, y_mm``, each free parameter with ``_stderr``, ``_ci95_lo``,
        ``_ci95_hi``, each layer's ``<layer>.n_633nm``, ``redchi``, ``mse``, ``success``.
    model : FilmModel
        The model every point was fitted with.
    """

    table: pd.DataFrame
    model: FilmModel

    def _columns(self) -> tuple[str | None, str | None]:
        """The first layer's thickness and index columns (None where absent)."""
        if not self.model.stack.layers:
            return None, None
        name = self.model.stack.layers[0].name
        th, n = f"{name}.thickness_nm", f"{name}.n_{NK_REPORT_NM:g}nm"
        cols = self.table.columns
        return (th if th in cols else None), (n if n in cols else None)

    def fit_report(self) -> str:
        """Text report: the thickness and index statistics and the table of points."""
        th, n = self._columns()
        t = self.table
        lines = [f"Film map: {len(t)} points, model {self.model.source}"]
        for col in (c for c in (th, n) if c):
            v = t[col].to_numpy(float)
            lines.append(
                f"  {col}: mean {np.mean(v):.6g}, std {np.std(v, ddof=1) if v.size > 1 else 0:.3g}"
                f", min {np.min(v):.6g}, max {np.max(v):.6g}"
            )
        if not t["success"].all():
            lines.append(f"  {int((~t['success']).sum())} point(s) where the optimiser failed")
        cols = ["file", "x_mm", "y_mm", *(c for c in (th, n) if c), "mse"]
        show = t[cols].assign(file=[Path(f).name for f in t["file"]])
        lines.append(show.to_string(index=False, float_format=lambda v: f"{v:.6g}"))
        return "\n".join(lines)

    def __str__(self) -> str:
        return self.fit_report()

    def _repr_html_(self) -> str:
        return self.table.to_html(index=False, float_format=lambda v: f"{v:.6g}")

    def plot(self, ax: Any = None) -> Any:
        """The thickness map and the index (n at 633 nm) map of the first layer.

        Parameters
        ----------
        ax : sequence of two matplotlib Axes, optional
            Default: a new figure with the two maps side by side.

        Returns
        -------
        matplotlib Figure
        """
        import matplotlib.pyplot as plt
        from matplotlib.ticker import ScalarFormatter

        if ax is None:
            fig, axes = plt.subplots(1, 2, figsize=(10, 4.2), layout="constrained")
        else:
            axes = list(ax)
            fig = axes[0].figure
        t = self.table
        for a, col in zip(axes, self._columns(), strict=True):
            if col is None:
                a.set_axis_off()
                continue
            sc = a.scatter(t["x_mm"], t["y_mm"], c=t[col], s=120, cmap="viridis")
            label = col.replace("thickness_nm", "thickness [nm]").replace(
                f"n_{NK_REPORT_NM:g}nm", f"n at {NK_REPORT_NM:g} nm"
            )
            cb = fig.colorbar(sc, ax=a, label=label)
            cb.formatter = ScalarFormatter(useOffset=False)  # the values, not an offset
            cb.update_ticks()
            a.set(xlabel="x [mm]", ylabel="y [mm]", aspect="equal", title=label)
        return fig

    def save_png(self, path: str | os.PathLike[str]) -> Path:
        """Write :meth:`plot` as a PNG, atomically."""
        import matplotlib.pyplot as plt

        from ..outputs import atomic_output

        p = Path(path)
        fig = self.plot()
        try:
            with atomic_output(p) as tmp:
                fig.savefig(tmp, format="png", dpi=100)
        finally:
            plt.close(fig)
        return p

    def save_csv(self, path: str | os.PathLike[str]) -> Path:
        """Write :attr:`table` as CSV, atomically (a new file or a complete replacement)."""
        from ..outputs import atomic_output, csv_safe_frame

        p = Path(path)
        with atomic_output(p) as tmp:
            csv_safe_frame(self.table).to_csv(tmp, index=False)
        return p


def fit_film_map(
    stack_or_model: Stack | FilmModel | str | os.PathLike[str],
    points: Sequence[MapPoint | tuple[str, float, float]] | str | os.PathLike[str],
    *,
    executor: Any = None,
    wavelength_range_nm: tuple[float, float] | None = None,
    default_sigma: Mapping[str, float] | None = None,
    method: str = METHOD,
    seed: int = 0,
    ci: str = "wald",
    maxeval: int | Sequence[int | None] | None = None,
) -> FilmMap:
    """Fit one film model to every point of a wafer map.

    Parameters
    ----------
    stack_or_model : Stack, FilmModel or path
        As :func:`labbrdf.fitting.film.fit_film`.
    points : sequence or path
        :class:`MapPoint` or ``(file, x, y)`` items, or a CSV listing
        (:func:`read_map_listing`). Each file is one point's data (one sample: no
        sample-name check).
    executor : Executor or str, optional
        Where the fits run (:func:`labbrdf.parallel.as_executor`; default processes).
    wavelength_range_nm, default_sigma, method, seed, ci, maxeval
        As :func:`~labbrdf.fitting.film.fit_film`; every point is fitted with the same seed.

    Returns
    -------
    FilmMap
        The same table whatever the executor and worker count.

    Raises
    ------
    FilmError
        A bad listing (naming it and the line), no points, and any point's fit error
        (naming the point's file).
    """
    from ..parallel import as_executor

    if isinstance(stack_or_model, Stack):
        fm = FilmModel.default(stack_or_model)
    elif isinstance(stack_or_model, FilmModel):
        fm = stack_or_model
    else:
        fm = load_model(stack_or_model, tabulated_from_file)
    if isinstance(points, (str, os.PathLike)):
        pts = read_map_listing(points)
    else:
        pts = [
            p if isinstance(p, MapPoint) else MapPoint(str(p[0]), *map(float, p[1:]))
            for p in points
        ]
    if not pts:
        raise FilmError("a map needs at least one point")
    kw = {"wavelength_range_nm": wavelength_range_nm, "default_sigma": default_sigma,
          "method": method, "seed": seed, "ci": ci, "maxeval": maxeval}  # fmt: skip
    rows = as_executor(executor).map(_fit_point, [(fm, p, kw) for p in pts], desc="map points")
    return FilmMap(pd.DataFrame(rows), fm)
