"""ABg (Harvey) scatter model in direction-cosine space, for reflection and transmission.

Physics layer: numpy and scipy.special / scipy.integrate only.

``f = A / (B + |beta - beta0|^g)`` [sr^-1] (+ ``kd / pi`` with ``diffuse``), where
``beta = (sin theta_s cos phi_s, sin theta_s sin phi_s)`` is the projection of the scatter
direction on the sample plane (its direction cosines) and ``beta0`` that of the specular
direction, ``(-sin theta_i, 0)`` with the source at ``phi = 0``. For transmission
(``transmission=True``) the directions are those of the BTDF frame (the reflection frame
mirrored in the sample plane, as in the ``.bsdf`` format) and ``beta0`` is the projection of
the direction of direct transmission, which is the same ``(-sin theta_i, 0)`` in that frame
for a thin sample between equal media (the convention of tabulated BTDF files). The model
is the *scattered* part: the specular (or directly transmitted) beam is a separate term
that the model leaves out.

The form depends on the scatter direction only through ``beta - beta0``: it is
shift-invariant in direction cosines (Harvey's observation), so one set (A, B, g) describes
every angle of incidence. For ``B -> 0`` it is the power law ``A |beta - beta0|^-g`` of a
fractal (inverse power law) PSD; ``B`` sets the shoulder, ``|beta - beta0| ~ B^(1/g)``,
below which the BSDF flattens to ``A / B`` at the specular direction.

References
----------
.. [1] Harvey J. E., "Light-scattering characteristics of optical surfaces", Ph.D.
   dissertation, University of Arizona (1976); Harvey J. E., Vernold C. L., "Transfer
   function characterization of scattering surfaces: revisited", Proc. SPIE 3141, 113-127
   (1997). doi:10.1117/12.279238
.. [2] Stover J. C., *Optical Scattering: Measurement and Analysis*, 3rd ed., SPIE Press
   (2012), sections 2.4 and 10.3 (direction cosines, the ABg and K-correlation forms).
   doi:10.1117/3.975276
.. [3] Zemax OpticStudio user manual, "ABg scatter model" and "ABg data file" (the form
   ``A / (B + |beta - beta0|^g)`` with beta the projected direction cosines).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import integrate, special

from .base import Model, ModelError, Parameters, lambert

__all__ = ["ABg", "abg_tis", "disk_integral", "shift_invariant_tis"]


def disk_integral(radius: ArrayLike, B: float, g: float) -> NDArray[np.float64]:
    """``int_0^R rho / (B + rho^g) d rho`` in closed form [1].

    ``R^2 / (2 B) 2F1(1, 2/g; 1 + 2/g; -R^g / B)`` (substitute ``t = rho^g / B`` in the
    integral representation of the Gauss hypergeometric function, Abramowitz & Stegun
    15.3.1). Multiplied by ``2 pi A`` it is the ABg scatter within ``|beta - beta0| < R``.

    Parameters
    ----------
    radius : array_like
        Upper limit R >= 0 [1] (a distance in direction cosines).
    B, g : float
        ABg parameters, ``B > 0``, ``g > 0``.

    Returns
    -------
    ndarray
        The integral, shaped like ``radius``.
    """
    r = np.asarray(radius, dtype=float)
    a = 2.0 / g
    return r**2 / (2.0 * B) * special.hyp2f1(1.0, a, 1.0 + a, -(r**g) / B)


def shift_invariant_tis(
    theta_i_deg: ArrayLike, radial: Callable[[NDArray], NDArray], *, rtol: float = 1e-12
) -> NDArray[np.float64]:
    """TIS [1] of a BSDF that depends on ``rho = |beta - beta0|`` only, over the hemisphere.

    ``TIS = int_{|beta| < 1} f(|beta - beta0|) d^2 beta`` (``cos theta d omega = d^2 beta``:
    the projected solid angle is the area in direction cosines). In polar coordinates about
    ``beta0`` the radial integral ``radial(R) = int_0^R f(rho) rho d rho`` is the caller's
    closed form; at normal incidence the disk is centred and ``TIS = 2 pi radial(1)``. Off
    normal the ray from ``beta0`` at angle ``psi`` leaves the unit disk at ``rho_max(psi) =
    -b cos psi + sqrt(1 - b^2 sin^2 psi)`` (``b = sin theta_i``), and the integral over
    ``psi`` is done by adaptive quadrature.

    Parameters
    ----------
    theta_i_deg : array_like
        Angle of incidence [deg] in [0, 90).
    radial : callable
        ``radial(R)`` for an array of R >= 0 [1].
    rtol : float
        Relative tolerance of the azimuth quadrature.

    Returns
    -------
    ndarray
        TIS [1], shaped like ``theta_i_deg``.
    """
    t = np.asarray(theta_i_deg, dtype=float)
    out = np.empty(t.shape)
    for idx, ti in np.ndenumerate(t):
        b = math.sin(math.radians(float(ti)))
        if b == 0.0:
            out[idx] = 2.0 * math.pi * float(radial(np.asarray(1.0)))
            continue

        def inner(psi: float, b: float = b) -> float:
            rmax = -b * math.cos(psi) + math.sqrt(1.0 - (b * math.sin(psi)) ** 2)
            return float(radial(np.asarray(rmax)))

        half, _ = integrate.quad(inner, 0.0, math.pi, epsabs=0.0, epsrel=rtol, limit=200)
        out[idx] = 2.0 * half  # even in psi: twice the half circle
    return out


def abg_tis(
    theta_i_deg: ArrayLike, A: float, B: float, g: float, *, rtol: float = 1e-12
) -> NDArray[np.float64]:
    """Total integrated scatter of the ABg term over the hemisphere [1].

    :func:`shift_invariant_tis` with the radial integral ``A`` :func:`disk_integral`: in
    closed form at normal incidence, one adaptive quadrature over the azimuth otherwise.

    Parameters
    ----------
    theta_i_deg : array_like
        Angle of incidence [deg] in [0, 90).
    A : float
        [sr^-1], >= 0.
    B, g : float
        > 0.
    rtol : float
        Relative tolerance of the azimuth quadrature.

    Returns
    -------
    ndarray
        TIS [1], shaped like ``theta_i_deg``.
    """
    if not (B > 0 and g > 0 and A >= 0):
        raise ModelError(f"abg TIS needs A >= 0, B > 0, g > 0; got A={A!r}, B={B!r}, g={g!r}")
    return shift_invariant_tis(theta_i_deg, lambda r: A * disk_integral(r, B, g), rtol=rtol)


class ABg(Model):
    """The ABg (Harvey) scatter model, ``A / (B + |beta - beta0|^g)`` [sr^-1].

    Other Parameters
    ----------------
    transmission : bool, default False
        The transmission form: fitted to BTDF data (quantity ``btdf``), ``beta0`` the
        direction of direct transmission (see the module docstring). The reflection form
        takes BRDF data only (not specular intensities: the model is the scatter).
    diffuse : bool, default False
        Add a Lambertian floor ``kd / pi`` [sr^-1], ``kd`` its hemispherical albedo.

    Parameters: ``A`` [sr^-1] in [0, 10] (linear: profiled out in fits; the fitting core
    flags a value within 1e-6 of the range, 1e-5 sr^-1, as at its bound), ``B`` [1] in
    [1e-10, 10] (log), ``g`` [1] in [0.05, 4]; with ``diffuse``, ``kd`` [1] in [0, 1]
    (linear).

    Notes
    -----
    Reciprocal: ``beta - beta0 = beta_s + beta_i`` (``beta_i`` the projection of the
    direction towards the source) is symmetric in the two directions. This is the form
    design programs take (the BSDF itself shift-invariant); Harvey's original statement is
    for ``f cos theta_s`` (the radiance), which differs from it away from the specular
    direction (Stover 2012, section 2.4; ``docs/harvey.md``). Only directions above the
    horizon are evaluated; below, 0.
    """

    name = "abg"
    #: the linear amplitude that multiplies the scatter shape (profiled out in fits)
    amplitude = "A"
    reference = (
        "Harvey J. E., Vernold C. L., Transfer function characterization of scattering "
        "surfaces: revisited, Proc. SPIE 3141 (1997); Stover, Optical Scattering (2012)"
    )
    doi = "10.1117/12.279238"
    reciprocity_note = (
        "abg is reciprocal by construction (|beta - beta0| = |beta_s + beta_i| is symmetric "
        "in the two directions, and the Lambertian kd / pi is constant)."
    )
    linear: tuple[str, ...] = ("A",)

    def __init__(self, transmission: bool = False, diffuse: bool = False, **options: Any) -> None:
        if options:
            raise ModelError(
                f"model 'abg' got unknown options {sorted(options)}; options are "
                "['diffuse', 'transmission']"
            )
        self._diffuse = bool(diffuse)
        self.transmission = bool(transmission)
        if self._diffuse:
            self.linear = ("A", "kd")
        # the scattered part only: BSDF data, never a specular intensity
        self.quantities = ("btdf",) if self.transmission else ("brdf",)
        opts: dict[str, Any] = {}
        if self.transmission:
            opts["transmission"] = True
        if self._diffuse:
            opts["diffuse"] = True
        super().__init__(**opts)

    def default_params(self) -> Parameters:
        """A 0.01, B 1e-3 (log), g 2; kd 0 with ``diffuse``."""
        p = Parameters()
        p.add("A", 1e-2, 0.0, 10.0, units="sr-1", description="ABg amplitude")
        p.add("B", 1e-3, 1e-10, 10.0, units="1", log=True, description="ABg shoulder")
        p.add("g", 2.0, 0.05, 4.0, units="1", description="ABg slope")
        if self._diffuse:
            p.add("kd", 0.0, 0.0, 1.0, units="1", description="Lambertian albedo")
        return p

    # ------------------------------------------------------------------ geometry
    @staticmethod
    def delta_beta(theta_i: NDArray, theta_s: NDArray, phi_s: NDArray) -> NDArray:
        """``|beta - beta0|`` [1] of scatter directions (radians; source at phi = 0)."""
        st = np.sin(theta_s)
        return np.hypot(st * np.cos(phi_s) + np.sin(theta_i), st * np.sin(phi_s))

    def lobe_width(self, p: Mapping[str, float]) -> float:
        """Angular scale of the lobe [rad] (a quadrature hint): the shoulder ``B^(1/g)``."""
        return float(min(max(p["B"] ** (1.0 / p["g"]), 1e-4), 0.5))

    def _scatter(self, p: Mapping[str, float], ti: NDArray, ts: NDArray, ps: NDArray) -> NDArray:
        B, g = p["B"], p["g"]
        if not (B > 0 and g > 0):
            raise ModelError(f"abg parameters B and g must be > 0; got B={B!r}, g={g!r}")
        up = (np.cos(ti) > 0) & (np.cos(ts) > 0)
        return np.where(up, 1.0 / (B + self.delta_beta(ti, ts, ps) ** g), 0.0)

    def _evaluate(
        self,
        p: Mapping[str, float],
        theta_i: NDArray,
        theta_r: NDArray,
        phi_r: NDArray,
        wavelength: NDArray | None,
    ) -> NDArray:
        out = p[self.amplitude] * self._scatter(p, theta_i, theta_r, phi_r)
        if self._diffuse:
            out = out + p["kd"] * lambert(theta_i, theta_r)
        return out

    def linear_components(
        self,
        p: Mapping[str, float],
        theta_i: NDArray,
        theta_r: NDArray,
        phi_r: NDArray,
        wavelength: NDArray | None,
    ) -> dict[str, NDArray] | None:
        """``{amplitude: the scatter shape}`` (and ``"kd": 1 / pi`` with ``diffuse``).

        For ABg ``{"A": 1 / (B + |beta - beta0|^g)}``; a subclass names its own amplitude
        (:attr:`amplitude`) and shape (``_scatter``).
        """
        out = {self.amplitude: self._scatter(p, theta_i, theta_r, phi_r)}
        if self._diffuse:
            out["kd"] = np.broadcast_to(lambert(theta_i, theta_r), np.shape(theta_r)).copy()
        return out

    def is_reciprocal(self, params: Mapping[str, float] | None = None) -> bool:
        """Always True."""
        return True

    def guess(self, theta_i: NDArray, theta_r: NDArray, value: NDArray) -> dict[str, float]:
        """B from the half width of the in-plane lobe, g = 2 and A = peak * B."""
        v = np.asarray(value, float)
        if v.size == 0 or not np.any(v > 0):
            return {}
        j = int(np.argmax(v))
        d = np.abs(np.sin(np.asarray(theta_r, float)) - np.sin(np.asarray(theta_i, float)))
        near = d[(v >= 0.5 * v[j]) & (d > 0)]
        half = float(np.clip(np.max(near) if near.size else 0.05, 1e-4, 1.0))
        B = float(np.clip(half**2, 1.1e-10, 9.0))
        return {"B": B, "g": 2.0, "A": float(np.clip(v[j] * B, 0.0, 10.0))}

    def hemispherical(
        self, theta_i_deg: ArrayLike, params: Mapping[str, float] | None = None
    ) -> NDArray[np.float64] | None:
        """TIS [1] of the scattered part (+ ``kd``): :func:`abg_tis`.

        The hemisphere is that of the data: reflected (BRDF) or transmitted (BTDF) light.
        """
        p = self.values(params)
        tis = abg_tis(theta_i_deg, p["A"], p["B"], p["g"])
        if self._diffuse:
            tis = tis + p["kd"]
        return tis
