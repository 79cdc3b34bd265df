"""Hemispherical integrals: reflectance, energy and reciprocity checks, grid quadrature.

The models' hemispherical reflectance and its checks; the quadrature of tabulated BSDF
values on a scatter grid about the specular direction (:func:`grid_integral`) lives with the
grid's geometry in :mod:`labbrdf.bsdf_geometry`, below the file readers, and is offered here
too.

Model layer: numpy + scipy and :mod:`labbrdf.models`. Angles at the public boundary are in degrees.

References
----------
.. [1] Zou X., Bai L., Wu Z., "Mirror reflectance spectrum modeling of smooth samples",
   Acta Optica Sinica 33(6), 0612008 (2013). doi:10.3788/AOS201333.0612008
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import brentq, minimize_scalar

from .bsdf_geometry import grid_integral
from .models.base import Model, Parameters
from .models.smooth3 import smooth3_hemispherical, smooth3_lobe_integral

__all__ = [
    "EnergyCheck",
    "ReciprocityDefect",
    "energy_check",
    "energy_limit_angle",
    "grid_integral",
    "hemispherical_reflectance",
    "k1_max_energy",
    "reciprocity_defect",
    "smooth3_hemispherical",
    "smooth3_lobe_integral",
]

#: default relative accuracy of the hemispherical quadrature (convergence target)
RTOL = 1e-6
_N_START = 8
_N_MAX = 128
_MAX_KINKS = 2


# ----------------------------------------------------------------------------- smooth3
def k1_max_energy(k2: float, k3: float, theta_max_deg: float) -> float:
    """Largest k1 for which smooth3 keeps ``rho(theta) <= 1`` for all ``theta <= theta_max``.

    ``k1_max = 4 / (pi max_{0 <= theta <= theta_max} I(theta) / cos(theta))``
    (docs/models.md 1.4; replaces the paper's ``k1 <= 4/pi``, eq. (8) of [1]_).

    Parameters
    ----------
    k2, k3 : float
        Lobe shift and 1/e half-width [rad].
    theta_max_deg : float
        Largest incidence angle to protect [deg], in [0, 90).

    Returns
    -------
    float
        k1_max [1].
    """
    tmax = math.radians(float(_check_theta_i(theta_max_deg, "theta_max_deg")))

    def g(t: float | NDArray) -> NDArray:
        return smooth3_lobe_integral(t, k2, k3) / np.cos(t)

    grid = np.linspace(0.0, tmax, 721)
    vals = g(grid)
    j = int(np.argmax(vals))
    best = float(vals[j])
    lo, hi = grid[max(j - 1, 0)], grid[min(j + 1, grid.size - 1)]
    if hi > lo:
        res = minimize_scalar(
            lambda t: -float(g(t)), bounds=(lo, hi), method="bounded", options={"xatol": 1e-12}
        )
        best = max(best, -float(res.fun))
    return 4.0 / (math.pi * best)


# ----------------------------------------------------------------------------- quadrature
def _check_theta_i(theta_i_deg: ArrayLike, name: str = "theta_i_deg") -> NDArray[np.float64]:
    t = np.asarray(theta_i_deg, dtype=float)
    if not np.all(np.isfinite(t)) or np.any(t < 0) or np.any(t >= 90):
        raise ValueError(f"{name} must be finite and in [0, 90) degrees; got {theta_i_deg!r}")
    return t


def _lobe_width(model: Model, p: Mapping[str, float]) -> float:
    fn = getattr(model, "lobe_width", None)
    w = float(fn(p)) if callable(fn) else 0.2
    return min(max(w, 1e-4), 0.5)


def _panels(a: float, b: float, breaks: list[float]) -> NDArray[np.float64]:
    pts = np.unique(np.clip(np.array([a, b, *breaks]), a, b))
    keep = np.concatenate([[True], np.diff(pts) > 1e-9 * (b - a)])
    return pts[keep]


def _gauss(edges: NDArray, n: int) -> tuple[NDArray, NDArray]:
    x, w = np.polynomial.legendre.leggauss(n)
    lo, hi = edges[:-1, None], edges[1:, None]
    half = 0.5 * (hi - lo)
    return (lo + half * (x + 1.0)).ravel(), (half * w).ravel()


def _kinks(model: Model, p: Mapping[str, float], ti: float, ph: NDArray) -> NDArray:
    """Zeros in theta_r (per azimuth node) of the model's kink functions, NaN-padded."""
    fn = getattr(model, "kink_functions", None)
    funcs = fn(p, ti) if callable(fn) else []
    if not funcs:
        return np.empty((ph.size, 0))
    grid = np.linspace(0.0, math.pi / 2, 181)
    out = []
    for h in funcs:
        v = h(grid[None, :], ph[:, None])
        change = np.signbit(v[:, :-1]) != np.signbit(v[:, 1:])
        for _ in range(_MAX_KINKS):
            j = np.argmax(change, axis=1)
            has = change[np.arange(ph.size), j]
            change[np.arange(ph.size), j] = False
            lo, hi = grid[j].copy(), grid[j + 1].copy()
            slo = np.signbit(h(lo, ph))
            for _ in range(55):  # bisection to ~1e-16 rad
                mid = 0.5 * (lo + hi)
                same = np.signbit(h(mid, ph)) == slo
                lo, hi = np.where(same, mid, lo), np.where(same, hi, mid)
            out.append(np.where(has, 0.5 * (lo + hi), np.nan))
    return np.stack(out, axis=1)


def _hemi_quad(model: Model, p: Mapping[str, float], ti: float, width: float, n: int) -> float:
    steps = width * np.array([0.25, 0.5, 1.0, 2.0, 4.0, 8.0, 16.0])
    centre = getattr(model, "lobe_centre", None)
    tc = float(centre(p, ti)) if callable(centre) else ti
    tb = [ti, tc, *(tc - steps), *(tc + steps), math.pi / 2 - 0.02, math.pi / 2 - 0.1]
    tb.append(math.acos(min(2.0 * width, 1.0)))  # steep masking edge: cos = 4 alpha (GGX)
    t_edges = _panels(0.0, math.pi / 2, tb)
    s = max(math.sin(ti), width)
    p_edges = _panels(0.0, math.pi, [math.pi - k / s for k in steps])
    ph, wp = _gauss(p_edges, n)
    kinks = _kinks(model, p, ti, ph)
    if kinks.shape[1] == 0:
        tr, wt = _gauss(t_edges, n)
        tr2, wt2 = tr[None, :], wt[None, :]
    else:  # per-azimuth panels that also break at the kinks
        edges = np.concatenate(
            [np.broadcast_to(t_edges, (ph.size, t_edges.size)), np.nan_to_num(kinks, nan=0.0)],
            axis=1,
        )
        edges.sort(axis=1)
        x, w = np.polynomial.legendre.leggauss(n)
        half = 0.5 * np.diff(edges, axis=1)[:, :, None]
        tr2 = (edges[:, :-1, None] + half * (x + 1.0)).reshape(ph.size, -1)
        wt2 = (half * w).reshape(ph.size, -1)
    f = model.evaluate(ti, tr2, ph[:, None], params=p)
    integrand = f * np.cos(tr2) * np.sin(tr2) * wt2 * wp[:, None]
    return 2.0 * float(np.sum(integrand))


def _hemi_adaptive(model: Model, p: Mapping[str, float], ti: float, rtol: float) -> float:
    width = _lobe_width(model, p)
    n = _N_START
    prev = _hemi_quad(model, p, ti, width, n)
    while n < _N_MAX:
        n *= 2
        cur = _hemi_quad(model, p, ti, width, n)
        change = abs(cur - prev)
        if change <= rtol * abs(cur) + 1e-15:
            return cur
        prev = cur
    raise RuntimeError(
        f"hemispherical quadrature of {model.name!r} at theta_i = "
        f"{math.degrees(ti):.6g} deg did not converge to rtol {rtol:g} "
        f"with {_N_MAX} nodes per panel (last change {change:.3g})"
    )


def hemispherical_reflectance(
    model: Model,
    params: Mapping[str, float] | Parameters | None,
    theta_i_deg: ArrayLike,
    *,
    method: str = "auto",
    rtol: float = RTOL,
) -> NDArray[np.float64]:
    """Directional-hemispherical reflectance ``rho = int f cos(theta_r) d omega_r`` of a model.

    Parameters
    ----------
    model : Model
        Any registered model (its ``evaluate`` gives f [sr^-1]).
    params : mapping or Parameters or None
        Parameter values; None uses the model's current values.
    theta_i_deg : array_like
        Incidence angle(s) [deg], in [0, 90).
    method : {"auto", "closed", "quadrature"}
        ``auto`` uses the model's closed form (:meth:`labbrdf.models.Model.hemispherical`)
        where it has one (smooth3) and quadrature otherwise.
    rtol : float
        Relative accuracy target of the quadrature: the Gauss-Legendre nodes per panel are
        doubled (8 to 128) until two successive results agree to ``rtol``; otherwise a
        RuntimeError is raised. The change bounds the error of the last result as long as
        convergence is at least as fast as n^-2 (exponential on smooth panels, n^-2 across
        an unresolved kink); the tests check the 1e-6 claim against closed forms and the
        oracle albedos.

    Returns
    -------
    ndarray
        rho [1] (a fraction), shaped like ``theta_i_deg``.

    Notes
    -----
    Composite Gauss-Legendre in ``theta_r`` (panels graded geometrically around the specular
    angle and ``model.lobe_centre(p, theta_i)`` on the scale ``model.lobe_width(p)``, broken
    at the zeros of ``model.kink_functions(p, theta_i)`` per azimuth node, and graded near the
    horizon) times composite Gauss-Legendre in ``phi_r`` on [0, pi] (panels graded towards
    the specular half-plane), doubled for the mirror half: models must be even in ``phi_r``,
    which holds for every isotropic model with the source at ``phi = 0``. The three hints are
    optional methods of the model. Cost: about 1e5 to 2e6 model evaluations per angle.
    """
    if method not in ("auto", "closed", "quadrature"):
        raise ValueError(f"method must be 'auto', 'closed' or 'quadrature'; got {method!r}")
    if not 0 < rtol < 1:
        raise ValueError(f"rtol must be in (0, 1); got {rtol!r}")
    t = _check_theta_i(theta_i_deg)
    p = model.values(params)
    if method != "quadrature":
        closed = model.hemispherical(t, p)
        if closed is not None:
            return np.asarray(closed, dtype=float)
        if method == "closed":
            raise ValueError(f"no closed form for model {model.name!r}; use method='quadrature'")
    flat = [_hemi_adaptive(model, p, math.radians(x), rtol) for x in t.ravel()]
    return np.asarray(flat, dtype=float).reshape(t.shape)


# ----------------------------------------------------------------------------- energy
class EnergyCheck(NamedTuple):
    """Energy conservation at given incidence angles (fractions, degrees)."""

    theta_i_deg: NDArray[np.float64]
    rho: NDArray[np.float64]
    ok: bool
    limit_angle_deg: float


def energy_limit_angle(
    model: Model,
    params: Mapping[str, float] | Parameters | None = None,
    *,
    rho_max: float = 1.0,
    step_deg: float = 1.0,
    theta_max_deg: float = 89.5,
) -> float:
    """Largest incidence angle up to which ``rho(theta) <= rho_max`` [deg].

    Scans ``0 .. theta_max_deg`` in ``step_deg`` steps, then refines the first crossing by
    Brent's method to 1e-6 deg (a crossing and re-crossing within one step is not seen; use
    a coarser step for quadrature-based models, whose every rho costs a 2-D quadrature).
    Returns ``theta_max_deg`` when rho never exceeds ``rho_max`` on the scan, and 0 when it
    already does at normal incidence.

    Parameters
    ----------
    model : Model
    params : mapping or Parameters or None
        None uses the model's current values.
    rho_max : float
        Energy limit [1].
    step_deg : float
        Scan step [deg], > 0.
    theta_max_deg : float
        End of the scan [deg], in (0, 90).

    Returns
    -------
    float
        The angle [deg].
    """
    if not step_deg > 0:
        raise ValueError(f"step_deg must be > 0; got {step_deg!r}")
    _check_theta_i(theta_max_deg, "theta_max_deg")
    p = model.values(params)

    def excess(x: float) -> float:
        return float(hemispherical_reflectance(model, p, x)) - rho_max

    grid = np.append(np.arange(0.0, theta_max_deg, step_deg), theta_max_deg)
    vals = hemispherical_reflectance(model, p, grid) - rho_max
    over = np.nonzero(vals > 0)[0]
    if over.size == 0:
        return float(theta_max_deg)
    j = int(over[0])
    if j == 0:
        return 0.0
    return float(brentq(excess, grid[j - 1], grid[j], xtol=1e-6, rtol=1e-12))


def energy_check(
    model: Model,
    params: Mapping[str, float] | Parameters | None,
    theta_i_deg: ArrayLike,
    *,
    rho_max: float = 1.0,
) -> EnergyCheck:
    """rho at the measured incidence angles, whether all are <= ``rho_max``, and the limit angle.

    Parameters
    ----------
    model : Model
    params : mapping or Parameters or None
    theta_i_deg : array_like
        Measured incidence angles [deg].
    rho_max : float
        Energy limit [1].

    Returns
    -------
    EnergyCheck
    """
    t = np.atleast_1d(_check_theta_i(theta_i_deg))
    rho = np.atleast_1d(hemispherical_reflectance(model, params, t))
    return EnergyCheck(
        t, rho, bool(np.all(rho <= rho_max)), energy_limit_angle(model, params, rho_max=rho_max)
    )


# ----------------------------------------------------------------------------- reciprocity
class ReciprocityDefect(NamedTuple):
    """Largest reciprocity defect ``|f(i, r) - f(r, i)|`` on a grid and where it occurs."""

    max_abs: float  #: [sr^-1]
    max_rel: float  #: relative to max(|f(i, r)|, |f(r, i)|) [1]
    theta_i_deg: float
    theta_r_deg: float
    phi_r_deg: float


def reciprocity_defect(
    model: Model,
    params: Mapping[str, float] | Parameters | None = None,
    *,
    theta_max_deg: float = 85.0,
    step_deg: float = 5.0,
    phi_step_deg: float = 15.0,
) -> ReciprocityDefect:
    """Reciprocity defect ``max |f(ti, tr, phi) - f(tr, ti, phi)|`` over a grid.

    Parameters
    ----------
    model : Model
    params : mapping or Parameters or None
        None uses the model's current values.
    theta_max_deg : float
        Largest polar angle of the grid [deg], in [0, 90).
    step_deg, phi_step_deg : float
        Grid steps in polar angle and azimuth [deg], > 0.

    Returns
    -------
    ReciprocityDefect
        Absolute [sr^-1] and relative [1] defects and the grid point of the absolute one.
    """
    _check_theta_i(theta_max_deg, "theta_max_deg")
    if not (step_deg > 0 and phi_step_deg > 0):
        raise ValueError(
            f"step_deg and phi_step_deg must be > 0; got {step_deg!r}, {phi_step_deg!r}"
        )
    p = model.values(params)
    t = np.append(np.arange(0.0, theta_max_deg, step_deg), theta_max_deg)
    ph = np.arange(0.0, 360.0, phi_step_deg)
    ti, tr, pr = np.meshgrid(t, t, ph, indexing="ij")
    a = model.evaluate(np.radians(ti), np.radians(tr), np.radians(pr), params=p)
    b = model.evaluate(np.radians(tr), np.radians(ti), np.radians(pr), params=p)
    d = np.abs(a - b)
    scale = np.maximum(np.abs(a), np.abs(b))
    with np.errstate(divide="ignore", invalid="ignore"):
        rel = np.where(scale > 0, d / scale, 0.0)
    k = np.unravel_index(int(np.argmax(d)), d.shape)
    return ReciprocityDefect(
        float(d[k]), float(np.max(rel)), float(ti[k]), float(tr[k]), float(pr[k])
    )
