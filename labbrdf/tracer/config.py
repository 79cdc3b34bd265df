"""Configuration of a tracer run: a frozen, JSON-able dataclass."""

from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass, field, replace
from typing import Any

import numpy as np

from labbrdf.microfacet import TabulatedNDF

from .medium import Medium

__all__ = ["Coating", "Substrate", "TraceConfig"]

SCATTERING = ("single", "multiple")
TERMINATION = ("threshold", "roulette")
ESTIMATORS = ("auto", "evaluated", "counting")
# each batch holds (n_bins x 16) float64 sums: 4.2 MB on the 1-degree grid
MAX_BATCHES = 64
#: the most rays of one run: a run keeps per-block sums (16 floats per ``block_rays``
#: rays), so memory stays small below it, and at about 1e6 rays/s it is already hours
MAX_RAYS = 1_000_000_000


def _check(cond: bool, name: str, expected: str, value: Any) -> None:
    if not cond:
        raise ValueError(f"{name} must be {expected}, got {value!r}")


def _finite(x: Any) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


@dataclass(frozen=True)
class Substrate:
    """Opaque substrate: a rough conductor (N = n + ik, GGX or tabulated NDF) or a diffuse base.

    Two kinds (:attr:`kind`): ``"conductor"`` (the default; ``"mirror"`` with
    ``mirror=True``), whose facets reflect with the Fresnel matrix of ``n + ik``, and
    ``"lambertian"`` (``albedo`` given, see :meth:`lambertian`): a flat, depolarizing,
    diffusely reflecting base, as under a paint's or a plastic's clear layer.

    Parameters
    ----------
    n, k : float
        Real and imaginary parts of the index [1], k >= 0.
    alpha : float
        GGX roughness [1] (0 = smooth). Not used by the tracer when ``ndf`` is given
        (:meth:`from_surface` stores the maximum-likelihood GGX alpha there, for reference).
    mirror : bool
        Ideal mirror (|r_s| = |r_p| = 1, the perfect-conductor limit r_s = -1, r_p = +1);
        n and k are then ignored. For the white-furnace test.
    ndf : TabulatedNDF or None
        Tabulated slope distribution replacing GGX on the substrate (its D, Smith Lambda
        and visible-normal sampling); None = GGX with ``alpha`` (the original path, bit for
        bit). Not combinable with ``TraceConfig(coherent=True)``.
    albedo : float or None
        Lambertian base of this albedo [1], in [0, 1]; None = the conductor. A ray reaching
        the base leaves it with its Mueller matrix multiplied by ``albedo * diag(1, 0, 0,
        0)`` in a cosine-distributed direction (``docs/tracer.md``); ``n``, ``k`` and
        ``alpha`` are then unused (``alpha`` = 0, ``n``, ``k`` at their defaults), and
        ``mirror``, ``ndf`` and ``TraceConfig(coherent=True)`` are refused.
    """

    n: float = 1.55
    k: float = 7.71
    alpha: float = 0.2
    mirror: bool = False
    ndf: TabulatedNDF | None = None
    albedo: float | None = None

    @classmethod
    def lambertian(cls, albedo: float) -> Substrate:
        """A Lambertian (diffuse, depolarizing) base of albedo ``albedo`` [1] in [0, 1].

        Bare (no coating) its BRDF is ``albedo / pi`` [sr^-1] in every direction.
        """
        return cls(alpha=0.0, albedo=albedo)

    @property
    def kind(self) -> str:
        """``"lambertian"``, ``"mirror"`` or ``"conductor"``."""
        if self.albedo is not None:
            return "lambertian"
        return "mirror" if self.mirror else "conductor"

    def describe(self) -> str:
        """One line for people: the kind and its parameters."""
        if self.albedo is not None:
            return f"Lambertian base, albedo {self.albedo:g}"
        if self.mirror:
            return f"ideal mirror, alpha {self.alpha:g}"
        table = ", slope table" if self.ndf is not None else ""
        return f"N = {self.n:g}+{self.k:g}i, alpha {self.alpha:g}{table}"

    @classmethod
    def from_surface(
        cls,
        heights: Any,
        pixel_size: float | tuple[float, float] | None = None,
        *,
        degree: int = 1,
        bins: int = 64,
        **kw: Any,
    ) -> Substrate:
        """Substrate whose facets follow the slope distribution of a height map.

        Parameters
        ----------
        heights : ndarray (M, N) or labbrdf.roughness.synthetic.Surface
            Heights [m] (NaN = missing) or a generated surface (its spacing is used).
        pixel_size : float or (float, float)
            Grid spacing [m] (not needed for a Surface).
        degree : int
            Levelling polynomial (1 = mean plane), see :func:`labbrdf.roughness.topography.level`.
        bins : int
            Slope cells per axis of the table (:meth:`TabulatedNDF.from_slopes`).
        **kw
            ``n``, ``k``, ``mirror``.

        Returns
        -------
        Substrate
            ``ndf`` = the table; ``alpha`` = the ML GGX alpha of the same slopes.
        """
        from labbrdf.roughness.topography import fit_slope_distribution, level, slopes

        if hasattr(heights, "z") and hasattr(heights, "spacing"):
            pixel_size = heights.spacing
            heights = heights.z
        if pixel_size is None:
            raise ValueError("pixel_size is needed for a plain height array")
        z = level(heights, degree)
        if z.ndim != 2:
            raise ValueError("from_surface needs an areal height map (2-D), got a profile")
        px = tuple(float(v) for v in np.broadcast_to(np.asarray(pixel_size, float), (2,)))
        sx, sy = slopes(z, px)
        if sy is None:
            raise ValueError("a slope table needs an areal height map (2-D), got a profile")
        table = TabulatedNDF.from_slopes(sx, sy, bins=bins)
        alpha = min(fit_slope_distribution(sx, sy).ggx.alpha, 10.0)
        return cls(alpha=alpha, ndf=table, **kw)

    def to_dict(self) -> dict[str, Any]:
        """JSON-safe dict (the table, if any, as :meth:`TabulatedNDF.to_dict`)."""
        return {
            "n": self.n,
            "k": self.k,
            "alpha": self.alpha,
            "mirror": self.mirror,
            "ndf": None if self.ndf is None else self.ndf.to_dict(),
            "albedo": self.albedo,
        }

    def __post_init__(self) -> None:
        if isinstance(self.ndf, dict):
            object.__setattr__(self, "ndf", TabulatedNDF.from_dict(self.ndf))
        if self.albedo is not None:
            self._check_base()
        _check(
            self.ndf is None or isinstance(self.ndf, TabulatedNDF),
            "substrate.ndf",
            "a TabulatedNDF or None",
            type(self.ndf).__name__,
        )
        _check(_finite(self.n) and self.n >= 0, "substrate.n", "a finite number >= 0", self.n)
        _check(_finite(self.k) and self.k >= 0, "substrate.k", "a finite number >= 0", self.k)
        _check(
            _finite(self.alpha) and 0 <= self.alpha <= 10,
            "substrate.alpha",
            "in [0, 10]",
            self.alpha,
        )
        _check(
            self.mirror or self.albedo is not None or complex(self.n, self.k) != 0,
            "substrate n + ik",
            "non-zero (or mirror=True)",
            (self.n, self.k),
        )

    def _check_base(self) -> None:
        """Validation of the Lambertian kind (its own fields and what it excludes)."""
        _check(
            _finite(self.albedo) and 0 <= self.albedo <= 1,  # type: ignore[operator]
            "substrate.albedo",
            "a finite number in [0, 1] (or None for the conductor)",
            self.albedo,
        )
        _check(
            not self.mirror,
            "substrate.mirror",
            "False with a Lambertian base (albedo given)",
            self.mirror,
        )
        _check(
            self.ndf is None,
            "substrate.ndf",
            "None with a Lambertian base (albedo given: the base is flat)",
            type(self.ndf).__name__,
        )


@dataclass(frozen=True)
class Coating:
    """A dielectric coating (varnish) over the substrate.

    Parameters
    ----------
    n : float
        Real index of the coating [1], > 0.
    k : float
        Extinction coefficient [1] >= 0; enters only through Beer-Lambert absorption,
        attenuation coefficient 4 pi k / lambda per unit path length.
    thickness_nm : float
        Physical thickness [nm] >= 0.
    alpha : float
        GGX roughness of the top (air/coating) interface [1] (kept for reference when
        ``ndf`` is given).
    ndf : TabulatedNDF or None
        Tabulated slope distribution of the top interface (a measured table, or
        :meth:`TabulatedNDF.beckmann` / :meth:`TabulatedNDF.ggx`), seen from above; seen
        from below the walk uses its mirror image (the point reflection of the slopes).
        None = GGX with ``alpha``. The exit operator of the evaluated estimator is built
        for GGX, so with a table on the coating the evaluated walk exits through the
        facets it samples (:mod:`labbrdf.tracer.exit_sampled`).
    medium : Medium or None
        A homogeneous Henyey-Greenstein medium filling the coating (optical thickness,
        single-scattering albedo, asymmetry; :mod:`labbrdf.tracer.medium`); its rays are
        followed through it at every crossing. None = a clear coating (the walk as
        without the field, bit for bit). Not combinable with ``coherent=True``.
    """

    n: float = 1.5
    k: float = 0.0
    thickness_nm: float = 162.5
    alpha: float = 0.2
    ndf: TabulatedNDF | None = None
    medium: Medium | None = None

    @classmethod
    def from_surface(
        cls, heights: Any, pixel_size: Any = None, *, bins: int = 64, **kw: Any
    ) -> Coating:
        """Coating whose top interface follows the slopes of a measured height map.

        As :meth:`Substrate.from_surface` (levelled, table of ``bins`` cells per axis);
        ``alpha`` = the ML GGX alpha of the same slopes; ``**kw``: n, k, thickness_nm.
        """
        sub = Substrate.from_surface(heights, pixel_size, bins=bins)
        return cls(alpha=sub.alpha, ndf=sub.ndf, **kw)

    def to_dict(self) -> dict[str, Any]:
        """JSON-safe dict (the table, if any, as :meth:`TabulatedNDF.to_dict`)."""
        return {
            "n": self.n,
            "k": self.k,
            "thickness_nm": self.thickness_nm,
            "alpha": self.alpha,
            "ndf": None if self.ndf is None else self.ndf.to_dict(),
            # a clear coating's dict (and so its JSON) is the same as before the field
            **({} if self.medium is None else {"medium": self.medium.to_dict()}),
        }

    def __post_init__(self) -> None:
        if isinstance(self.ndf, dict):
            object.__setattr__(self, "ndf", TabulatedNDF.from_dict(self.ndf))
        if isinstance(self.medium, dict):
            extra = sorted(set(self.medium) - {"tau", "ssa", "g"})
            _check(not extra, "coating.medium", "a dict of tau, ssa and g", extra)
            object.__setattr__(self, "medium", Medium(**self.medium))
        _check(
            self.medium is None or isinstance(self.medium, Medium),
            "coating.medium",
            "a Medium or None",
            type(self.medium).__name__,
        )
        _check(
            self.ndf is None or isinstance(self.ndf, TabulatedNDF),
            "coating.ndf",
            "a TabulatedNDF or None",
            type(self.ndf).__name__,
        )
        _check(_finite(self.n) and self.n > 0, "coating.n", "a finite number > 0", self.n)
        _check(_finite(self.k) and self.k >= 0, "coating.k", "a finite number >= 0", self.k)
        _check(
            _finite(self.thickness_nm) and self.thickness_nm >= 0,
            "coating.thickness_nm",
            "a finite number >= 0",
            self.thickness_nm,
        )
        _check(
            _finite(self.alpha) and 0 <= self.alpha <= 10,
            "coating.alpha",
            "in [0, 10]",
            self.alpha,
        )


@dataclass(frozen=True)
class TraceConfig:
    """Everything that defines a tracer run (and hence its result, bit for bit).

    Parameters
    ----------
    wavelength_nm : float
        Vacuum wavelength [nm].
    theta_i_deg : float
        Polar angle of the source direction [deg], in [0, 90); the source azimuth is 0.
    substrate : Substrate
        The opaque substrate.
    coating : Coating or None
        Optional dielectric coating on top of the substrate.
    rays : int
        Number of rays.
    seed : int
        Seed; block b uses ``numpy.random.SeedSequence([seed, b])``.
    scattering : {"multiple", "single"}
        ``"multiple"``: random walk on each microsurface (Heitz et al. 2016), energy
        conserving. ``"single"``: one facet event per interface with separable Smith masking
        G1(w_i) G1(w_o) (the oracles' model); masked weight is terminated.
    termination : {"threshold", "roulette"}
        Rays whose intensity (unpolarized input) falls below ``tau`` are dropped
        (the paper's threshold) or play Russian roulette (unbiased).
    tau : float
        Weight threshold [1].
    max_bounces : int
        Maximum number of facet events per ray; the rest is terminated.
    theta_step_deg, phi_step_deg : float
        Grid steps [deg]; must divide 90 and 360. The default 1-degree grid has the paper's
        91 x 360 bins.
    coherent : bool
        Replace coating + substrate by one rough interface whose facets reflect with the
        coherent thin-film (Airy) amplitudes of a conformal film (needs a coating, and
        not an ideal mirror); the facets use the coating's alpha.
    block_rays : int
        Rays per random-number block (part of the definition of the random streams).
    estimator : {"auto", "evaluated", "counting"}
        How the map is estimated (``docs/tracer.md``). ``"counting"``: exiting rays are
        counted into bins (the paper's estimator). ``"evaluated"`` (single scattering
        with a rough first interface, or, when asked for, multiple scattering under an
        incoherent coating with a rough GGX top, :attr:`evaluated_multiple_applies`): the
        first interface's
        reflection is evaluated
        in closed form at every bin, the walk below it follows reflection and refraction
        with their Mueller weights instead of a random choice, and the exit through a
        rough top interface is applied as an operator on the up-going internal
        directions. ``"auto"``: evaluated wherever it applies, else counting.
    scalar : bool
        Scalar mode: the unpolarized Fresnel reflectance/transmittance ``(Rs + Rp) / 2``
        at every vertex and no polarization carried between vertices (what scalar codes
        such as pbrt-v4 or layerlab compute); only the M00 element is non-zero.
    batches : int
        Independent batches (ray index modulo ``batches``) of the evaluated estimator,
        for its standard errors; part of the definition of its floating-point sums.
    fold_blocks : int
        Consecutive blocks that a worker adds up (in block order) before returning one
        tally; the driver then adds these group tallies in group order. Part of the
        definition of the floating-point sum, so the result depends on it (in the last
        bits) but never on the scheduler, the worker count or the work-unit size. Larger
        groups send fewer 8.6 MB tallies between processes.
    """

    wavelength_nm: float = 650.0
    theta_i_deg: float = 45.0
    substrate: Substrate = field(default_factory=Substrate)
    coating: Coating | None = None
    rays: int = 200_000
    seed: int = 0
    scattering: str = "multiple"
    termination: str = "threshold"
    tau: float = 1e-4
    max_bounces: int = 100
    theta_step_deg: float = 1.0
    phi_step_deg: float = 1.0
    coherent: bool = False
    block_rays: int = 32768
    fold_blocks: int = 4
    estimator: str = "auto"
    batches: int = 8
    scalar: bool = False

    def __post_init__(self) -> None:
        if isinstance(self.substrate, dict):
            object.__setattr__(self, "substrate", Substrate(**self.substrate))
        if isinstance(self.coating, dict):
            object.__setattr__(self, "coating", Coating(**self.coating))
        _check(isinstance(self.substrate, Substrate), "substrate", "a Substrate", self.substrate)
        _check(
            self.coating is None or isinstance(self.coating, Coating),
            "coating",
            "a Coating or None",
            self.coating,
        )
        _check(
            _finite(self.wavelength_nm) and self.wavelength_nm > 0,
            "wavelength_nm",
            "a finite number > 0",
            self.wavelength_nm,
        )
        _check(
            _finite(self.theta_i_deg) and 0 <= self.theta_i_deg < 90,
            "theta_i_deg",
            "in [0, 90)",
            self.theta_i_deg,
        )
        _check(
            isinstance(self.rays, int)
            and not isinstance(self.rays, bool)
            and 0 < self.rays <= MAX_RAYS,
            "rays",
            f"a positive integer at most {MAX_RAYS:.0e}",
            self.rays,
        )
        _check(
            isinstance(self.seed, int) and not isinstance(self.seed, bool) and self.seed >= 0,
            "seed",
            "a non-negative integer",
            self.seed,
        )
        _check(
            self.scattering in SCATTERING, "scattering", f"one of {SCATTERING}", self.scattering
        )
        _check(
            self.termination in TERMINATION,
            "termination",
            f"one of {TERMINATION}",
            self.termination,
        )
        _check(_finite(self.tau) and 0 <= self.tau < 1, "tau", "in [0, 1)", self.tau)
        _check(
            isinstance(self.max_bounces, int) and self.max_bounces >= 1,
            "max_bounces",
            "an integer >= 1",
            self.max_bounces,
        )
        for name, full in (("theta_step_deg", 90.0), ("phi_step_deg", 360.0)):
            step = getattr(self, name)
            ok = _finite(step) and step > 0 and abs(full / step - round(full / step)) < 1e-9
            _check(ok, name, f"a positive divisor of {full:g}", step)
        _check(
            isinstance(self.block_rays, int) and self.block_rays >= 1,
            "block_rays",
            "an integer >= 1",
            self.block_rays,
        )
        _check(
            isinstance(self.fold_blocks, int) and self.fold_blocks >= 1,
            "fold_blocks",
            "an integer >= 1",
            self.fold_blocks,
        )
        _check(self.estimator in ESTIMATORS, "estimator", f"one of {ESTIMATORS}", self.estimator)
        _check(isinstance(self.scalar, bool), "scalar", "True or False", self.scalar)
        _check(
            isinstance(self.batches, int)
            and not isinstance(self.batches, bool)
            and 2 <= self.batches <= MAX_BATCHES,
            "batches",
            f"an integer in [2, {MAX_BATCHES}] (each batch keeps a map of all bins)",
            self.batches,
        )
        _check(
            self.estimator != "evaluated" or self.evaluated_applies,
            "estimator",
            "'counting' or 'auto' here: 'evaluated' needs scattering='single' and a rough "
            "first interface (alpha > 0), or a bare Lambertian base; with "
            "scattering='multiple' an incoherent coating with a rough GGX top (alpha > 0, "
            "no slope table): a bare substrate's or a coherent film's walk is counted",
            self.estimator,
        )
        # the incoherent walk treats the coating as a separate rough layer between two
        # interfaces, which never reduces to the bare substrate; a 0 nm layer is no layer
        _check(
            self.coherent or self.coating is None or self.coating.thickness_nm > 0,
            "coating.thickness_nm",
            "> 0 in the incoherent model (a 0 nm coating is the bare substrate: leave the "
            "coating out, or pass coherent=True, where a 0 nm film is exactly the bare "
            "substrate)",
            None if self.coating is None else self.coating.thickness_nm,
        )
        if self.coherent:
            self._check_coherent()

    def _check_coherent(self) -> None:
        """What ``coherent=True`` needs: a coating on a conductor's GGX facets."""
        _check(self.coating is not None, "coherent", "False when there is no coating", True)
        why = (
            (self.substrate.albedo is not None, "a Lambertian base (it has no film amplitudes)"),
            (
                self.substrate.ndf is not None,
                "a tabulated substrate NDF (the coherent facets use the coating's alpha)",
            ),
            (
                self.coating is not None and self.coating.ndf is not None,
                "a tabulated coating NDF (the coherent facets are GGX)",
            ),
            (self.substrate.mirror, "an ideal-mirror substrate (the film needs n + ik)"),
            (
                self.coating is not None and self.coating.medium is not None,
                "a scattering coating (the film's amplitudes are coherent)",
            ),
        )
        for bad, what in why:
            _check(not bad, "coherent", f"False with {what}", True)

    @property
    def evaluated_applies(self) -> bool:
        """Whether ``estimator="evaluated"`` covers this run.

        Single scattering: a rough first interface (the coating's top, or the substrate,
        or the coherent facets), whose reflection has a closed form (GGX, or a slope
        table's). Multiple scattering: :attr:`evaluated_multiple_applies`. A bare
        Lambertian base is its own closed form (``albedo / pi``) in either scattering mode.
        """
        if self.coating is None and self.substrate.albedo is not None:
            return True
        if self.scattering != "single":
            return self.evaluated_multiple_applies
        if self.coating is not None:
            return self.coating.alpha > 0
        return self.substrate.ndf is not None or self.substrate.alpha > 0

    @property
    def evaluated_multiple_applies(self) -> bool:
        """Whether the evaluated estimator covers this multiple-scattering run.

        An incoherent coating with a rough GGX top (its single events have closed forms
        with the height-correlated masking; ``docs/tracer.md``), over any base. A bare
        substrate and the coherent film keep counting.
        """
        c = self.coating
        return c is not None and not self.coherent and c.alpha > 0 and c.ndf is None

    @property
    def resolved_estimator(self) -> str:
        """``"evaluated"`` or ``"counting"`` (``"auto"`` resolved).

        ``"auto"`` keeps counting for multiple scattering under a coating: its evaluated
        estimator builds four operators per coating (768 MB and tens of seconds on the
        1-degree grid when not cached), dearer than a short counting run; ask for it with
        ``estimator="evaluated"`` (``docs/tracer.md``).
        """
        if self.estimator == "auto":
            coated_multiple = self.scattering != "single" and self.coating is not None
            return "evaluated" if self.evaluated_applies and not coated_multiple else "counting"
        return self.estimator

    @property
    def n_blocks(self) -> int:
        """Number of random-number blocks."""
        return -(-self.rays // self.block_rays)

    @property
    def n_groups(self) -> int:
        """Number of fold groups of ``fold_blocks`` consecutive blocks."""
        return -(-self.n_blocks // self.fold_blocks)

    def group_blocks(self, group: int) -> range:
        """Block indices of fold group ``group``."""
        start = group * self.fold_blocks
        return range(start, min(start + self.fold_blocks, self.n_blocks))

    def block_size(self, block: int) -> int:
        """Rays in block ``block`` (the last one may be short)."""
        return min(self.block_rays, self.rays - block * self.block_rays)

    def replace(self, **changes: Any) -> TraceConfig:
        """A copy with some fields changed."""
        return replace(self, **changes)

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON-safe dict."""
        coat_table = self.coating is not None and (
            self.coating.ndf is not None or self.coating.medium is not None
        )
        if self.substrate.ndf is None and not coat_table:
            d = asdict(self)
            if d["coating"] is not None:
                del d["coating"]["medium"]  # a clear coating: the JSON of before the field
            return d
        d = asdict(self.replace(substrate=Substrate(), coating=None))
        d["substrate"] = self.substrate.to_dict()
        d["coating"] = None if self.coating is None else self.coating.to_dict()
        return d

    def to_json(self) -> str:
        """JSON text (sorted keys)."""
        return json.dumps(self.to_dict(), sort_keys=True)

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> TraceConfig:
        """Inverse of :meth:`to_dict`; unknown keys raise ``ValueError``."""
        known = set(cls.__dataclass_fields__)
        unknown = sorted(set(data) - known)
        if unknown:
            raise ValueError(
                f"unknown TraceConfig keys {unknown}; expected some of {sorted(known)}"
            )
        return cls(**data)

    @classmethod
    def from_json(cls, text: str) -> TraceConfig:
        """Inverse of :meth:`to_json`."""
        return cls.from_dict(json.loads(text))
