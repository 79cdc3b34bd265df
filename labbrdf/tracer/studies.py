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


def _middle_max(x: list[float]) -> bool:
    return len(x) == 3 and x[1] > x[0] and x[1] > x[2]


#: the trend claims of each study (paper sec. 4), in the paper's order: (claim, the
#: per-label number it reads, the test on the numbers in order of increasing factor)
_TRENDS: dict[str, tuple[tuple[str, str, Callable[[list[float]], bool]], ...]] = {
    "incidence": (
        ("with larger theta_i the S0 spot shrinks", "S0_extent_sr", _decreasing),
        ("with larger theta_i the S0 peak grows", "S0_peak", _increasing),
        ("with larger theta_i the DOP spot shrinks", "DOP_extent_sr", _decreasing),
        ("with larger theta_i the DOP peak grows", "DOP_peak", _increasing),
    ),
    "roughness": (
        ("with larger alpha the S0 spot grows", "S0_extent_sr", _increasing),
        ("with larger alpha the S0 centre intensity falls", "S0_centre", _decreasing),
        ("with larger alpha the DOP spot grows", "DOP_extent_sr", _increasing),
        ("with larger alpha the DOP peak grows", "DOP_peak", _increasing),
    ),
    "substrate": (
        (
            "with larger n/k (Cu < Al < NiFe) the S0 centre intensity falls",
            "S0_centre",
            _decreasing,
        ),
        ("with larger n/k the DOP spot shrinks", "DOP_extent_sr", _decreasing),
        ("with larger n/k the DOP peak grows", "DOP_peak", _increasing),
    ),
    **{
        s: (
            ("the S0 centre intensity is largest for d_c = lambda/4", "S0_centre", _middle_max),
            ("with larger d_c the DOP spot shrinks", "DOP_extent_sr", _decreasing),
            ("with larger d_c the DOP peak grows", "DOP_peak", _increasing),
        )
        for s in ("thickness", "thickness_coherent")
    },
}


def _claim(
    study: str,
    claim: str,
    holds: bool,
    rows: list[tuple[str, dict[str, float]]],
    keys: Iterable[str],
) -> dict[str, Any]:
    """One entry of :func:`evaluate_claims`: the claim, its verdict and the numbers read."""
    ev = {lab: {k: st[k] for k in keys} for lab, st in rows}
    return {"study": study, "claim": claim, "holds": bool(holds), "evidence": ev}


def _common_claims(
    study: str, rows: list[tuple[str, dict[str, float]]], tol: float, z_max: float
) -> list[dict[str, Any]]:
    """The claims every study makes: mirror symmetry, the specular S0 peak, grazing DOP."""
    sym_s0 = all(st["S0_symmetry_z"] <= z_max for _, st in rows)
    sym_dop = all(st["DOP_symmetry_z"] <= z_max for _, st in rows)
    spec = all(abs(st["S0_plane_argmax_deg"] - st["theta_i_deg"]) <= tol for _, st in rows)
    grazing = all(
        st["DOP_peak_theta_deg"] >= 80 and abs(st["DOP_peak_phi_deg"] - 180) <= 10
        for _, st in rows
    )
    return [
        _claim(study, "S0 is symmetric about phi_r = 180 deg", sym_s0, rows, ("S0_symmetry_z",)),
        _claim(
            study, "DOP is symmetric about phi_r = 180 deg", sym_dop, rows, ("DOP_symmetry_z",)
        ),
        _claim(
            study,
            "S0 is largest at theta_r = theta_i in the plane phi_r = 180 deg",
            spec,
            rows,
            ("S0_plane_argmax_deg", "theta_i_deg"),
        ),
        _claim(
            study,
            "DOP is largest at (theta_r = 90, phi_r = 180) deg",
            grazing,
            rows,
            ("DOP_peak", "DOP_peak_theta_deg", "DOP_peak_phi_deg"),
        ),
    ]


def _trend_claims(study: str, rows: list[tuple[str, dict[str, float]]]) -> list[dict[str, Any]]:
    """The study's own trend claims (:data:`_TRENDS`) on its labels in the paper's order."""
    out = []
    for claim, key, test in _TRENDS.get(study, ()):
        values = [st[key] for _, st in rows]
        if test is _middle_max and len(values) != 3:
            continue  # "largest at lambda/4" needs the paper's three thicknesses
        out.append(_claim(study, claim, test(values), rows, (key,)))
    return out


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
    tol = 1.0 * max(1.0, float(studies[0][2].config.theta_step_deg)) if studies else 1.0
    out: list[dict[str, Any]] = []
    for study, rows in by.items():
        out += _common_claims(study, rows, tol, z_max)
    for study in ("incidence", "roughness", "substrate", "thickness", "thickness_coherent"):
        if study in by:
            out += _trend_claims(study, by[study])
    return out
