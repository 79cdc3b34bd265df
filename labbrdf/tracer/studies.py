"""The four factor studies of Dong et al. 2022, section 4, and their qualitative claims.

Common set-up (paper sec. 4): natural light at 650 nm, a varnish of n = 1.5 on Al
(1.55 + 7.71i), optical thickness ``d_c = n d = lambda/4``, theta_i = 45 deg and
alpha = 0.2 for coating and substrate unless the study varies it:

* ``incidence``: theta_i = 30, 45, 60 deg (Figs. 7-8);
* ``roughness``: alpha = 0.2, 0.4, 0.6 (Figs. 9-10);
* ``substrate``: Cu 0.23 + 3.63i, Al 1.55 + 7.71i, NiFe 2.43 + 4.00i (Figs. 11-12);
* ``thickness``: d_c = lambda/8, lambda/4, lambda/2 (Figs. 13-14), incoherent, plus
  ``thickness_coherent``, the same with ``coherent=True`` (conformal Airy film per facet).

:func:`evaluate_claims` tests each qualitative statement of section 4 on the traced maps and
returns the numbers it used. Notes: the paper calls (theta_r = 90, phi_r = 180) the
"zenith"; it is the grazing forward direction. "Spot centre intensity" is read as the value
in the specular bin (theta_i, 180); "S0 spot extent" as the solid angle of the bins where S0
is at least half its specular value; "DOP spot extent" as the solid angle where the DOP is
at least half its peak; DOP is only read in bins with at least ``min_count`` exiting rays.
"""

from __future__ import annotations

import builtins
from collections.abc import Callable, Iterable
from typing import Any

import numpy as np

from .config import Coating, Substrate, TraceConfig
from .result import TraceResult

__all__ = ["MATERIALS", "evaluate_claims", "factor_studies", "study_configs"]

#: substrate indices at 650 nm used by the paper (sec. 4.3)
MATERIALS = {"Cu": (0.23, 3.63), "Al": (1.55, 7.71), "NiFe": (2.43, 4.00)}

WAVELENGTH = 650.0
N_VARNISH = 1.5


def _cfg(
    *,
    theta: float = 45.0,
    alpha: float = 0.2,
    material: str = "Al",
    optical_fraction: float = 0.25,
    coherent: bool = False,
    rays: int,
    seed: int,
    scattering: str,
    step: float,
) -> TraceConfig:
    n, k = MATERIALS[material]
    return TraceConfig(
        wavelength_nm=WAVELENGTH,
        theta_i_deg=theta,
        substrate=Substrate(n=n, k=k, alpha=alpha),
        coating=Coating(
            n=N_VARNISH, thickness_nm=optical_fraction * WAVELENGTH / N_VARNISH, alpha=alpha
        ),
        rays=rays,
        seed=seed,
        scattering=scattering,
        coherent=coherent,
        theta_step_deg=step,
        phi_step_deg=step,
    )


def study_configs(
    rays: int = 200_000, seed: int = 0, scattering: str = "multiple", step: float = 1.0
) -> list[tuple[str, str, TraceConfig]]:
    """The configurations of the factor studies: (study, label, config)."""
    kw: dict[str, Any] = {"rays": rays, "seed": seed, "scattering": scattering, "step": step}
    out: list[tuple[str, str, TraceConfig]] = []
    for t in (30.0, 45.0, 60.0):
        out.append(("incidence", f"theta_i={t:g}", _cfg(theta=t, **kw)))
    for a in (0.2, 0.4, 0.6):
        out.append(("roughness", f"alpha={a:g}", _cfg(alpha=a, **kw)))
    for mat in MATERIALS:
        out.append(("substrate", mat, _cfg(material=mat, **kw)))
    for frac, lab in ((0.125, "lambda/8"), (0.25, "lambda/4"), (0.5, "lambda/2")):
        out.append(("thickness", lab, _cfg(optical_fraction=frac, **kw)))
    for frac, lab in ((0.125, "lambda/8"), (0.25, "lambda/4"), (0.5, "lambda/2")):
        out.append(("thickness_coherent", lab, _cfg(optical_fraction=frac, coherent=True, **kw)))
    return out


def factor_studies(
    rays: int = 200_000,
    seed: int = 0,
    *,
    scattering: str = "multiple",
    step: float = 1.0,
    map: Callable[..., Iterable[Any]] = builtins.map,  # noqa: A002
) -> list[tuple[str, str, TraceResult]]:
    """Trace the paper's four factor studies (plus the coherent thickness study).

    Parameters
    ----------
    rays : int
        Rays per configuration (the paper used 2e5).
    seed : int
        Seed (the same for every configuration).
    scattering : {"multiple", "single"}
        Microsurface scattering model.
    step : float
        Grid step [deg] of both angles.
    map : callable
        Ordered map used by :func:`labbrdf.tracer.trace` for its work units.

    Returns
    -------
    list of (study, label, TraceResult)
    """
    from . import trace

    return [
        (study, label, trace(cfg, map=map))
        for study, label, cfg in study_configs(rays, seed, scattering, step)
    ]


# ----------------------------------------------------------------------------------------
# claims
# ----------------------------------------------------------------------------------------


def _plane(res: TraceResult) -> int:
    return int(np.argmin(np.abs(res.phi_r_deg - 180.0)))


def _specular(res: TraceResult) -> tuple[int, int]:
    i = int(np.argmin(np.abs(res.theta_r_deg - res.config.theta_i_deg)))
    return i, _plane(res)


def _symmetry_z(res: TraceResult, what: str, min_count: int) -> float:
    """Largest |map(theta, 180 + d) - map(theta, 180 - d)| in units of its MC error."""
    j0 = _plane(res)
    n_phi = res.phi_r_deg.size
    j = np.arange(n_phi)
    mirror = (2 * j0 - j) % n_phi
    pop = _populated(res, min_count)
    ok = pop & pop[:, mirror]
    if what == "S0":
        val = res.s0()
        err = res.mueller_stderr[..., 0, 0]
    elif res.estimator == "evaluated":
        val = res.dop()
        err = res.dop_stderr()
    else:
        val = res.dop()
        # DOP error ~ 1/sqrt(count) (binomial-like spread of the per-ray polarization)
        err = 1.0 / np.sqrt(np.maximum(res.counts, 1))
    diff = np.abs(val - val[:, mirror])
    sig = np.sqrt(err**2 + err[:, mirror] ** 2)
    with np.errstate(divide="ignore", invalid="ignore"):
        z = np.where(ok & (sig > 0), diff / sig, 0.0)
    return float(np.nanmax(z))


def _populated(res: TraceResult, min_count: int) -> np.ndarray:
    """Bins whose values can be judged.

    Counting: at least ``min_count`` counted rays. Evaluated (which counts no rays):
    S0 > 0 with a finite DOP error.
    """
    if res.estimator == "evaluated":
        return (res.s0() > 0) & np.isfinite(res.dop_stderr())
    return res.counts >= min_count


def _extent(res: TraceResult, val: np.ndarray, ok: np.ndarray, ref: float) -> float:
    """Solid angle [sr] of the bins (among ``ok``) where ``val >= ref / 2``."""
    v = np.where(ok, val, -np.inf)
    return float(res.grid.solid_angle_sr[v >= 0.5 * ref].sum())


def _stats(res: TraceResult, min_count: int) -> dict[str, float]:
    s0 = res.s0()
    dop = res.dop()
    ok = _populated(res, min_count)
    if not ok.any():
        raise ValueError(
            f"no bin has min_count={min_count} exiting rays ({res.config.rays} rays on a "
            f"{res.config.theta_step_deg:g}-degree grid): use more rays or a coarser step"
        )
    i0, j0 = _specular(res)
    plane = s0[:, j0]
    dmap = np.where(ok, dop, -np.inf)
    imax, jmax = np.unravel_index(int(np.argmax(dmap)), dmap.shape)
    return {
        "S0_peak": float(s0.max()),
        "S0_centre": float(s0[i0, j0]),
        "S0_extent_sr": _extent(res, s0, _populated(res, 1), float(s0[i0, j0])),
        "S0_plane_argmax_deg": float(res.theta_r_deg[int(np.argmax(plane))]),
        "DOP_peak": float(dmap[imax, jmax]),
        "DOP_peak_theta_deg": float(res.theta_r_deg[imax]),
        "DOP_peak_phi_deg": float(res.phi_r_deg[jmax]),
        "DOP_centre": float(dop[i0, j0]),
        "DOP_extent_sr": _extent(res, np.nan_to_num(dop, nan=-np.inf), ok, dmap[imax, jmax]),
        "S0_symmetry_z": _symmetry_z(res, "S0", min_count),
        "DOP_symmetry_z": _symmetry_z(res, "DOP", min_count),
        "theta_i_deg": float(res.config.theta_i_deg),
    }


def _increasing(x: list[float]) -> bool:
    return all(b > a for a, b in zip(x, x[1:], strict=False))


def _decreasing(x: list[float]) -> bool:
    return all(b < a for a, b in zip(x, x[1:], strict=False))


def evaluate_claims(
    studies: list[tuple[str, str, TraceResult]], *, min_count: int = 20, z_max: float = 5.0
) -> list[dict[str, Any]]:
    """Check each qualitative claim of Dong 2022 section 4 on traced maps.

    Parameters
    ----------
    studies : list of (study, label, TraceResult)
        As returned by :func:`factor_studies` (the order of labels within a study is the
        paper's order of increasing factor).
    min_count : int
        Bins with fewer exiting rays are ignored for peaks, extents and symmetry.
    z_max : float
        A symmetry claim holds if no mirrored bin pair differs by more than ``z_max``
        Monte Carlo standard errors.

    Returns
    -------
    list of dict
        ``{"study", "claim", "holds", "evidence"}``; evidence holds the per-label numbers.
    """
    by: dict[str, list[tuple[str, dict[str, float]]]] = {}
    for study, label, res in studies:
        by.setdefault(study, []).append((label, _stats(res, min_count)))
    out: list[dict[str, Any]] = []

    def add(study: str, claim: str, holds: bool, keys: tuple[str, ...]) -> None:
        ev = {lab: {k: st[k] for k in keys} for lab, st in by[study]}
        out.append({"study": study, "claim": claim, "holds": bool(holds), "evidence": ev})

    def col(study: str, key: str) -> list[float]:
        return [st[key] for _, st in by[study]]

    def spec_peak(study: str, tol: float) -> bool:
        return all(
            abs(st["S0_plane_argmax_deg"] - st["theta_i_deg"]) <= tol for _, st in by[study]
        )

    def sym(study: str, key: str) -> bool:
        return all(st[key] <= z_max for _, st in by[study])

    def dop_grazing(study: str) -> bool:
        return all(
            st["DOP_peak_theta_deg"] >= 80 and abs(st["DOP_peak_phi_deg"] - 180) <= 10
            for _, st in by[study]
        )

    for study in by:
        tol = 1.0 * max(1.0, float(studies[0][2].config.theta_step_deg))
        add(
            study,
            "S0 is symmetric about phi_r = 180 deg",
            sym(study, "S0_symmetry_z"),
            ("S0_symmetry_z",),
        )
        add(
            study,
            "DOP is symmetric about phi_r = 180 deg",
            sym(study, "DOP_symmetry_z"),
            ("DOP_symmetry_z",),
        )
        add(
            study,
            "S0 is largest at theta_r = theta_i in the plane phi_r = 180 deg",
            spec_peak(study, tol),
            ("S0_plane_argmax_deg", "theta_i_deg"),
        )
        add(
            study,
            "DOP is largest at (theta_r = 90, phi_r = 180) deg",
            dop_grazing(study),
            ("DOP_peak", "DOP_peak_theta_deg", "DOP_peak_phi_deg"),
        )

    if "incidence" in by:
        s = "incidence"
        add(
            s,
            "with larger theta_i the S0 spot shrinks",
            _decreasing(col(s, "S0_extent_sr")),
            ("S0_extent_sr",),
        )
        add(
            s,
            "with larger theta_i the S0 peak grows",
            _increasing(col(s, "S0_peak")),
            ("S0_peak",),
        )
        add(
            s,
            "with larger theta_i the DOP spot shrinks",
            _decreasing(col(s, "DOP_extent_sr")),
            ("DOP_extent_sr",),
        )
        add(
            s,
            "with larger theta_i the DOP peak grows",
            _increasing(col(s, "DOP_peak")),
            ("DOP_peak",),
        )
    if "roughness" in by:
        s = "roughness"
        add(
            s,
            "with larger alpha the S0 spot grows",
            _increasing(col(s, "S0_extent_sr")),
            ("S0_extent_sr",),
        )
        add(
            s,
            "with larger alpha the S0 centre intensity falls",
            _decreasing(col(s, "S0_centre")),
            ("S0_centre",),
        )
        add(
            s,
            "with larger alpha the DOP spot grows",
            _increasing(col(s, "DOP_extent_sr")),
            ("DOP_extent_sr",),
        )
        add(
            s,
            "with larger alpha the DOP peak grows",
            _increasing(col(s, "DOP_peak")),
            ("DOP_peak",),
        )
    if "substrate" in by:
        s = "substrate"
        add(
            s,
            "with larger n/k (Cu < Al < NiFe) the S0 centre intensity falls",
            _decreasing(col(s, "S0_centre")),
            ("S0_centre",),
        )
        add(
            s,
            "with larger n/k the DOP spot shrinks",
            _decreasing(col(s, "DOP_extent_sr")),
            ("DOP_extent_sr",),
        )
        add(
            s, "with larger n/k the DOP peak grows", _increasing(col(s, "DOP_peak")), ("DOP_peak",)
        )
    for s in ("thickness", "thickness_coherent"):
        if s not in by:
            continue
        c = col(s, "S0_centre")
        if len(c) == 3:
            add(
                s,
                "the S0 centre intensity is largest for d_c = lambda/4",
                c[1] > c[0] and c[1] > c[2],
                ("S0_centre",),
            )
        add(
            s,
            "with larger d_c the DOP spot shrinks",
            _decreasing(col(s, "DOP_extent_sr")),
            ("DOP_extent_sr",),
        )
        add(
            s, "with larger d_c the DOP peak grows", _increasing(col(s, "DOP_peak")), ("DOP_peak",)
        )
    return out
