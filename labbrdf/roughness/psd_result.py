"""``labbrdf.psd(...)``: the PSDs of a sample's height maps, their composite and a model fit.

The workflow behind ``labbrdf psd`` and the report's PSD section: read each map
(:func:`labbrdf.adapters.topography.read_height_map`), compute its PSD
(:mod:`labbrdf.roughness.psd`), combine them (:func:`~labbrdf.roughness.psd.composite`)
and optionally fit a model (:func:`~labbrdf.roughness.psd_fit.fit_psd`). The result shows
itself: ``str``, ``_repr_html_``, ``plot()``, ``to_frame()`` / ``to_csv()``, ``to_dict()``.
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from labbrdf.jsonsafe import jsonable

from .psd import Overlap, Spectrum, composite, map_psd, profile_psd
from .psd_fit import PSDFit, fit_psd

__all__ = ["KINDS", "PSDResult", "psd"]

#: what ``kind`` may be: the 2-D (areal, azimuthal average) or the 1-D (profile) PSD
KINDS = ("auto", "2d", "1d")


@dataclass(frozen=True)
class PSDResult:
    """The PSDs of one sample's height maps, their composite, and a fitted model.

    Attributes
    ----------
    spectra : tuple of Spectrum
        One per map, in the order given.
    composite : Spectrum
        Over the union of their bands (the single spectrum when there is one map).
    overlaps : tuple of Overlap
        Agreement of each pair of spectra over their common band.
    fit : PSDFit or None
        The model fitted to the composite.
    files : tuple of str
        The maps' sources.
    warnings : tuple of str
        Doubts from the reading (geometry) and the composite (overlaps that disagree).
    """

    spectra: tuple[Spectrum, ...]
    composite: Spectrum
    overlaps: tuple[Overlap, ...] = ()
    fit: PSDFit | None = None
    files: tuple[str, ...] = ()
    warnings: tuple[str, ...] = ()

    @property
    def kind(self) -> str:
        """``"2d"`` (PSD [m^4]) or ``"1d"`` (profile PSD [m^3])."""
        return self.composite.kind

    def to_frame(self) -> Any:
        """One row per bin of every spectrum and of the composite (pandas DataFrame).

        Columns: ``source`` (file name or ``composite``), ``kind``, ``f_per_m`` [1/m],
        ``psd`` and ``u`` (in ``unit``), ``n`` (independent values), ``unit``, and
        ``model`` (the fitted model at ``f``; empty without a fit).
        """
        import pandas as pd

        frames = []
        for s in (*self.spectra, self.composite):
            model = self.fit.curve(s.f) if self.fit is not None else np.full(s.f.size, np.nan)
            frames.append(
                pd.DataFrame(
                    {
                        "source": s.label,
                        "kind": s.kind,
                        "f_per_m": s.f,
                        "psd": s.psd,
                        "u": s.u,
                        "n": s.n,
                        "unit": s.unit,
                        "model": model,
                    }
                )
            )
        return pd.concat(frames, ignore_index=True)

    def to_csv(self, path: str | os.PathLike[str]) -> None:
        """Write :meth:`to_frame` as CSV (atomically; an existing file is kept on error)."""
        from labbrdf.outputs import atomic_output, csv_safe_frame

        with atomic_output(path) as tmp:
            csv_safe_frame(self.to_frame()).to_csv(tmp, index=False, lineterminator="\n")

    def map_rows(self) -> list[dict[str, Any]]:
        """Per map: file, kind, points, pixel, band and the sigma / slope over the band."""
        rows = []
        for s in self.spectra:
            rows.append(
                {
                    "source": s.label,
                    "kind": s.kind,
                    "direction": s.direction,
                    "points": list(s.shape),
                    "pixel_m": list(s.pixel_size),
                    "band_per_m": list(s.band),
                    "sigma_band_m": s.band_sigma(),
                    "slope_rms_band": s.band_slope(),
                    "detrend": s.detrend,
                    "window": s.window,
                    "bins": int(s.f.size),
                }
            )
        return rows

    def to_dict(self) -> dict[str, Any]:
        """JSON-safe summary (no per-bin arrays: :meth:`to_frame` has them)."""
        c = self.composite
        return jsonable(
            {
                "kind": self.kind,
                "unit": c.unit,
                "convention": (
                    "f in cycles per metre; 2-D PSD integrates over the frequency plane to "
                    "sigma^2; 1-D PSD two-sided"
                ),
                "maps": self.map_rows(),
                "composite": {
                    "band_per_m": list(c.band),
                    "bins": int(c.f.size),
                    "sigma_band_m": c.band_sigma(),
                },
                "overlaps": [
                    {
                        "first": o.first,
                        "second": o.second,
                        "band_per_m": list(o.band),
                        "bins": o.n_bins,
                        "chi2_dof": o.chi2_dof,
                        "median_ratio": o.median_ratio,
                        "agree": o.agree,
                    }
                    for o in self.overlaps
                ],
                "fit": self.fit.to_dict() if self.fit is not None else None,
                "warnings": list(self.warnings),
            }
        )

    def __str__(self) -> str:
        lines = [f"{self.kind.upper()} PSD of {len(self.spectra)} map(s) [{self.composite.unit}]"]
        for r in self.map_rows():
            lo, hi = r["band_per_m"]
            lines.append(
                f"  {r['source']}: band {lo:.4g}-{hi:.4g} 1/m, sigma {r['sigma_band_m'] * 1e9:.4g}"
                f" nm, RMS slope {r['slope_rms_band']:.3g} over it ({r['detrend']}; window "
                f"{r['window']})"
            )
        c = self.composite
        if len(self.spectra) > 1:
            lines.append(f"  composite: band {c.band[0]:.4g}-{c.band[1]:.4g} 1/m, {c.f.size} bins")
        lines += [f"  {o.sentence()}" for o in self.overlaps]
        if self.fit is not None:
            lines += ["", str(self.fit)]
        lines += [f"warning: {w}" for w in self.warnings]
        return "\n".join(lines)

    def _repr_html_(self) -> str:
        from labbrdf.richrepr import card

        facts: list[tuple[str, Any]] = [("kind", f"{self.kind} PSD [{self.composite.unit}]")]
        for o in self.overlaps:
            facts.append(("overlap", o.sentence()))
        if self.fit is not None:
            lo, hi = self.fit.band
            facts.append(
                (
                    "fit",
                    f"{self.fit.model} over {lo:.4g}-{hi:.4g} 1/m, "
                    f"chi^2/dof {self.fit.redchi:.3g}",
                )
            )
            facts += [(n, f"{v} {u} (95 % {i})") for n, v, i, u in self.fit.rows()]
        facts += [("warning", w) for w in self.warnings]
        header = ("map", "band [1/m]", "sigma [nm]", "RMS slope", "window")
        rows = [
            (
                r["source"],
                f"{r['band_per_m'][0]:.4g} - {r['band_per_m'][1]:.4g}",
                f"{r['sigma_band_m'] * 1e9:.4g}",
                f"{r['slope_rms_band']:.3g}",
                r["window"],
            )
            for r in self.map_rows()
        ]
        return card("Surface PSD", facts, (header, rows))

    def plot(self, ax: Any = None) -> Any:
        """Log-log PSD of each map (with 1-sigma bars), the composite and the fitted model.

        Parameters
        ----------
        ax : matplotlib Axes, optional
            Where to draw; default a new figure.

        Returns
        -------
        matplotlib Figure
        """
        if ax is None:
            import matplotlib.pyplot as plt

            fig, ax = plt.subplots(figsize=(6.4, 4.6), layout="constrained")
        else:
            fig = ax.figure
        draw_psd(ax, self)
        return fig


def draw_psd(ax: Any, result: PSDResult) -> None:
    """Draw ``result`` on ``ax`` (shared by :meth:`PSDResult.plot` and the report)."""
    from labbrdf._plotting import COLOURS, MARKERS, text

    for i, s in enumerate(result.spectra):
        ax.errorbar(
            s.f,
            s.psd,
            yerr=np.minimum(s.u, 0.95 * s.psd),
            fmt=MARKERS[i % len(MARKERS)],
            ms=3,
            lw=0.8,
            color=COLOURS[i % len(COLOURS)],
            label=text(f"{Path(s.label).name or 'map'} ({s.band[0]:.3g}-{s.band[1]:.3g} 1/m)"),
        )
    c = result.composite
    if len(result.spectra) > 1:
        f, p = _broken_at_gaps(c.f, c.psd)
        ax.plot(f, p, "-", color="0.3", lw=1.5, label="composite")
    if result.fit is not None:
        f = np.geomspace(*result.fit.band, 200)
        ax.plot(
            f, result.fit.curve(f), "--", color="k", lw=1.2, label=text(_fit_label(result.fit))
        )
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("spatial frequency f [1/m]")
    label = (
        "2-D PSD (azimuthal average) [m$^4$]" if c.kind == "2d" else "1-D PSD (two-sided) [m$^3$]"
    )
    ax.set_ylabel(label)
    ax.grid(True, which="major", alpha=0.3)
    ax.legend(fontsize="small")


def _broken_at_gaps(f: Any, p: Any) -> tuple[Any, Any]:
    """``f``, ``p`` with a NaN between bins further apart than 1.5 grid steps (no line)."""
    if f.size < 3:
        return f, p
    r = np.diff(np.log(f))
    step = float(np.median(r))
    cut = np.flatnonzero(r > 1.5 * step) + 1
    return np.insert(f.astype(float), cut, np.nan), np.insert(p.astype(float), cut, np.nan)


def _fit_label(fit: PSDFit) -> str:
    vals = ", ".join(
        f"{k}={v:.3g}" + (f" {u}" if u != "1" else "")
        for (k, v), u in zip(fit.values.items(), fit.units.values(), strict=True)
    )
    return f"{fit.model} fit: {vals}"


# ------------------------------------------------------------------------ the workflow
def _label(src: Any) -> str:
    return (
        os.fspath(src) if isinstance(src, (str, os.PathLike)) else str(getattr(src, "path", "map"))
    )


def _read(src: Any, channel: int | str | None, read_kw: dict[str, Any]) -> Any:
    from labbrdf.adapters.topography import read_height_map

    if isinstance(src, (str, os.PathLike)):
        return read_height_map(src, channel, **read_kw)
    if hasattr(src, "heights") and hasattr(src, "pixel_size"):
        return src
    raise TypeError(f"expected a file name or a HeightMap, got {type(src).__name__}")


def _flatten(sources: Iterable[Any]) -> list[Any]:
    out: list[Any] = []
    for s in sources:
        if isinstance(s, (list, tuple)):
            out.extend(s)
        else:
            out.append(s)
    return out


def _resolve_kind(kind: str, maps: Sequence[Any]) -> str:
    from labbrdf.adapters import AdapterError

    if kind not in KINDS:
        raise ValueError(f"kind must be one of {KINDS}, got {kind!r}")
    profiles = [hm for hm in maps if hm.heights.ndim == 1]
    if kind == "auto":
        return "1d" if profiles else "2d"
    if kind == "2d" and profiles:
        raise AdapterError(
            profiles[0].path,
            "is a line profile: its PSD is 1-D [m^3] and cannot join 2-D PSDs [m^4]; ask for "
            "the 1-D PSD (kind '1d', on the command line --kind 1d: the maps' rows averaged)",
        )
    return kind


def _spectrum(hm: Any, kind: str, opts: dict[str, Any]) -> Spectrum:
    from labbrdf.adapters import AdapterError

    label = str(hm.path)
    try:
        if kind == "2d":
            return map_psd(hm.heights, hm.pixel_size, label=label, **opts)
        return profile_psd(hm.heights, hm.pixel_size, label=label, **opts)
    except ValueError as exc:
        raise AdapterError(label, str(exc)) from None


def psd(
    *sources: Any,
    kind: str = "auto",
    fit: str | None = None,
    f_min: float | None = None,
    f_max: float | None = None,
    window: str = "hann",
    degree: int = 1,
    per_decade: int = 10,
    channel: int | str | None = None,
    seed: int = 0,
    **read_kw: Any,
) -> PSDResult:
    """PSDs of one sample's height maps (files or HeightMaps), their composite, a model fit.

    Parameters
    ----------
    *sources : path-like or HeightMap (or lists of them)
        The maps of one sample, e.g. an AFM scan and a profilometer map.
    kind : {"auto", "2d", "1d"}
        ``"2d"``: azimuthally averaged 2-D PSDs [m^4] (areal maps only); ``"1d"``: profile
        PSDs [m^3] (a map's rows averaged); ``"auto"``: 2-D unless a source is a profile.
    fit : str, optional
        A model of :data:`labbrdf.roughness.psd_models.PSD_MODELS` to fit to the
        composite (``"k-correlation"``, ``"gaussian"``, ``"exponential"``, ``"fractal"``).
    f_min, f_max : float, optional
        The fitted band [1/m]; default the composite's.
    window, degree, per_decade
        As :func:`labbrdf.roughness.psd.map_psd`.
    channel, read_kw
        As :func:`labbrdf.adapters.topography.read_height_map` (``unit``,
        ``pixel_size``, ``physical_sizes``).
    seed : int
        The fit's nlopt seed.

    Returns
    -------
    PSDResult

    Raises
    ------
    AdapterError
        A file cannot be read, is too small for a PSD, has gaps, or is a profile where a
        2-D PSD is asked for (the file is named).
    ValueError
        No source, a bad ``kind``, too few bins to fit.
    """
    items = _flatten(sources)
    if not items:
        raise ValueError("no height map given")
    maps = [_read(s, channel, read_kw) for s in items]
    k = _resolve_kind(kind, maps)
    opts = {"window": window, "degree": degree, "per_decade": per_decade}
    spectra = [_spectrum(hm, k, opts) for hm in maps]
    warnings = [f"{hm.path}: {w}" for hm in maps for w in getattr(hm, "warnings", ())]
    overlaps: list[Overlap] = []
    if len(spectra) == 1:
        comp = spectra[0]
    else:
        comp, overlaps = composite(spectra, per_decade=per_decade)
        warnings += [o.sentence() for o in overlaps if not o.agree]
        warnings += [n for n in comp.notes if n.startswith("no map covers")]
    fitted = fit_psd(comp, fit, f_min=f_min, f_max=f_max, seed=seed) if fit else None
    return PSDResult(
        tuple(spectra),
        comp,
        tuple(overlaps),
        fitted,
        tuple(_label(s) for s in items),
        tuple(warnings),
    )
