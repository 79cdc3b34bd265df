"""Microfacet BRDF with separable Smith shadowing and the exact complex Fresnel factor.

Physics layer: numpy only (the Fresnel amplitudes and the ellipsometric inversion come from
:mod:`labbrdf.optics`, D and G1 from the distribution's module in
:data:`labbrdf.microfacet.registry.DISTRIBUTIONS`).

``f = scale * F(theta_d) D(h) G1(w_i) G1(w_o) / (4 cos theta_i cos theta_r)`` [sr^-1], where
h is the half vector, theta_d the local incidence angle on the facet (cos = w_i.h), D the
distribution of normals and G1 its Smith masking function (eqs. (20), (25)-(27), (33), (34)
of [1]_). The distribution is any registered one: GGX (Trowbridge-Reitz, the default) or
Beckmann, or one added to the registry. With GGX this is the single-scattering model of
Mitsuba's ``roughconductor`` (distribution ``ggx``) and of NIST SCATMECH's
``Shadowed_Facet_BRDF_Model`` with the ellipsoid (GGX) slope distribution (oracles README
section 4).

References
----------
.. [1] Walter B., Marschner S. R., Li H., Torrance K. E., "Microfacet models for refraction
   through rough surfaces", Proc. EGSR 2007, eqs. (20), (25)-(27), (33), (34).
   doi:10.2312/EGWR/EGSR07/195-206
.. [2] Trowbridge T. S., Reitz K. P., "Average irregularity representation of a rough surface
   for ray reflection", J. Opt. Soc. Am. 65(5), 531-536 (1975). doi:10.1364/JOSA.65.000531
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..ellipsometry import nk_from_psi_delta
from ..microfacet import registry
from ..optics import fresnel_cos
from .base import Model, ModelError, Parameters, lambert

__all__ = ["Microfacet", "stokes_from_jones"]

_SHADOWING = ("smith", "none")
_OPTIONS = ["n", "k", "psi_delta", "ideal_mirror", "shadowing", "diffuse", "distribution"]
_REFERENCE = (
    "Walter B. et al., Microfacet models for refraction through rough surfaces, "
    "EGSR 2007 ({label} D, Smith G1); Fresnel amplitudes of the substrate"
)
_RECIPROCITY = (
    "microfacet is reciprocal by construction (the {label} term "
    "F D G1 G1 / (4 cos\u03b8i cos\u03b8r) and the Lambertian kd / pi are symmetric in the "
    "two directions)."
)

# coherency vector (Es Es*, Es Ep*, Ep Es*, Ep Ep*) -> Stokes (S0, S1, S2, S3), LB convention
_A = np.array([[1, 0, 0, 1], [1, 0, 0, -1], [0, 1, 1, 0], [0, 1j, -1j, 0]], dtype=complex)
_A_INV = np.linalg.inv(_A)


def stokes_from_jones(jones: NDArray) -> NDArray[np.float64]:
    """Mueller matrix (..., 4, 4) of Jones matrices (..., 2, 2) in the LB Stokes convention.

    ``S0 = |Es|^2 + |Ep|^2``, ``S1 = |Es|^2 - |Ep|^2``, ``S2 = 2 Re(Es Ep*)``,
    ``S3 = 2 Im(Es* Ep)``
    (oracles README section 2: S3 = +1 when E turns from s towards p, time factor exp(-iwt)).

    Parameters
    ----------
    jones : ndarray
        Complex Jones matrices acting on (Es, Ep).

    Returns
    -------
    ndarray
        Real Mueller matrices (..., 4, 4).
    """
    j = np.asarray(jones, dtype=complex)
    kron = (j[..., :, None, :, None] * np.conj(j)[..., None, :, None, :]).reshape(
        *j.shape[:-2], 4, 4
    )
    return np.real(_A @ kron @ _A_INV)


class Microfacet(Model):
    """Microfacet BRDF with Smith G1 G1 and the exact Fresnel factor of a substrate.

    Other Parameters
    ----------------
    n, k : float
        Complex index N = n + ik of the substrate (k >= 0), ambient index 1. Give exactly
        one of ``n, k``, ``psi_delta`` and ``ideal_mirror``.
    psi_delta : tuple of float
        ``(psi_deg, delta_deg, theta_deg)`` measured by an ellipsometer on the same sample;
        N comes from the two-phase inversion :func:`labbrdf.ellipsometry.nk_from_psi_delta`.
    ideal_mirror : bool
        F = 1 (rs = -1, rp = +1, the limit N -> i infinity).
    shadowing : {"smith", "none"}, default "smith"
        Separable Smith ``G1(w_i) G1(w_o)`` or G = 1.
    diffuse : bool, default False
        Add a Lambertian floor ``kd / pi`` [sr^-1] (unpolarized: Mueller ``kd / pi`` times
        diag(1, 0, 0, 0)), for painted, polymer or other surfaces whose subsurface scatter
        the facets do not describe.
    distribution : str, default "ggx"
        A name of :data:`labbrdf.microfacet.registry.DISTRIBUTIONS` (``"ggx"``,
        ``"beckmann"``, or one added there): its ``d`` and ``smith_g1`` give D and G1.
        Stored in :attr:`options` when it is not the default.

    Parameters: ``alpha`` [1] in [1e-3, 1.5] (log), the distribution's roughness (GGX:
    eq. (33) of Walter et al. 2007; Beckmann: eq. (25), the RMS slope of ``|grad z|``),
    ``scale`` [1] in [0, 10], fixed at 1 (free it for relative data; it enters linearly);
    with ``diffuse``, ``kd`` [1] in [0, 1], the directional-hemispherical albedo of the
    floor (linear).

    Notes
    -----
    Reciprocal for every parameter value (D, G and F(w_i.h) are symmetric). Energy is
    conserved with Smith shadowing (single scattering loses energy, up to 21 % for
    alpha = 0.4); with G = 1 the albedo exceeds 1 at grazing incidence.
    The index is taken wavelength-independent: fit one model per wavelength.
    GGX's G1 is evaluated in the form of eq. (34) of Walter et al. 2007
    (:func:`labbrdf.microfacet.ggx.smith_g1_closed`), which the oracles were checked
    against; a distribution that defines ``smith_g1_closed`` has it used the same way,
    the others their ``smith_g1 = 1 / (1 + Lambda)``.
    """

    name = "microfacet"
    reference = _REFERENCE.format(label="GGX")
    doi = "10.2312/EGWR/EGSR07/195-206"
    reciprocity_note = _RECIPROCITY.format(label="GGX")
    linear: tuple[str, ...] = ("scale",)

    def __init__(
        self,
        n: float | None = None,
        k: float | None = None,
        psi_delta: tuple[float, float, float] | None = None,
        ideal_mirror: bool = False,
        shadowing: str = "smith",
        diffuse: bool = False,
        distribution: str = "ggx",
        **options: Any,
    ) -> None:
        if options:
            raise ModelError(
                f"model 'microfacet' got unknown options {sorted(options)}; options are {_OPTIONS}"
            )
        self._set_distribution(distribution)
        self._diffuse = bool(diffuse)
        if self._diffuse:
            self.linear = ("scale", "kd")
        if shadowing not in _SHADOWING:
            raise ModelError(
                f"microfacet option 'shadowing' must be one of "
                f"{list(_SHADOWING)}; got {shadowing!r}"
            )
        given = [n is not None, psi_delta is not None, bool(ideal_mirror)]
        if sum(given) != 1:
            raise ModelError(
                "microfacet needs exactly one of n=(and k=), "
                "psi_delta=(psi_deg, delta_deg, theta_deg) or ideal_mirror=True"
            )
        if k is not None and n is None:
            raise ModelError("microfacet option 'k' needs 'n' as well")
        opts: dict[str, Any] = {"shadowing": shadowing}
        self.N: complex | None
        if n is not None:
            kk = 0.0 if k is None else k
            if not (
                np.isfinite(n) and np.isfinite(kk) and n >= 0 and kk >= 0 and (n > 0 or kk > 0)
            ):
                raise ModelError(
                    f"microfacet options n, k must be finite, >= 0 and not both "
                    f"0 (N = n + ik); got n={n!r}, k={kk!r}"
                )
            self.N = complex(n, kk)
            opts.update(n=float(n), k=float(kk))
        elif psi_delta is not None:
            try:
                psi, delta, theta = (float(x) for x in psi_delta)
            except (TypeError, ValueError):
                raise ModelError(
                    "microfacet option 'psi_delta' must be three numbers "
                    f"(psi_deg, delta_deg, theta_deg); got {psi_delta!r}"
                ) from None
            big_n = complex(nk_from_psi_delta(psi, delta, theta))
            self.N = big_n
            opts.update(psi_delta=(psi, delta, theta), n=big_n.real, k=big_n.imag)
        else:
            self.N = None
            opts.update(ideal_mirror=True)
        self._shadowing = shadowing
        if self._diffuse:
            opts["diffuse"] = True
        if self.distribution != "ggx":
            opts["distribution"] = self.distribution
        super().__init__(**opts)

    def _set_distribution(self, name: Any) -> None:
        """Take D and G1 from the registered distribution ``name``; state it in the texts."""
        try:
            dist = registry.get(name)
        except (KeyError, TypeError):
            raise ModelError(
                f"microfacet option 'distribution' must be one of {list(registry.names())}; "
                f"got {name!r}"
            ) from None
        #: the registry name (the module is looked up when used: a model is pickled by
        #: the process pools, a module cannot be)
        self.distribution: str = dist.NAME
        if dist.NAME != "ggx":
            self.reference = _REFERENCE.format(label=dist.LABEL)
            self.reciprocity_note = _RECIPROCITY.format(label=dist.LABEL)

    @property
    def _dist(self) -> Any:
        return registry.get(self.distribution)

    def _g1(self, cos_v: NDArray, alpha: float) -> NDArray:
        dist = self._dist
        return getattr(dist, "smith_g1_closed", dist.smith_g1)(cos_v, alpha)

    @property
    def label(self) -> str:
        """The model and its distribution for a reader, e.g. ``"microfacet (Beckmann)"``."""
        return f"{self.name} ({self._dist.LABEL})"

    def default_params(self) -> Parameters:
        """alpha 0.2 in [1e-3, 1.5] (log); scale 1, fixed."""
        p = Parameters()
        what = f"{self._dist.LABEL} roughness"
        p.add("alpha", 0.2, 1e-3, 1.5, units="1", log=True, description=what)
        p.add(
            "scale",
            1.0,
            0.0,
            10.0,
            vary=False,
            units="1",
            description="overall factor (relative data)",
        )
        if self._diffuse:
            p.add("kd", 0.0, 0.0, 1.0, units="1", description="Lambertian albedo")
        return p

    def lobe_width(self, p: Mapping[str, float]) -> float:
        """Angular scale of the lobe in theta_r [rad] (a quadrature hint): ``2 alpha``."""
        return 2.0 * float(p["alpha"])

    def is_reciprocal(self, params: Mapping[str, float] | None = None) -> bool:
        """Always True."""
        return True

    # ------------------------------------------------------------------ internals
    def _amplitudes(self, cos_d: NDArray) -> tuple[NDArray, NDArray]:
        if self.N is None:
            return -np.ones_like(cos_d, dtype=complex), np.ones_like(cos_d, dtype=complex)
        rs, rp = fresnel_cos(1.0, self.N, cos_d)[:2]
        return np.asarray(rs, dtype=complex), np.asarray(rp, dtype=complex)

    def _geometry(
        self, ti: NDArray, tr: NDArray, pr: NDArray
    ) -> tuple[NDArray, NDArray, NDArray, NDArray, NDArray]:
        wi = np.stack(np.broadcast_arrays(np.sin(ti), 0.0 * ti, np.cos(ti)), axis=-1)
        wo = np.stack([np.sin(tr) * np.cos(pr), np.sin(tr) * np.sin(pr), np.cos(tr)], axis=-1)
        hv = wi + wo
        norm = np.linalg.norm(hv, axis=-1, keepdims=True)
        with np.errstate(divide="ignore", invalid="ignore"):
            h = np.where(norm > 0, hv / norm, np.array([0.0, 0.0, 1.0]))
        cos_d = np.clip(np.sum(wi * h, axis=-1), 0.0, 1.0)
        return wi, wo, h, cos_d, h[..., 2]

    def _scalar_factor(
        self, p: Mapping[str, float], ti: NDArray, tr: NDArray, cos_h: NDArray
    ) -> NDArray:
        alpha = p["alpha"]
        if not alpha > 0:
            raise ModelError(f"microfacet parameter 'alpha' must be > 0; got {alpha!r}")
        ci, co = np.cos(ti), np.cos(tr)
        up = (ci > 0) & (co > 0)
        d = self._dist.d(cos_h, alpha)
        g = (
            self._g1(ci, alpha) * self._g1(co, alpha)
            if self._shadowing == "smith"
            else np.ones_like(d)
        )
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(up, p["scale"] * d * g / (4.0 * ci * co), 0.0)

    def _evaluate(
        self,
        p: Mapping[str, float],
        theta_i: NDArray,
        theta_r: NDArray,
        phi_r: NDArray,
        wavelength: NDArray | None,
    ) -> NDArray:
        _, _, _, cos_d, cos_h = self._geometry(theta_i, theta_r, phi_r)
        rs, rp = self._amplitudes(cos_d)
        fres = 0.5 * (np.abs(rs) ** 2 + np.abs(rp) ** 2)
        out = self._scalar_factor(p, theta_i, theta_r, cos_h) * fres
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
        """``{"scale": specular part / scale}`` (and ``"kd": 1 / pi`` with ``diffuse``)."""
        q = dict(p, scale=1.0)
        if not self._diffuse:
            return {"scale": self._evaluate(q, theta_i, theta_r, phi_r, wavelength)}
        q["kd"] = 0.0
        return {
            "scale": self._evaluate(q, theta_i, theta_r, phi_r, wavelength),
            "kd": np.broadcast_to(lambert(theta_i, theta_r), np.shape(theta_r)).copy(),
        }

    # ------------------------------------------------------------------ polarization
    def mueller(
        self,
        theta_i: ArrayLike,
        theta_r: ArrayLike,
        phi_r: ArrayLike = np.pi,
        params: Mapping[str, float] | Parameters | None = None,
    ) -> NDArray[np.float64]:
        """Mueller BRDF (..., 4, 4) [sr^-1] in the LB convention of oracles README section 2.

        Frames: for each ray ``s = phi_hat(phi) = (-sin phi, cos phi, 0)`` with phi the ray's
        azimuth (0 for the incident ray, ``phi_r`` for the exit ray, also at theta = 0) and
        ``p = k x s``. The facet's Jones matrix ``diag(rs, rp)`` acts in the facet frame
        ``s_f = k_in x h / |k_in x h|``, ``p = k x s_f``, and is carried into the ray frames
        by the projections of the basis vectors; the Mueller matrix follows from the Jones
        matrix (:func:`stokes_from_jones`). Element [0, 0] equals :meth:`evaluate`.

        Parameters
        ----------
        theta_i, theta_r, phi_r : array_like
            Incidence, detector polar angle and detector outward azimuth [rad].
        params : mapping or Parameters or None
            Parameter overrides.

        Returns
        -------
        ndarray
            f_M [sr^-1], shape ``broadcast(theta_i, theta_r, phi_r) + (4, 4)``.
        """
        p = self.values(params)
        ti, tr, pr = np.broadcast_arrays(
            np.asarray(theta_i, float), np.asarray(theta_r, float), np.asarray(phi_r, float)
        )
        wi, wo, h, cos_d, cos_h = self._geometry(ti, tr, pr)
        k_in, k_out = -wi, wo
        zero = np.zeros_like(pr)
        s_in = np.broadcast_to(np.array([0.0, 1.0, 0.0]), wi.shape)
        s_out = np.stack([-np.sin(pr), np.cos(pr), zero], axis=-1)
        p_in, p_out = np.cross(k_in, s_in), np.cross(k_out, s_out)
        sf = np.cross(k_in, h)
        nf = np.linalg.norm(sf, axis=-1, keepdims=True)
        with np.errstate(divide="ignore", invalid="ignore"):
            sf = np.where(nf > 1e-12, sf / nf, s_in)  # normal facet incidence: any s works
        pf_in, pf_out = np.cross(k_in, sf), np.cross(k_out, sf)

        def dot(a: NDArray, b: NDArray) -> NDArray:
            return np.sum(a * b, axis=-1)

        b_in = np.stack(
            [
                np.stack([dot(sf, s_in), dot(sf, p_in)], -1),
                np.stack([dot(pf_in, s_in), dot(pf_in, p_in)], -1),
            ],
            -2,
        )
        b_out = np.stack(
            [
                np.stack([dot(s_out, sf), dot(s_out, pf_out)], -1),
                np.stack([dot(p_out, sf), dot(p_out, pf_out)], -1),
            ],
            -2,
        )
        rs, rp = self._amplitudes(cos_d)
        jf = np.zeros((*rs.shape, 2, 2), dtype=complex)
        jf[..., 0, 0], jf[..., 1, 1] = rs, rp
        m = stokes_from_jones(b_out @ jf @ b_in)
        out = self._scalar_factor(p, ti, tr, cos_h)[..., None, None] * m
        if self._diffuse:
            out[..., 0, 0] += p["kd"] * lambert(ti, tr)
        return out
