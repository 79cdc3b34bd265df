"""The constants of one tracer run that the walk and the evaluated estimator share.

:class:`WalkSetup` holds what a :class:`~labbrdf.tracer.config.TraceConfig` means for the
walk: the kind of run (single or multiple scattering, layered, coherent, evaluated), the
indices, and one microfacet distribution object per interface
(:mod:`labbrdf.microfacet.interface`): ``top`` (the coating's air/coating interface, None
without an incoherent coating) and ``sub`` (the substrate, or the coherent film's facets).
The walk asks the interface a ray is on for its Smith Lambda and G1 and for visible
normals (:meth:`WalkSetup.lambda_of`, :meth:`WalkSetup.g1_of`, :meth:`WalkSetup.sample`),
and the Fresnel numbers of its facet events (:meth:`WalkSetup.substrate_abcs`,
:meth:`WalkSetup.layered_abcs`).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from ..microfacet.interface import ClosedForm, Table, facets
from .binning import Grid
from .config import TraceConfig
from .exit_sampled import exit_is_sampled
from .interfaces import fresnel_abcs

__all__ = ["WalkSetup", "grid_of", "scalar_abcs"]

F64 = NDArray[np.float64]


def grid_of(cfg: TraceConfig) -> Grid:
    """The output grid of a run."""
    return Grid(cfg.theta_step_deg, cfg.phi_step_deg)


class WalkSetup:
    """Per-run constants derived from the config (module docstring)."""

    def __init__(self, cfg: TraceConfig) -> None:
        sub, coat = cfg.substrate, cfg.coating
        self.single = cfg.scattering == "single"
        self.layered = coat is not None and not cfg.coherent
        self.coherent = bool(cfg.coherent)
        self.mirror = sub.mirror
        self.n_sub = complex(sub.n, sub.k)
        self.alpha_sub = coat.alpha if (coat is not None and cfg.coherent) else sub.alpha
        self.alpha_top = coat.alpha if coat is not None else 0.0
        self.n_coat = coat.n if coat is not None else 1.0
        self.k_coat = coat.k if coat is not None else 0.0
        self.d = coat.thickness_nm if coat is not None else 0.0
        self.lam = cfg.wavelength_nm
        self.coat = coat
        self.n_above_sub = self.n_coat if self.layered else 1.0
        # one distribution per interface: the coherent facets are GGX with the coating's
        # alpha; the top is seen from above (from below: its mirror image)
        self.sub: ClosedForm | Table = facets(self.alpha_sub, None if cfg.coherent else sub.ndf)
        self.top: ClosedForm | Table | None = (
            facets(self.alpha_top, coat.ndf) if (coat is not None and self.layered) else None
        )
        self.evaluated = cfg.resolved_estimator == "evaluated"
        # evaluated multiple scattering under a coating (walk._escape_air): the random
        # walk, with the escapes into the air booked and the single events evaluated
        self.ms_evaluated = self.evaluated and self.layered and not self.single
        # the evaluated walk's deposits, per batch and bin: the exit operator's cells, the
        # exits binned, then (multiple scattering through the operator) the later
        # vertices' levels of cells from below and from above (:mod:`.height_basis`)
        self.channels = 2
        self.grid = grid_of(cfg)
        self.batches = cfg.batches
        # evaluated, with a nearly smooth top, or one the GGX exit operator does not
        # describe (a slope table): the exit is the walk's own facet (exit_sampled)
        self.sampled_exit = (
            self.evaluated
            and self.top is not None
            and (
                not self.top.ggx_closed_form
                or exit_is_sampled(grid_of(cfg), self.n_coat, self.alpha_top)
            )
        )
        if self.ms_evaluated and not self.sampled_exit:
            from .height_basis import LEVELS

            self.channels = 2 + 3 * LEVELS
        self.scalar = bool(cfg.scalar)
        # Lambertian base instead of the conductor's microsurface (None: the conductor)
        self.albedo = sub.albedo
        # a scattering coating (labbrdf.tracer.medium) and the absorption optical
        # thickness of the coating's k along the normal, 4 pi k d / lambda
        self.medium = coat.medium if (coat is not None and self.layered) else None
        self.a_abs = 4 * np.pi * self.k_coat * self.d / self.lam

    # -- the interfaces ---------------------------------------------------------------
    def _each(
        self, on_sub: NDArray[np.bool_], f: Callable[[ClosedForm | Table, NDArray | slice], F64]
    ) -> F64:
        """``f(interface, rays)`` for the rays on each interface, substrate first.

        An interface that holds every ray gets the whole arrays (``slice(None)``).
        """
        out: F64 | None = None
        for face, sel in ((self.sub, on_sub), (self.top, ~on_sub)):
            if face is None or not sel.any():
                continue
            if sel.all():
                return f(face, slice(None))
            if out is None:
                out = np.empty(sel.size)
            out[sel] = f(face, sel)
        if out is None:
            return np.empty(on_sub.size)
        return out

    def lambda_of(
        self, k: F64, on_sub: NDArray[np.bool_], below: NDArray[np.bool_] | None = None
    ) -> F64:
        """Smith Lambda of the travel directions ``k`` on each ray's interface."""
        return self._each(
            on_sub, lambda f, s: f.smith_lambda(k[:, s], None if below is None else below[s])
        )

    def g1_of(
        self, k: F64, on_sub: NDArray[np.bool_], below: NDArray[np.bool_] | None = None
    ) -> F64:
        """Smith G1 of the travel directions ``k`` on each ray's interface."""
        return self._each(
            on_sub, lambda f, s: f.smith_g1(k[:, s], None if below is None else below[s])
        )

    def sample(
        self,
        k: F64,
        on_sub: NDArray[np.bool_],
        below: NDArray[np.bool_],
        u: F64,
        rng: np.random.Generator,
    ) -> F64:
        """Visible normals (3, n) of the rays' interfaces (``u``: uniforms (2, n))."""
        m = np.empty_like(k)
        for face, sel in ((self.sub, on_sub), (self.top, ~on_sub)):
            if face is None or not sel.any():
                continue
            s: NDArray | slice = slice(None) if sel.all() else sel
            m[:, s] = face.sample_visible(k[:, s], below[s], u[0][s], u[1][s], rng)
        return m

    # -- Fresnel numbers --------------------------------------------------------------
    def beer_lambert(self, kz: F64) -> F64 | None:
        """The coating's attenuation along directions of z component ``kz`` (None: none)."""
        if self.k_coat == 0 or self.d == 0:
            return None
        return np.exp(-4 * np.pi * self.k_coat * self.d / (self.lam * np.abs(kz)))

    def substrate_abcs(self, cos_i: F64) -> tuple[F64, F64, F64, NDArray]:
        """Reflection numbers (A, B, C, S) of the substrate's facets (or the film's)."""
        out = self._substrate_abcs(cos_i)
        return scalar_abcs(out) if self.scalar else out

    def _substrate_abcs(self, cos_i: F64) -> tuple[F64, F64, F64, NDArray]:
        if self.coherent:
            from ..films.onefilm import film_amplitudes

            theta = np.degrees(np.arccos(np.clip(cos_i, 0.0, 1.0)))
            coat = self.coat
            assert coat is not None  # TraceConfig refuses coherent=True without a coating
            rs, rp = film_amplitudes(
                1.0, complex(coat.n, coat.k), self.n_sub, coat.thickness_nm, self.lam, theta
            )
            rs2 = np.abs(rs) ** 2
            rp2 = np.abs(rp) ** 2
            x = rs * np.conj(rp)
            return 0.5 * (rs2 + rp2), 0.5 * (rs2 - rp2), x.real, x.imag
        refl, _, _ = fresnel_abcs(self.n_above_sub, self.n_sub, cos_i, mirror=self.mirror)
        return refl

    def layered_abcs(
        self, cos_i: F64, on_top: NDArray[np.bool_], below: NDArray[np.bool_]
    ) -> tuple[tuple, tuple, F64, F64]:
        """Reflection/transmission numbers for a mix of top-interface and substrate rays."""
        refl, tr, cos_t, eta = self._layered_abcs(cos_i, on_top, below)
        if self.scalar:
            refl, tr = scalar_abcs(refl), scalar_abcs(tr)
        return refl, tr, cos_t, eta

    def _layered_abcs(
        self, cos_i: F64, on_top: NDArray[np.bool_], below: NDArray[np.bool_]
    ) -> tuple[tuple, tuple, F64, F64]:
        nc = self.n_coat
        n1 = np.where(on_top & below, nc, np.where(on_top, 1.0, nc)).astype(np.complex128)
        n2 = np.where(on_top, np.where(below, 1.0, nc), 0.0).astype(np.complex128)
        if not self.mirror:
            n2 = np.where(on_top, n2, self.n_sub)
        else:
            n2 = np.where(on_top, n2, 1.0 + 0.0j)  # placeholder, overridden below
        refl, tr, cos_t = fresnel_abcs(n1, n2, cos_i, opaque=~on_top)
        if self.mirror:
            sub = ~on_top
            refl = (
                np.where(sub, 1.0, refl[0]),
                np.where(sub, 0.0, refl[1]),
                np.where(sub, -1.0, refl[2]),
                np.where(sub, 0.0, refl[3]),
            )
        eta = np.where(on_top, n1.real / np.where(on_top, n2.real, 1.0), 1.0)
        return refl, tr, cos_t, eta


def scalar_abcs(abcs: tuple) -> tuple:
    """Scalar mode: the unpolarized reflectance A alone, B = C = S = 0.

    With the rows 1-3 of M zeroed after each vertex the ray then carries only S0, weighted
    by ``(|r_s|^2 + |r_p|^2) / 2`` (or the transmittance) at every vertex, which is what
    a scalar (unpolarized) code computes.
    """
    z = np.zeros_like(abcs[0])
    return abcs[0], z, z, z
