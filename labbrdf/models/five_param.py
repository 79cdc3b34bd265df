"""Wu Zhensen's five-parameter semi-empirical BRDF, eq. (3) of Zou, Bai, Wu (2013).

Physics layer: numpy only.

References
----------
.. [1] Wu Z., Xie D., Xie P., Wei Q., "Modeling reflectance function from rough surface and
   algorithms", Acta Optica Sinica 22(8), 897-901 (2002).
.. [2] Zou X., Bai L., Wu Z., "Mirror reflectance spectrum modeling of smooth samples",
   Acta Optica Sinica 33(6), 0612008 (2013), eq. (3). doi:10.3788/AOS201333.0612008
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .base import Model, ModelError, Parameters
from .shadowing import g_maxwell_beard, g_none, g_torrance_sparrow

__all__ = ["DIFFUSE_FORMS", "SHADOWING", "FiveParam", "five_param_geometry"]

#: built-in shadowing choices (a user callable is also accepted)
SHADOWING = ("ts", "none", "mb")

#: diffuse forms: name -> (basis function of theta_i [sr^-1], reciprocal?)
DIFFUSE_FORMS: dict[str, tuple[Callable[[NDArray], NDArray], bool]] = {
    "kd_over_cos_i": (lambda ti: 1.0 / np.cos(ti), False),
    "lambert": (lambda ti: np.ones_like(ti), True),
    "kd_cos_i": (lambda ti: np.cos(ti), False),
}


def five_param_geometry(
    theta_i: NDArray, theta_r: NDArray, phi_r: NDArray
) -> tuple[NDArray, NDArray]:
    """Facet tilt and local incidence cosines of the five-parameter model, [2]_ below eq. (3).

    ``cos^2(gamma) = [cos ti cos tr + sin ti sin tr cos(phi_r - phi_i) + 1] / 2`` and
    ``cos(alpha) = (cos ti + cos tr) / (2 cos gamma)``, with phi_i = 0.

    Parameters
    ----------
    theta_i, theta_r : ndarray
        Source and detector polar angles [rad].
    phi_r : ndarray
        Outward azimuth of the detector, source at 0 [rad]; the specular half-plane is pi.

    Returns
    -------
    cos_alpha, cos_gamma : ndarray
        N.H and L.H [1].

    Notes
    -----
    2 gamma is the angle between the outward directions L and V, so the lobe (alpha = 0) lands
    at phi_r = pi. Data with phi = 0 on the forward side must be converted on import.
    """
    ldotv = np.cos(theta_i) * np.cos(theta_r) + np.sin(theta_i) * np.sin(theta_r) * np.cos(phi_r)
    cos_gamma = np.sqrt(np.clip(0.5 * (1.0 + ldotv), 0.0, None))
    with np.errstate(divide="ignore", invalid="ignore"):
        cos_alpha = (np.cos(theta_i) + np.cos(theta_r)) / (2.0 * cos_gamma)
    return cos_alpha, cos_gamma


class FiveParam(Model):
    """Five-parameter semi-empirical BRDF (Wu et al. 2002), as written in eq. (3) of [2]_.

    ``f = k_b [k_r^2 cos a / (1 + (k_r^2 - 1) cos a)] exp[b (1 - cos g)^a_] G / (cos ti cos tr)
    + diffuse`` [sr^-1], where ``a`` is the facet tilt, ``g`` the local incidence angle and
    ``a_`` the parameter ``a``.

    Other Parameters
    ----------------
    shadowing : {"ts", "none", "mb"} or callable, default "ts"
        G: Torrance-Sparrow V-groove in Blinn's form, 1, or Maxwell-Beard (adds the fixed
        parameters ``Omega`` and ``tau`` [rad]); a callable
        ``G(theta_i, theta_r, phi_r, cos_alpha, cos_gamma)`` is used as given.
    diffuse : {"kd_over_cos_i", "lambert", "kd_cos_i"}, default "kd_over_cos_i"
        The diffuse term ``k_d / cos ti`` (as printed in [2]_), ``k_d`` or ``k_d cos ti``.

    Parameters: ``kb`` [sr^-1] in [1e-6, 1e3] (log), ``kr`` [1] in [1e-3, 3] (log),
    ``a`` [1] in [0.05, 10], ``b`` [1] in [-20, 20], ``kd`` [sr^-1] in [0, 1/pi]
    (docs/models.md 2.4). ``kb`` and ``kd`` enter linearly.

    Notes
    -----
    The shadowing function G is **unverified against the 2002 paper**: its text could not be
    read (docs/models.md 2.2); the V-groove default is the Torrance-Sparrow heritage choice.
    Fitted ``kb, kr, a, b`` are not comparable across G choices, so the choice is kept in
    ``options``. The specular term is reciprocal for every built-in G; the printed diffuse
    term ``k_d / cos ti`` is not, so the model is reciprocal only for ``kd == 0`` or the
    ``lambert`` form. Energy is not conserved at grazing incidence for ``kd > 0`` with the
    printed diffuse form.
    """

    name = "five_param"
    reference = (
        "Wu Z., Xie D., Xie P., Wei Q., Acta Optica Sinica 22(8) 897-901 (2002); "
        "eq. (3) of Zou, Bai, Wu, Acta Optica Sinica 33(6) 0612008 (2013)"
    )
    doi = "10.3788/AOS201333.0612008"
    reciprocity_note = (
        "five_param is not reciprocal in general: its diffuse term k_d / cos\u03b8i "
        "depends on the incidence direction alone; it is reciprocal only for k_d = 0."
    )
    linear = ("kb", "kd")

    def __init__(
        self,
        shadowing: str | Callable[..., Any] = "ts",
        diffuse: str = "kd_over_cos_i",
        **options: Any,
    ) -> None:
        if options:
            raise ModelError(
                f"model 'five_param' got unknown options {sorted(options)}; "
                "options are ['shadowing', 'diffuse']"
            )
        if not callable(shadowing) and shadowing not in SHADOWING:
            raise ModelError(
                f"five_param option 'shadowing' must be one of {list(SHADOWING)} "
                f"or a callable G(theta_i, theta_r, phi_r, cos_alpha, cos_gamma); "
                f"got {shadowing!r}"
            )
        if diffuse not in DIFFUSE_FORMS:
            raise ModelError(
                f"five_param option 'diffuse' must be one of "
                f"{list(DIFFUSE_FORMS)}; got {diffuse!r}"
            )
        self._shadowing = shadowing
        self._diffuse = diffuse
        super().__init__(shadowing=shadowing, diffuse=diffuse)

    def default_params(self) -> Parameters:
        """Defaults and bounds of docs/models.md 2.4 (engineering judgement)."""
        p = Parameters()
        p.add("kb", 1.0, 1e-6, 1e3, units="sr-1", log=True, description="specular amplitude")
        p.add("kr", 0.1, 1e-3, 3.0, units="1", log=True, description="facet slope parameter")
        p.add("a", 1.5, 0.05, 10.0, units="1", description="Fresnel-like exponent")
        p.add("b", 1.0, -20.0, 20.0, units="1", description="Fresnel-like rise")
        p.add("kd", 0.0, 0.0, 1.0 / math.pi, units="sr-1", description="diffuse amplitude")
        if self._shadowing == "mb":
            p.add(
                "Omega",
                0.7,
                1e-3,
                math.pi,
                vary=False,
                units="rad",
                log=True,
                description="Maxwell-Beard Omega",
            )
            p.add(
                "tau",
                0.25,
                1e-3,
                math.pi,
                vary=False,
                units="rad",
                log=True,
                description="Maxwell-Beard tau",
            )
        return p

    # ------------------------------------------------------------------ pieces
    def shadowing(
        self, p: Mapping[str, float], theta_i: NDArray, theta_r: NDArray, phi_r: NDArray
    ) -> NDArray[np.float64]:
        """G [1] for the chosen shadowing option (see class docstring)."""
        ca, cg = five_param_geometry(theta_i, theta_r, phi_r)
        return self._g(p, theta_i, theta_r, phi_r, ca, cg)

    def _g(
        self,
        p: Mapping[str, float],
        ti: NDArray,
        tr: NDArray,
        pr: NDArray,
        ca: NDArray,
        cg: NDArray,
    ) -> NDArray:
        s = self._shadowing
        if callable(s):
            return np.asarray(s(ti, tr, pr, ca, cg), dtype=float)
        if s == "ts":
            return g_torrance_sparrow(ti, tr, ca, cg)
        if s == "none":
            return g_none(ti, tr, ca, cg)
        for k in ("Omega", "tau"):
            if not p[k] > 0:
                raise ModelError(f"five_param parameter {k!r} must be > 0 [rad]; got {p[k]!r}")
        return g_maxwell_beard(ca, cg, p["Omega"], p["tau"])

    def _bases(
        self, p: Mapping[str, float], ti: NDArray, tr: NDArray, pr: NDArray
    ) -> tuple[NDArray, NDArray]:
        kr, a, b = p["kr"], p["a"], p["b"]
        if not kr > 0:
            raise ModelError(f"five_param parameter 'kr' must be > 0; got {kr!r}")
        if not a > 0:
            raise ModelError(f"five_param parameter 'a' must be > 0; got {a!r}")
        ca, cg = five_param_geometry(ti, tr, pr)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            dist = kr**2 * ca / (1.0 + (kr**2 - 1.0) * ca)
            fres = np.exp(b * np.clip(1.0 - cg, 0.0, None) ** a)
            spec = dist * fres * self._g(p, ti, tr, pr, ca, cg) / (np.cos(ti) * np.cos(tr))
            diff = DIFFUSE_FORMS[self._diffuse][0](ti)
        return spec, np.broadcast_to(diff, spec.shape)

    # ------------------------------------------------------------------ Model API
    def _evaluate(
        self,
        p: Mapping[str, float],
        theta_i: NDArray,
        theta_r: NDArray,
        phi_r: NDArray,
        wavelength: NDArray | None,
    ) -> NDArray:
        spec, diff = self._bases(p, theta_i, theta_r, phi_r)
        return p["kb"] * spec + p["kd"] * diff

    def linear_components(
        self,
        p: Mapping[str, float],
        theta_i: NDArray,
        theta_r: NDArray,
        phi_r: NDArray,
        wavelength: NDArray | None,
    ) -> dict[str, NDArray] | None:
        """``{"kb": specular basis, "kd": diffuse basis}``; f = kb * b_kb + kd * b_kd."""
        spec, diff = self._bases(p, theta_i, theta_r, phi_r)
        return {"kb": spec, "kd": np.array(diff)}

    def lobe_width(self, p: Mapping[str, float]) -> float:
        """Angular scale of the lobe in theta_r [rad] (a quadrature hint): ``2 sqrt(2) kr``."""
        return 2.0 * math.sqrt(2.0) * float(p["kr"])

    def kink_functions(
        self, p: Mapping[str, float], theta_i: float
    ) -> list[Callable[[NDArray, NDArray], NDArray]]:
        """Functions of (theta_r, phi_r) whose zeros are kinks of f (a quadrature hint).

        For the ``ts`` shadowing these are the switches of the min():
        ``2 cos(alpha) cos(theta) - cos(gamma)`` for theta = theta_r and theta_i.
        """
        if self._shadowing != "ts":
            return []

        def switch(use_r: bool) -> Callable[[NDArray, NDArray], NDArray]:
            def h(tr: NDArray, pr: NDArray) -> NDArray:
                ca, cg = five_param_geometry(np.asarray(theta_i), tr, pr)
                return 2.0 * ca * np.cos(tr if use_r else theta_i) - cg

            return h

        return [switch(True), switch(False)]

    def is_reciprocal(self, params: Mapping[str, float] | None = None) -> bool:
        """True iff the diffuse term is reciprocal (``lambert`` or ``kd == 0``) and G is symmetric.

        Built-in G are symmetric; a user callable is checked on a 5-degree grid.
        """
        p = self.values(params)
        if not (DIFFUSE_FORMS[self._diffuse][1] or p["kd"] == 0.0):
            return False
        if not callable(self._shadowing):
            return True
        t = np.radians(np.arange(0.0, 90.0, 5.0))
        ti, tr, pr = np.meshgrid(t, t, np.radians(np.arange(0.0, 361.0, 30.0)), indexing="ij")
        ca, cg = five_param_geometry(ti, tr, pr)
        g1 = self._g(p, ti, tr, pr, ca, cg)
        g2 = self._g(p, tr, ti, pr, ca, cg)
        return bool(np.array_equal(g1, g2))
