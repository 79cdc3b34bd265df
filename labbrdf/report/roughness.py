"""A height map's roughness against the light: sigma of the band that scatters, g, exp(-g).

The numbers the report's sections share about a height map paired with optical files of
one sample (the section ``smoothness`` tabulates them, ``nk`` divides the measured
reflectance by the Davies loss, ``fits`` flags fits of a rough sample). Physics:
:mod:`labbrdf.roughness.smoothness`; the band: ``docs/smoothness.md``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..adapters.topography import HeightMap
from ..roughness import smoothness as sm
from ..roughness.topography import (
    RoughnessStats,
    level,
    on_measured_points,
    roughness_statistics,
    s_filter,
)
from ..samples import SampleGroup
from .context import Context

__all__ = [
    "MapRoughness",
    "SpecularLoss",
    "groups_with_maps",
    "judge",
    "map_roughness",
    "rayleigh_flags",
    "specular_loss_for",
]


@dataclass
class MapRoughness:
    """A height map's sigma and its band, computed once per report."""

    hm: HeightMap
    stats: RoughnessStats
    levelled: np.ndarray
    short_nm: float  # shortest period the map resolves: 2 pixels [nm]
    long_nm: float  # the map size [nm]
    cache: dict[float, float]

    @property
    def name(self) -> str:
        """The height map's file name."""
        return Path(self.hm.path).name

    @property
    def sigma_nm(self) -> float:
        """sigma of the whole map [nm]."""
        return self.stats.sigma * 1e9

    @property
    def u_rel(self) -> float:
        """Relative 1-sigma uncertainty of sigma [1] (NaN where unknown)."""
        u = self.stats.uncertainty.get("sigma", math.nan)
        return u / self.stats.sigma if math.isfinite(u) and self.stats.sigma > 0 else math.nan

    def sigma_for(self, shortest_nm: float) -> tuple[float, str]:
        """sigma [nm] of the roughness that scatters, and how the map's band covers it."""
        cov, _ = sm.band_coverage(shortest_nm, self.short_nm, self.long_nm)
        c = str(cov)
        if c == "none":
            return math.nan, c
        if c == "misses short periods":
            return self.sigma_nm, c
        key = round(shortest_nm, 3)
        if key not in self.cache:
            f = s_filter(self.levelled, self.hm.pixel_size, shortest_nm * 1e-9)
            v = f[np.isfinite(f)]
            self.cache[key] = float(np.sqrt(np.mean((v - v.mean()) ** 2))) * 1e9
        return self.cache[key], c


def map_roughness(ctx: Context) -> dict[str, MapRoughness]:
    """Every height map's statistics, kept on the context (the fits section asks too)."""
    store: dict[str, MapRoughness] = ctx.map_roughness
    for hm in ctx.height_maps:
        if hm.path in store:
            continue
        try:
            st = on_measured_points(roughness_statistics(hm.heights, hm.pixel_size), hm.points)
        except ValueError:
            continue  # the surface section reports it
        size = max(hm.physical_sizes) * 1e9
        short = 2.0 * min(hm.pixel_size) * 1e9
        if not short < size:
            continue
        store[hm.path] = MapRoughness(hm, st, level(hm.heights, 1), short, size, {})
    return store


def groups_with_maps(ctx: Context) -> list[tuple[SampleGroup, list[MapRoughness], list[str]]]:
    """(group, its height maps, its optical files' names) for groups holding both."""
    maps = map_roughness(ctx)
    out = []
    for g in ctx.samples:
        keys = {str(p) for p in g.paths}
        mine = [m for path, m in maps.items() if path in keys]
        optical = [Path(p).name for p in g.paths if str(p) not in maps]
        if mine and optical:
            out.append((g, mine, optical))
    return out


@dataclass(frozen=True)
class SpecularLoss:
    """The Davies specular loss a paired height map predicts for rows of reflectance.

    Attributes
    ----------
    map : str
        The height map's file name.
    sigma_nm, g, loss, u_loss : ndarray
        Per row: sigma of the roughness that scatters [nm], the Rayleigh parameter g [1],
        ``exp(-g)`` [1] and its 1-sigma from sigma's uncertainty [1]; NaN where the map's
        band holds no period that scatters.
    """

    map: str
    sigma_nm: np.ndarray
    g: np.ndarray
    loss: np.ndarray
    u_loss: np.ndarray


def specular_loss_for(
    ctx: Context, source: str, wavelength_nm: Sequence[float], theta_deg: Sequence[float]
) -> SpecularLoss | None:
    """``exp(-g)`` per (wavelength, angle) from the height map paired with file ``source``.

    The sigma is the same as in the section ``smoothness``'s table
    (:meth:`MapRoughness.sigma_for`: the roughness that scatters at that wavelength and
    angle), g and exp(-g) those of
    :mod:`labbrdf.roughness.smoothness`. None when no height map is of the same sample as
    ``source``
    (a file name, as the rows' ``source`` gives it); the first map of the group otherwise.
    """
    maps = [m for _, ms, optical in groups_with_maps(ctx) if source in optical for m in ms]
    if not maps:
        return None
    m = maps[0]
    wl = np.asarray(wavelength_nm, dtype=float)
    th = np.radians(np.asarray(theta_deg, dtype=float))
    d = np.asarray(sm.shortest_scattering_period(wl, th), dtype=float)
    sigma = _sigmas(m, d)
    g = np.asarray(sm.rayleigh_parameter(np.nan_to_num(sigma), wl, th), dtype=float)
    g[~np.isfinite(sigma)] = np.nan
    u = np.nan_to_num(sigma * m.u_rel)
    u_g = np.asarray(sm.rayleigh_parameter_uncertainty(np.nan_to_num(sigma), u, wl, th))
    loss = np.asarray(sm.specular_loss(np.nan_to_num(g)), dtype=float)
    loss[~np.isfinite(g)] = np.nan
    return SpecularLoss(m.name, sigma, g, loss, loss * u_g)


#: most S-filtered sigmas computed per map for one comparison; between them, interpolated
#: in the period (sigma varies smoothly with the band's short end)
MAX_PERIODS = 64


def _sigmas(m: MapRoughness, periods: np.ndarray) -> np.ndarray:
    """sigma [nm] of the roughness that scatters, per shortest scattering period [nm]."""
    u = np.unique(periods)
    if u.size > MAX_PERIODS:
        u = np.linspace(u[0], u[-1], MAX_PERIODS)
    at = np.array([m.sigma_for(float(v))[0] for v in u])
    if u.size == 1:
        return np.full(periods.shape, at[0])
    return np.asarray(np.interp(periods, u, at), dtype=float)


def judge(m: MapRoughness, wl_nm: float, theta_deg: float) -> dict[str, Any]:
    """One (wavelength, angle) of one map: band, sigma, g, both verdicts, exp(-g)."""
    th = math.radians(theta_deg)
    d = float(sm.shortest_scattering_period(wl_nm, th))
    sigma, cov = m.sigma_for(d)
    row: dict[str, Any] = {
        "map": m.name,
        "wavelength_nm": wl_nm,
        "theta_i": theta_deg,
        "shortest_nm": d,
        "coverage": cov,
        "thr_rayleigh": float(sm.smooth_threshold(wl_nm, th, "rayleigh")),
        "thr_fraunhofer": float(sm.smooth_threshold(wl_nm, th, "fraunhofer")),
    }
    if not math.isfinite(sigma):
        row.update(rayleigh="outside the map's band", fraunhofer="outside the map's band")
        return row
    u = sigma * m.u_rel
    g = float(sm.rayleigh_parameter(sigma, wl_nm, th))
    row.update(
        sigma_nm=sigma,
        u_sigma_nm=u if math.isfinite(u) else None,
        g=g,
        u_g=float(sm.rayleigh_parameter_uncertainty(sigma, u, wl_nm, th))
        if math.isfinite(u)
        else None,
        rayleigh=str(sm.verdict(sigma, u, wl_nm, th, "rayleigh")),
        fraunhofer=str(sm.verdict(sigma, u, wl_nm, th, "fraunhofer")),
        loss=float(sm.specular_loss(g)),
    )
    return row


def rayleigh_flags(
    ctx: Context, sources: Sequence[str], wavelength_nm: float, thetas_deg: Sequence[float]
) -> list[str]:
    """Where the Rayleigh criterion fails for a fit's sample: ``"Rayleigh: rough at 60 deg"``.

    ``sources`` are the fitted rows' file names; the sample is the group holding them
    (:attr:`Context.samples`), its sigma that of the group's height map(s). Empty when the
    group has no height map.
    """
    out: list[str] = []
    names = set(sources)
    for _group, maps, optical in groups_with_maps(ctx):
        if not names & set(optical):
            continue
        for m in maps:
            for t in sorted(set(round(float(x), 3) for x in thetas_deg if math.isfinite(x))):
                v = judge(m, wavelength_nm, t)["rayleigh"]
                if v in ("rough", "undecided"):
                    out.append(f"Rayleigh ({m.name}): {v} at {t:g} deg")
    return out
