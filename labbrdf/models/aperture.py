"""A model seen through an instrument: averaged over the detector's cone and the beam's.

Physics layer: numpy only.

A scatterometer does not measure the BSDF at one pair of directions: its detector collects
light over a solid angle (a field stop seen from the sample) and its beam arrives with a
divergence. The measured value is the BSDF averaged over both, so near the specular
direction of a smooth sample, where the BSDF changes on the scale of the aperture, a model
fitted without the average takes the instrument's width for the sample's (Stover 2012,
section 6.3, "instrument signature"). :class:`Apertured` wraps any model and returns that
average, so a fit of the wrapper estimates the sample's parameters.

The detector is a uniform cone of half-angle ``detector_deg`` about the nominal detector
direction; the beam a uniform cone of half-angle ``beam_deg`` about the nominal incident
direction. Each cone is integrated by a product rule on its cap: Gauss-Legendre in
``cos t`` (t the angle from the cone's axis, so that the nodes are uniform in solid angle)
times the periodic trapezoid rule in the azimuth about the axis. The model must be
isotropic (it depends on the detector azimuth relative to the source's), which every
registry model is.

References
----------
.. [1] Stover J. C., *Optical Scattering: Measurement and Analysis*, 3rd ed., SPIE Press
   (2012), chapter 6 (the instrument signature, detector solid angle and beam).
   doi:10.1117/3.975276
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .base import Model, ModelError, Parameters

__all__ = ["Apertured", "cap_nodes", "cone_directions"]

#: largest cone half-angle [deg]: beyond it the "aperture" is no longer a small instrument
#: width and the average would hide the sample's lobe
MAX_APERTURE_DEG = 20.0


def cap_nodes(
    half_angle_deg: float, n_t: int, n_psi: int
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Nodes ``(t, psi)`` [rad] and weights (summing to 1) of the uniform average over a cap.

    Gauss-Legendre with ``n_t`` nodes in ``cos t`` on ``[cos a, 1]`` and ``n_psi`` equally
    spaced azimuths: exact for polynomials in ``cos t`` of degree ``2 n_t - 1`` times
    trigonometric polynomials in ``psi`` of degree below ``n_psi``.
    """
    a = math.radians(half_angle_deg)
    x, w = np.polynomial.legendre.leggauss(n_t)
    lo = math.cos(a)
    u = lo + (1.0 - lo) * 0.5 * (x + 1.0)
    psi = 2.0 * np.pi * (np.arange(n_psi) + 0.5) / n_psi
    t = np.arccos(np.clip(u, -1.0, 1.0))
    tt, pp = np.meshgrid(t, psi, indexing="ij")
    ww = np.repeat(0.5 * w[:, None], n_psi, axis=1) / n_psi
    return tt.ravel(), pp.ravel(), ww.ravel()


def cone_directions(
    theta: NDArray, phi: NDArray, t: NDArray, psi: NDArray
) -> tuple[NDArray, NDArray]:
    """Polar angle and azimuth [rad] of directions at angle ``t`` from ``(theta, phi)``.

    The offset direction is ``cos t n + sin t (cos psi e_theta + sin psi e_phi)`` with
    ``n`` the axis and ``e_theta``, ``e_phi`` the unit tangents along increasing theta and
    phi (exact; at the pole ``e_phi`` is taken at the given ``phi``). Inputs broadcast.
    """
    st, ct = np.sin(theta), np.cos(theta)
    sp, cp = np.sin(phi), np.cos(phi)
    a, b, c = np.cos(t), np.sin(t) * np.cos(psi), np.sin(t) * np.sin(psi)
    x = a * st * cp + b * ct * cp - c * sp
    y = a * st * sp + b * ct * sp + c * cp
    z = a * ct - b * st
    return np.arctan2(np.hypot(x, y), z), np.arctan2(y, x)


class Apertured(Model):
    """``model`` averaged over the detector's cone and the beam's divergence.

    Parameters
    ----------
    model : Model
        The sample's model (any isotropic model); its parameters are this model's.
    detector_deg : float
        Half-angle of the detector's cone [deg], in [0, 20].
    beam_deg : float
        Half-angle of the beam's divergence [deg], in [0, 20].
    nodes : tuple of int
        ``(n_t, n_psi)`` of each cap's product rule (:func:`cap_nodes`); raise them when
        the sample's lobe is much narrower than the aperture.

    Notes
    -----
    Cost: ``n_t n_psi`` model evaluations per point for each cone that is not 0 (their
    product with both). The average is linear, so the wrapped model's linear parameters
    stay linear (its components are averaged the same way).
    """

    def __init__(
        self,
        model: Model,
        detector_deg: float = 0.0,
        beam_deg: float = 0.0,
        nodes: tuple[int, int] = (8, 24),
    ) -> None:
        if not isinstance(model, Model):
            raise ModelError(f"Apertured: expected a Model, got {type(model).__name__}")
        _check_can_average(model)
        for name, v in (("detector_deg", detector_deg), ("beam_deg", beam_deg)):
            if not (isinstance(v, int | float) and 0.0 <= v <= MAX_APERTURE_DEG):
                raise ModelError(
                    f"Apertured: {name}={v!r}: expected a half-angle in [0, "
                    f"{MAX_APERTURE_DEG:g}] deg"
                )
        n_t, n_psi = (int(n) for n in nodes)
        if not (1 <= n_t <= 64 and 1 <= n_psi <= 256):
            raise ModelError(f"Apertured: nodes={nodes!r}: expected 1..64 and 1..256")
        self.inner = model
        self.name = model.name
        self.reference = model.reference
        self.doi = model.doi
        self.linear = model.linear
        # a cone average of a BSDF; a specular intensity is not a BSDF value
        self.quantities = tuple(q for q in model.quantities if q in ("brdf", "btdf"))
        self.reciprocity_note = model.reciprocity_note
        self.detector_deg, self.beam_deg = float(detector_deg), float(beam_deg)
        self._det = cap_nodes(self.detector_deg, n_t, n_psi) if detector_deg > 0 else None
        self._beam = cap_nodes(self.beam_deg, n_t, n_psi) if beam_deg > 0 else None
        super().__init__(**model.options)
        self.params = model.params.copy()
        self.options = dict(model.options, detector_deg=self.detector_deg, beam_deg=self.beam_deg)

    def default_params(self) -> Parameters:
        """The wrapped model's current parameters (a copy)."""
        return self.inner.params.copy()

    def lobe_width(self, p: Mapping[str, float]) -> float:
        """The wrapped model's lobe width, widened by the aperture [rad]."""
        fn = getattr(self.inner, "lobe_width", None)
        w = float(fn(p)) if callable(fn) else 0.2
        return w + math.radians(self.detector_deg + self.beam_deg)

    def _average(self, fn: Any, ti: NDArray, tr: NDArray, pr: NDArray) -> Any:
        """sum_k w_k fn(ti_k, tr_k, pr_k) over the beam's and the detector's nodes."""
        ti, tr, pr = np.broadcast_arrays(ti, tr, pr)
        beam = self._beam if self._beam is not None else (np.zeros(1), np.zeros(1), np.ones(1))
        det = self._det if self._det is not None else (np.zeros(1), np.zeros(1), np.ones(1))
        total: Any = None
        for tb, pb, wb in zip(*beam, strict=True):
            # the source moves to (ti_b, phi_b); the model sees the detector's azimuth
            # relative to it. The source's direction is at phi = 0, its cone about it.
            ti_b, phi_b = cone_directions(ti, np.zeros_like(ti), tb, pb)
            tr_d, pr_d = cone_directions(tr[..., None], pr[..., None], det[0], det[1])
            val = fn(ti_b[..., None], tr_d, pr_d - phi_b[..., None])
            term = _weighted(val, det[2], wb)
            total = term if total is None else _add(total, term)
        return total

    def _evaluate(
        self,
        p: Mapping[str, float],
        theta_i: NDArray,
        theta_r: NDArray,
        phi_r: NDArray,
        wavelength: NDArray | None,
    ) -> NDArray:
        wl = None if wavelength is None else np.asarray(wavelength)[..., None]

        def value(a: NDArray, b: NDArray, c: NDArray) -> NDArray:
            ta, tb, tc = np.broadcast_arrays(a, b, c)
            return self.inner._evaluate(p, ta, tb, tc, wl)

        return self._average(value, theta_i, theta_r, phi_r)

    def linear_components(
        self,
        p: Mapping[str, float],
        theta_i: NDArray,
        theta_r: NDArray,
        phi_r: NDArray,
        wavelength: NDArray | None,
    ) -> dict[str, NDArray] | None:
        """The wrapped model's linear components, averaged the same way."""
        wl = None if wavelength is None else np.asarray(wavelength)[..., None]

        def comps(a: NDArray, b: NDArray, c: NDArray) -> dict[str, NDArray] | None:
            ta, tb, tc = np.broadcast_arrays(a, b, c)
            return self.inner.linear_components(p, ta, tb, tc, wl)

        one = np.zeros(1)
        if comps(one, one, one) is None:
            return None
        return self._average(comps, theta_i, theta_r, phi_r)

    def is_reciprocal(self, params: Mapping[str, float] | None = None) -> bool:
        """False: an instrument's average is not symmetric in the two directions in general."""
        return False


def _check_can_average(model: Model) -> None:
    """Refuse a model whose value cannot be averaged over the aperture's cones.

    A Monte Carlo model (its cost times the nodes, its noise fixed by a seed per point)
    and a specular-plane model (its value off the plane of incidence is not a prediction,
    and the cones leave the plane) are refused, with why.
    """
    if getattr(model, "stochastic", False):
        raise ModelError(
            f"model {model.name!r} is a Monte Carlo estimate: averaging it over the "
            "aperture's cones multiplies its rays by the number of nodes; fit it without "
            "the aperture (its bins are wider than a small aperture) or use a closed-form "
            "model"
        )
    if getattr(model, "domain", "hemisphere") != "hemisphere":
        raise ModelError(
            f"model {model.name!r} describes the plane of incidence only: the aperture's "
            "cones leave that plane; use a hemispherical model (microfacet, abg, "
            "harvey_shack, five_param)"
        )


def _weighted(val: Any, w_det: NDArray, w_beam: float) -> Any:
    """``w_beam * sum_j w_det[j] val[..., j]`` for an array or a dict of arrays."""
    if isinstance(val, dict):
        return {k: w_beam * np.asarray(v) @ w_det for k, v in val.items()}
    return w_beam * (np.asarray(val) @ w_det)


def _add(a: Any, b: Any) -> Any:
    if isinstance(a, dict):
        return {k: a[k] + b[k] for k in a}
    return a + b
