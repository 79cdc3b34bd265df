"""A rough dielectric coating over a rough conductor or a diffuse base, by the tracer.

Objects layer: the BRDF is the M00 element of :func:`labbrdf.tracer.trace` in single
scattering with the evaluated estimator ([1]_ sec. 2.3, ``docs/tracer.md``),
one trace per distinct incidence (and wavelength) of the points asked for, on a coarse
grid, interpolated to the points. Every trace uses the same seed whatever the parameters
(common random numbers), so the BRDF is a deterministic and nearly smooth function of the
parameters and a fit can use it like a closed-form model; its Monte Carlo error enters the
fit through :meth:`Layered.point_noise` and :meth:`Layered.point_variance`
(``docs/models.md`` 7). Over a Lambertian base (``base="diffuse"``) the walk's expectation
is a closed form (:mod:`labbrdf.tracer.coated_lambert`), evaluated on the same grid without
rays: deterministic, no Monte Carlo error.

References
----------
.. [1] Dong Z., Bai P., Xu W., Liu Y., Sun X., "Modeling and characteristic analysis
   methods for reflection polarization on coated surfaces", Acta Optica Sinica 42(22),
   2224001 (2022), sec. 2.3 (the layered walk; see :mod:`labbrdf.tracer`).
   doi:10.3788/AOS202242.2224001
.. [2] Walter B., Marschner S. R., Li H., Torrance K. E., "Microfacet models for refraction
   through rough surfaces", Proc. EGSR 2007, eqs. (20), (21), (33), (34).
   doi:10.2312/EGWR/EGSR07/195-206
"""

from __future__ import annotations

import math
from collections import OrderedDict
from collections.abc import Mapping
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .base import Model, ModelError, Parameters, lambert
from .layered_medium import MEDIUM_NAMES, add_medium_params, medium_of, medium_option
from .layered_options import check_distribution as _distribution
from .layered_options import check_scattering as _scattering
from .layered_options import flag as _flag
from .layered_options import is_real as _real

__all__ = ["Layered"]

_BASES = ("conductor", "diffuse")
#: traces kept per model instance (two small maps each): a fit's Jacobian and polish come
#: back to the same parameter values several times
_CACHE_SIZE = 64
#: grid steps [deg] the tracer accepts (divisors of 90 and of 360)
_THETA_STEPS = (1.0, 2.0, 3.0, 5.0, 6.0)
_PHI_STEPS = (2.0, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0, 12.0)
#: the steps "auto" chooses from: bins of at most 3 x 6 degrees keep the interpolated bin
#: averages within ~0.3 % of point values for lobes of alpha >= 0.25 (a 6 x 12 grid made
#: a fitted alpha 2.4 % low); the cost of a trace barely depends on the grid
_AUTO_THETA_STEPS = (1.0, 2.0, 3.0)
_AUTO_PHI_STEPS = (2.0, 3.0, 4.0, 5.0, 6.0)


def _auto_step(spacing: float, steps: tuple[float, ...]) -> float:
    """The largest allowed step not above half the data's angular spacing [deg]."""
    ok = [s for s in steps if s <= spacing / 2.0]
    return max(ok) if ok else steps[0]


class Layered(Model):
    """Rough dielectric coating over a rough conductor or a Lambertian base, by the tracer.

    Other Parameters
    ----------------
    n, k : float
        Complex index N = n + ik of the conductor substrate [1] (``--nk-from FILE`` sets
        them at the file's wavelength).
    base : {"conductor", "diffuse"}, default "conductor"
        What lies under the coating: the rough conductor ``n + ik`` (parameter
        ``alpha_sub``) or a flat Lambertian, depolarizing base (parameter ``albedo``;
        paints, plastics, vinyls; :meth:`labbrdf.Substrate.lambertian`).
    coherent : bool, default False
        The tracer's coherent mode (:mod:`labbrdf.tracer`): coating and substrate as one
        rough interface whose facets carry a conformal film, reflecting with the Airy
        amplitudes; adds the parameter ``thickness_nm`` and drops ``alpha_sub`` (the facets
        use ``alpha_top``). Without it the coating is a separate rough layer whose
        thickness enters only through Beer-Lambert absorption (``coating_k``).
    coating_k : float, default 0
        Extinction coefficient of the coating [1].
    thickness_nm : float, default 1000
        Coating thickness [nm] of the incoherent model (a parameter in coherent mode).
    floor : bool, default False
        Add a Lambertian floor ``kd / pi`` [sr^-1] (linear; profiled by the fit).
    rays : int, default 20000
        Rays per trace (conductor base; a diffuse base is evaluated without rays). On a
        3 x 6 degree grid 2e4 rays give a per-bin relative standard error of about 3 %
        over the lobe of a coating on Al (``docs/models.md`` 7).
    seed : int, default 0
        Seed of every trace (common random numbers: the same for all parameter values;
        conductor base), or of the walks tabulated for ``scattering="multiple"`` over a
        diffuse base.
    grid : "auto", "THETAxPHI" or (float, float), default "auto"
        Tracer bin steps (theta, phi) [deg], e.g. "3x6"; "auto" derives them from the
        number of points per incidence of the first evaluation (:meth:`_set_grid`; at
        most 3 x 6 degrees).
    wavelength_nm : float, default 550
        Wavelength [nm] for points that carry none.
    distribution : str, default "ggx"
        Microfacet distribution of both rough interfaces, a name of
        ``labbrdf.microfacet.DISTRIBUTIONS`` (e.g. "beckmann"). Other than GGX it is
        traced through its slope table and its exit is sampled through the walk's facets
        (``docs/tracer.md``); conductor base and incoherent mode only (the closed form of a
        diffuse base and the coherent facets are written for GGX).
    scattering : {"single", "multiple"}, default "single"
        Scattering on the coating's rough top, the tracer's word: "single" (one facet
        event per crossing, separable Smith ``G1 G1``) or "multiple" (the Heitz et al.
        2016 random walk on the microsurface, all orders; ``base="diffuse"`` only:
        :mod:`labbrdf.tracer.coated_lambert_ms`). Single scattering loses energy at the
        rough top (a lossless coating over a white base returns 0.977 / 0.927 / 0.803 at
        ``alpha_top`` 0.05 / 0.1 / 0.2); "multiple" conserves it.
    medium : bool, default False
        A Henyey-Greenstein medium in the coating, traced even over a diffuse base
        (:mod:`labbrdf.models.layered_medium`: its parameters and limits).

    Parameters: ``n_coat`` [1] in [1.2, 2.2], fixed at 1.5 by default (``--free n_coat``);
    ``alpha_top`` [1] in [0.02, 1] (log), GGX roughness of the coating's top;
    ``alpha_sub`` [1] in [0.02, 1] (log), GGX roughness of the conductor (incoherent);
    ``albedo`` [1] in [0, 1], of the diffuse base;
    ``thickness_nm`` [nm] in [0, 2000] (coherent only); ``scale`` [1] in [0, 10], fixed at
    1 (free it for relative data; linear); ``kd`` [1] in [0, 1] with ``floor`` (linear).

    Notes
    -----
    The tracer bins the exit directions; the model's value at a point is the bilinear
    interpolation (in theta_r and periodic phi_r) of the cos-weighted bin averages at the
    bin centres. Against the point value of the BRDF this has a bias of order
    ``h^2 f'' / 8``, which is why "auto" keeps the bins at most half the data's spacing
    and at most 3 x 6 degrees.
    A diffuse base: every ray that reaches it is re-emitted with the cosine law whatever
    way it came, so the walk is a renewal process and its expectation is the series
    ``a T(theta_i) T(theta_o) / (pi n^2 (1 - a R))`` plus the first surface
    (:mod:`labbrdf.tracer.coated_lambert`; agrees with the counting walk over every bin,
    ``docs/tracer.md``), evaluated on the tracer's grid and interpolated like a traced
    map: the traced model without its noise.
    Single scattering (separable Smith G1 G1) loses energy at rough interfaces. Over a
    conductor the multiple-scattering walk only counts rays, whose noise no fit can use;
    over a diffuse base the renewal form holds for the whole microsurface walk
    (``scattering="multiple"``; ``T``, ``R`` and the first surface's higher orders from
    walks with fixed seeds, tabulated once per coating over ``alpha_top`` in [0.02, 1]
    and splined, about 10 s of walks per seed and coating, cached on disk; each new
    ``n_coat`` is a new table; three seed replicates by default; ``docs/tracer.md``).
    A nearly smooth top (``alpha_top`` below about ``0.035 / (n_coat - 1)``, 0.07 for
    n_coat = 1.5) has an exit lobe narrower than the tracer's exit operator resolves; there
    the tracer exits through the walk's own sampled facet instead (unbiased, no operator to
    build, but the light that went through the coating is then about as noisy per bin as
    counting: :meth:`point_variance` says how much). The two exits are different
    estimates of the same BRDF: at the switch the model moves by about its Monte Carlo
    error (``docs/tracer.md``, a nearly smooth coating top).
    """

    name = "layered"
    reference = (
        "Dong Z. et al., Acta Optica Sinica 42(22) 2224001, 2022 (layered walk, sec. 2.3); "
        "Walter B. "
        "et al., EGSR 2007 (GGX, Smith G1, rough-dielectric BTDF); evaluated estimator with "
        "common random numbers"
    )
    doi = "10.3788/AOS202242.2224001"
    reciprocity_note = (
        "layered is reciprocal up to its Monte Carlo error in the incoherent mode (the "
        "walk's interfaces are reciprocal, the estimate of each direction pair is not "
        "symmetrised); the coherent film and the Lambertian floor are reciprocal."
    )
    linear: tuple[str, ...] = ("scale",)
    #: none: on the specular line each roughness still sets the peak's height (the GGX
    #: D(0) = 1 / (pi alpha^2) of its interface), so specular-only data constrain both,
    #: if weakly and correlated; the fitting core's correlation flags show it
    specular_line_shape: tuple[str, ...] = ()
    #: common random numbers make the traced BRDF smooth on scales above ~1e-3 of a
    #: parameter's range (below it, single rays changing bins show as small jumps); None
    #: in the coherent mode, whose map is evaluated in closed form
    fd_rel_step: float | None = 3e-3
    #: traced (not in the coherent mode): the value depends on the seed
    stochastic: bool = True
    #: three seeds: the seed spread is estimated with 2 degrees of freedom at 3x the cost
    #: of one fit (docs/models.md 7)
    default_replicates: int = 3
    #: a scattering coating (option ``medium``; :mod:`labbrdf.models.layered_medium`)
    _medium: bool = False

    def __init__(
        self,
        n: float | None = None,
        k: float | None = None,
        base: str = "conductor",
        coherent: bool = False,
        coating_k: float = 0.0,
        thickness_nm: float = 1000.0,
        floor: bool = False,
        rays: int = 20_000,
        seed: int = 0,
        grid: str | tuple[float, float] = "auto",
        wavelength_nm: float = 550.0,
        distribution: str = "ggx",
        scattering: str = "single",
        medium: bool = False,
        **options: Any,
    ) -> None:
        if options:
            raise ModelError(
                f"model 'layered' got unknown options {sorted(options)}; options are "
                "['n', 'k', 'base', 'coherent', 'coating_k', 'thickness_nm', 'floor', "
                "'rays', 'seed', 'grid', 'wavelength_nm', 'distribution', 'scattering', "
                "'medium']"
            )
        if base not in _BASES:
            raise ModelError(f"layered option 'base' must be one of {list(_BASES)}; got {base!r}")
        self._base = base
        self._coherent = _flag(coherent, "coherent")
        self._distribution = _distribution(distribution, base, self._coherent)
        self._floor = _flag(floor, "floor")
        self._nk = (1.0, 0.0)
        self._closed = medium_option(self, medium, scattering, self._closed_form(base, scattering))
        if base == "diffuse":
            if n is not None or k is not None:
                raise ModelError(
                    "layered with base='diffuse' takes no substrate index n, k (they are the "
                    "conductor's); leave out --nk-from and n=, k="
                )
            if self._coherent:
                raise ModelError(
                    "layered: coherent=True needs base='conductor' (the film's Airy "
                    "amplitudes need the substrate's index)"
                )
        if base == "conductor":
            if n is None:
                raise ModelError(
                    "layered with base='conductor' needs the substrate index n= (and k=), "
                    "e.g. --nk-from FILE or --param n=1.55 --param k=7.71"
                )
            kk = 0.0 if k is None else k
            if not (_real(n) and _real(kk) and n >= 0 and kk >= 0 and (n > 0 or kk > 0)):
                raise ModelError(
                    f"layered options n, k must be finite, >= 0 and not both 0; got "
                    f"n={n!r}, k={kk!r}"
                )
            self._nk = (float(n), float(kk))
        if not (_real(coating_k) and coating_k >= 0):
            raise ModelError(f"layered option 'coating_k' must be >= 0; got {coating_k!r}")
        if not (_real(thickness_nm) and thickness_nm > 0):
            raise ModelError(f"layered option 'thickness_nm' must be > 0; got {thickness_nm!r}")
        if not (_real(rays) and float(rays).is_integer() and 1000 <= rays <= 10_000_000):
            raise ModelError(
                f"layered option 'rays' must be an integer in [1000, 1e7]; got {rays!r}"
            )
        if not (_real(seed) and float(seed).is_integer() and seed >= 0):
            raise ModelError(f"layered option 'seed' must be an integer >= 0; got {seed!r}")
        if not (_real(wavelength_nm) and wavelength_nm > 0):
            raise ModelError(f"layered option 'wavelength_nm' must be > 0; got {wavelength_nm!r}")
        self._grid: tuple[float, float] | None = None
        if grid != "auto":
            parts = grid.lower().split("x") if isinstance(grid, str) else grid
            try:
                dt, dp = (float(v) for v in parts)
            except (TypeError, ValueError):
                raise ModelError(
                    "layered option 'grid' must be 'auto', 'THETAxPHI' or (theta_step, "
                    "phi_step) [deg]; "
                    f"got {grid!r}"
                ) from None
            if dt not in _THETA_STEPS or dp not in _PHI_STEPS:
                raise ModelError(
                    f"layered option 'grid': theta step must be one of {list(_THETA_STEPS)} "
                    f"and phi step one of {list(_PHI_STEPS)} [deg]; got {grid!r}"
                )
            self._grid = (dt, dp)
        self._coating_k = float(coating_k)
        self._thickness = float(thickness_nm)
        self._rays = int(rays)
        self._seed = int(seed)
        self._wl_default = float(wavelength_nm)
        self._cache: OrderedDict[tuple, tuple[NDArray, NDArray]] = OrderedDict()
        self._operators: OrderedDict[str, Any] = OrderedDict()  # exit operators in memory
        self.traces = 0  # traces run (cache misses), for benchmarks
        opts: dict[str, Any] = {
            "base": base,
            "rays": self._rays,
            "seed": self._seed,
            **({"scattering": "multiple"} if self._multiple else {}),
            **({"medium": True} if self._medium else {}),
        }
        if self._wl_default != 550.0:
            opts["wavelength_nm"] = self._wl_default
        if base == "conductor":
            opts.update(n=self._nk[0], k=self._nk[1])
        if self._distribution != "ggx":
            opts["distribution"] = self._distribution
        if self._coherent:
            opts["coherent"] = True
        else:
            opts["thickness_nm"] = self._thickness
        if self._coating_k:
            opts["coating_k"] = self._coating_k
        self.linear = ("scale",)
        if self._floor:
            opts["floor"] = True
            self.linear = ("scale", "kd")
        opts["grid"] = "auto" if self._grid is None else f"{self._grid[0]:g}x{self._grid[1]:g}"
        super().__init__(**opts)

    def _closed_form(self, base: str, scattering: Any) -> bool:
        """Whether a diffuse base is evaluated in closed form; marks a deterministic model.

        A Lambertian base makes the walk a renewal process, whose expectation is a closed
        form (:mod:`labbrdf.tracer.coated_lambert`): no rays. The coherent mode's map is
        evaluated in closed form too. Both are deterministic. Multiple scattering: walks
        of the model's seed tabulated in ``alpha_top`` and splined
        (:mod:`labbrdf.tracer.coated_lambert_table`): smooth in the parameters (ordinary
        finite differences), but the value depends on the seed, so the fit takes three
        seed replicates by default.
        """
        self._multiple = _scattering(scattering, base, self._coherent, self._distribution)
        self._first_maps: OrderedDict[tuple, NDArray] = OrderedDict()  # closed form's
        closed = base == "diffuse"
        if closed or self._coherent:
            self.fd_rel_step = None
            self.stochastic = False
            self.default_replicates = 1
        if closed and self._multiple:
            # tables in alpha_top from walks of the model's seed: smooth, seed-dependent
            self.stochastic = True
            self.default_replicates = 3
        return closed

    def reseeded(self, seed: int) -> Layered:
        """The same model (options, grid) with the tracer seed ``seed`` and a fresh cache."""
        if not self.stochastic:
            return super().reseeded(seed)  # type: ignore[return-value]
        new = Layered(**{**self.options, "seed": seed})
        new._grid = self._grid
        return new

    def default_params(self) -> Parameters:
        """Defaults: n_coat 1.5 (fixed), alpha_top and alpha_sub 0.2, scale 1 (fixed), kd 0.

        Coherent mode: thickness_nm 500 instead of alpha_sub.
        """
        p = Parameters()
        p.add(
            "n_coat",
            1.5,
            1.2,
            2.2,
            vary=False,
            units="1",
            description="refractive index of the coating",
        )
        p.add(
            "alpha_top",
            0.2,
            0.02,
            1.0,
            units="1",
            log=True,
            description="GGX roughness of the coating's top",
        )
        if self._coherent:
            p.add("thickness_nm", 500.0, 0.0, 2000.0, units="nm", description="film thickness")
        elif self._base == "diffuse":
            p.add("albedo", 0.5, 0.0, 1.0, units="1", description="Lambertian base albedo")
        elif self._base == "conductor":
            p.add(
                "alpha_sub",
                0.2,
                0.02,
                1.0,
                units="1",
                log=True,
                description="GGX roughness of the conductor",
            )
        p.add(
            "scale",
            1.0,
            0.0,
            10.0,
            vary=False,
            units="1",
            description="overall factor of the traced part (relative data)",
        )
        if self._floor:
            p.add("kd", 0.0, 0.0, 1.0, units="1", description="Lambertian floor albedo")
        if self._medium:
            add_medium_params(p)
        return p

    def lobe_width(self, p: Mapping[str, float]) -> float:
        """Angular scale of the lobe in theta_r [rad] (a quadrature hint): ``2 alpha_top``."""
        return 2.0 * float(p["alpha_top"])

    def guess(self, theta_i: NDArray, theta_r: NDArray, value: NDArray) -> dict[str, float]:
        """``alpha_top`` from the specular peak's half width, ``alpha_sub`` the same.

        GGX falls to half its peak at ``tan^2 theta_m = alpha^2 (sqrt 2 - 1)``, i.e.
        ``theta_m ~ 0.64 alpha``, and the reflected direction turns by twice the facet's
        tilt: the lobe's half width at half maximum above the floor is ``~1.3 alpha`` [rad]
        (near normal incidence). Measured per incidence along theta_r (all azimuths, so a
        lower bound on the width), median over incidences. ``kd`` with ``floor``: pi times
        the 10th percentile of the data. ``albedo`` of a diffuse base: ``pi n_coat^2``
        times that percentile (a coated Lambertian base's floor is about
        ``albedo T^2 / (pi n^2)``). No roughness where no incidence shows a peak.
        """
        out: dict[str, float] = {}
        if self._base == "diffuse" and value.size:
            # the floor of a coated Lambertian base is about albedo T^2 / (pi n^2)
            n2 = float(self.params["n_coat"].value) ** 2
            floor = math.pi * n2 * float(np.percentile(value, 10))
            out["albedo"] = float(np.clip(floor, 0.02, 0.98))
        if self._floor and value.size:
            out["kd"] = float(np.clip(math.pi * np.percentile(value, 10), 1e-3, 0.9))
        widths = []
        for t in np.unique(np.round(theta_i, 9)):
            sel = np.round(theta_i, 9) == t
            v, tr = value[sel], theta_r[sel]
            if v.size < 5:
                continue
            lo, hi = float(np.percentile(v, 10)), float(v.max())
            if not hi > 2.0 * lo:  # no peak above the floor
                continue
            peak = float(tr[np.argmax(v)])
            half = v >= lo + 0.5 * (hi - lo)
            widths.append(float(np.max(np.abs(tr[half] - peak))))
        if widths:
            a = float(np.clip(np.median(widths) / 1.3, 0.03, 0.9))
            out["alpha_top"] = a
            if "alpha_sub" in self.params:
                out["alpha_sub"] = a
        return out

    # ------------------------------------------------------------------ tracing
    def _config(self, p: Mapping[str, float], theta_i_deg: float, wl: float) -> Any:
        from ..microfacet.interface import table_for
        from ..tracer import Coating, Substrate, TraceConfig

        n_coat, a_top = float(p["n_coat"]), float(p["alpha_top"])
        for name, v, lo in (("n_coat", n_coat, 0.0), ("alpha_top", a_top, 0.0)):
            if not (math.isfinite(v) and v > lo):
                raise ModelError(f"layered parameter {name!r} must be > {lo:g}; got {v!r}")
        thick = float(p["thickness_nm"]) if self._coherent else self._thickness
        dist = self._distribution
        coat = Coating(
            n=n_coat,
            k=self._coating_k,
            thickness_nm=thick,
            alpha=a_top,
            ndf=table_for(dist, a_top),
            medium=medium_of(p) if self._medium else None,
        )
        if self._base == "diffuse":
            sub = Substrate.lambertian(float(p["albedo"]))
        else:
            a_sub = a_top if self._coherent else float(p["alpha_sub"])
            sub = Substrate(n=self._nk[0], k=self._nk[1], alpha=a_sub, ndf=table_for(dist, a_sub))
        assert self._grid is not None
        return TraceConfig(
            wavelength_nm=wl,
            theta_i_deg=theta_i_deg,
            substrate=sub,
            coating=coat,
            rays=self._rays,
            seed=self._seed,
            scattering="multiple" if self._multiple else "single",
            estimator="evaluated",
            coherent=self._coherent,
            theta_step_deg=self._grid[0],
            phi_step_deg=self._grid[1],
        )

    def _key_params(self, p: Mapping[str, float]) -> tuple[float, ...]:
        names = ("n_coat", "alpha_top", "alpha_sub", "thickness_nm", "albedo", *MEDIUM_NAMES)
        return tuple(float(p[k]) for k in names if k in self.params)

    def trace_maps(
        self, p: Mapping[str, float], theta_i_deg: float, wavelength_nm: float
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """S0 BRDF map (n_theta, n_phi) and its batch deviations (B, n_theta, n_phi) [sr^-1].

        Unpolarized incidence; the tracer's grid (:attr:`grid_deg`); the floor not added;
        cached. The deviations' squares sum to the squared standard error of each bin.
        """
        from ..tracer import trace
        from ..tracer.operator import memory_cache

        key = (self._key_params(p), round(float(theta_i_deg), 9), float(wavelength_nm))
        hit = self._cache.get(key)
        if hit is not None:
            self._cache.move_to_end(key)
            return hit
        try:
            cfg = self._config(p, float(theta_i_deg), float(wavelength_nm))
        except ValueError as exc:
            raise ModelError(f"layered: {exc}") from None
        if self._closed:
            f = self._closed_map(cfg)
            return self._remember(key, (f, np.zeros((1, *f.shape))))
        with memory_cache(self._operators):
            res = trace(cfg)
        self.traces += 1
        f = np.asarray(res.mueller[..., 0, 0], float)
        assert res.batch_mueller is not None  # the evaluated estimator keeps its batches
        # batch deviations d_b = sqrt(N_b / (N (B - 1))) (f_b - f): sum_b d_b^2 is the
        # tracer's squared standard error, sum_b d_b(x) d_b(y) the covariance of two bins
        nb = np.asarray(res.block_rays, float)
        scale = np.sqrt(nb / (nb.sum() * (nb.size - 1)))[:, None, None]
        dev = scale * (np.asarray(res.batch_mueller[..., 0, 0], float) - f)
        if not np.any(res.mueller_stderr[..., 0, 0]):
            # no Monte Carlo part (a bare or coherent first surface): the batch maps are
            # the same map, and only their float32 storage differs from f
            dev = np.zeros_like(dev)
        return self._remember(key, (f, dev))

    def _remember(
        self, key: tuple, out: tuple[NDArray[np.float64], NDArray[np.float64]]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        self._cache[key] = out
        if len(self._cache) > _CACHE_SIZE:
            self._cache.popitem(last=False)
        return out

    def _closed_map(self, cfg: Any) -> NDArray[np.float64]:
        """S0 map of a coated Lambertian base in closed form (n_theta, n_phi) [sr^-1].

        The first surface's bin averages (:func:`labbrdf.tracer.estimator.first_surface_map`)
        plus the light through the coating (:mod:`labbrdf.tracer.coated_lambert`): the
        expectation of the traced map, on the same grid, without its Monte Carlo error.
        """
        from ..tracer import Grid
        from ..tracer.coated_lambert import coated_lambert

        coat = cfg.coating
        form = self._ms_form(coat.alpha) if self._multiple else coated_lambert
        grid = Grid(cfg.theta_step_deg, cfg.phi_step_deg)
        body = form(coat.n, coat.alpha, coat.k, coat.thickness_nm, cfg.wavelength_nm).bin_map(
            float(cfg.substrate.albedo), cfg.theta_i_deg, grid
        )
        self.traces += 1
        return np.asarray(self._first_map(cfg) + body, float)

    def _ms_form(self, alpha: float) -> Any:
        """Multiple scattering's ``T``, ``R`` at ``alpha``: tabulated for the model's seed.

        Inside :data:`labbrdf.tracer.coated_lambert_table.ALPHA_RANGE` the tables in
        ``alpha_top`` (smooth, built once); outside it the direct walks of
        :func:`labbrdf.tracer.coated_lambert_ms.coated_lambert_ms` (about 4 s each).
        """
        from functools import partial

        from ..tracer.coated_lambert_ms import coated_lambert_ms
        from ..tracer.coated_lambert_table import in_range, tabulated_ms

        return partial(tabulated_ms, seed=self._seed) if in_range(alpha) else coated_lambert_ms

    def _first_map(self, cfg: Any) -> NDArray[np.float64]:
        """The first surface's S0 map: closed form, plus the walk's higher orders if asked.

        It does not depend on the albedo: kept per (coating, incidence, grid).
        """
        from ..tracer import Grid
        from ..tracer.coated_lambert import first_surface_s0
        from ..tracer.coated_lambert_ms import first_surface_ms
        from ..tracer.coated_lambert_table import in_range, tabulated_first_surface
        from ..tracer.estimator import first_surface_map

        coat = cfg.coating
        # the first surface does not depend on the albedo: kept per (coating, incidence)
        key = (coat.n, coat.alpha, cfg.theta_i_deg, cfg.theta_step_deg, cfg.phi_step_deg)
        first = self._first_maps.get(key)
        if first is None:
            if self._multiple and in_range(coat.alpha):
                grid = Grid(cfg.theta_step_deg, cfg.phi_step_deg)
                single = first_surface_s0(coat.n, coat.alpha, cfg.theta_i_deg, grid)
                first = tabulated_first_surface(
                    single, coat.n, coat.alpha, cfg.theta_i_deg, grid, self._seed
                )
            elif self._multiple:
                first = first_surface_ms(cfg)[0]
            else:
                first = first_surface_map(cfg)[..., 0, 0]
            self._first_maps[key] = first
            if len(self._first_maps) > _CACHE_SIZE:
                self._first_maps.popitem(last=False)
        return np.asarray(first, float)

    @property
    def grid_deg(self) -> tuple[float, float] | None:
        """Tracer bin steps (theta, phi) [deg]; None until "auto" has seen data."""
        return self._grid

    def _set_grid(self, theta_i_deg: NDArray) -> None:
        """Tracer steps from the data's density (once, at the first evaluation).

        M points per incidence sample 2 pi sr at a spacing of about ``sqrt(2 pi / M)``;
        theta gets half of it, phi all of it (an azimuth degree is shorter than a polar one
        by sin theta).
        """
        if self._grid is not None:
            return
        n_inc = max(np.unique(np.round(theta_i_deg, 9)).size, 1)
        per = max(theta_i_deg.size / n_inc, 1.0)
        spacing = math.degrees(math.sqrt(2.0 * math.pi / per))
        dt = _auto_step(spacing, _AUTO_THETA_STEPS)
        dp = _auto_step(2.0 * spacing, _AUTO_PHI_STEPS)
        self._grid = (dt, dp)
        self.options["grid"] = f"{dt:g}x{dp:g}"

    def _maps_at(
        self,
        p: Mapping[str, float],
        theta_i: NDArray,
        theta_r: NDArray,
        phi_r: NDArray,
        wavelength: NDArray | None,
    ) -> tuple[NDArray, NDArray]:
        """Traced part at every point and its batch deviations (B, ...) [sr^-1]."""
        ti_deg = np.degrees(theta_i)
        tr_deg = np.degrees(theta_r)
        pr_deg = np.mod(np.degrees(phi_r), 360.0)
        self._set_grid(np.broadcast_to(ti_deg, tr_deg.shape).ravel())
        assert self._grid is not None
        wl = (
            np.full(ti_deg.shape, self._wl_default)
            if wavelength is None
            else np.broadcast_to(np.asarray(wavelength, float), ti_deg.shape)
        )
        wl = np.where(np.isfinite(wl), wl, self._wl_default)
        if not np.all((ti_deg >= 0) & (ti_deg < 90)):
            raise ModelError("layered: the tracer needs incidence angles in [0, 90) deg")
        val = np.zeros(ti_deg.shape)
        dev: NDArray | None = None
        up = (tr_deg >= 0) & (tr_deg <= 90)
        dt, dp = self._grid
        pairs = np.unique(np.stack([np.round(ti_deg, 9).ravel(), wl.ravel()], axis=1), axis=0)
        for t, w in pairs:
            sel = up & (np.round(ti_deg, 9) == t) & (wl == w)
            if not sel.any():
                continue
            f, d = self.trace_maps(p, float(t), float(w))
            if dev is None:
                dev = np.zeros((d.shape[0], *ti_deg.shape))
            u, v = tr_deg[sel] / dt, pr_deg[sel] / dp
            val[sel] = _bilinear(f, u, v)
            dev[:, sel] = _bilinear(d, u, v)
        return val, np.zeros((1, *ti_deg.shape)) if dev is None else dev

    # ------------------------------------------------------------------ model API
    def _evaluate(
        self,
        p: Mapping[str, float],
        theta_i: NDArray,
        theta_r: NDArray,
        phi_r: NDArray,
        wavelength: NDArray | None,
    ) -> NDArray:
        val, _ = self._maps_at(p, theta_i, theta_r, phi_r, wavelength)
        val = p["scale"] * val
        if self._floor:
            val = val + p["kd"] * lambert(theta_i, theta_r)
        return val

    def linear_components(
        self,
        p: Mapping[str, float],
        theta_i: NDArray,
        theta_r: NDArray,
        phi_r: NDArray,
        wavelength: NDArray | None,
    ) -> dict[str, NDArray] | None:
        """``{"scale": traced part, "kd": 1 / pi}`` (``kd`` with ``floor`` only)."""
        val, _ = self._maps_at(p, theta_i, theta_r, phi_r, wavelength)
        out = {"scale": np.broadcast_to(val, np.shape(theta_r)).copy()}
        if self._floor:
            out["kd"] = np.broadcast_to(lambert(theta_i, theta_r), np.shape(theta_r)).copy()
        return out

    def point_noise(
        self,
        p: Mapping[str, float],
        theta_i: NDArray,
        theta_r: NDArray,
        phi_r: NDArray,
        wavelength: NDArray | None,
    ) -> NDArray[np.float64]:
        """Monte Carlo error components (B, ...) [sr^-1]: covariance ``sum_b n_b n_b^T``.

        The bilinear interpolation of each batch's deviation from the mean map, scaled so
        that the squares sum to the squared standard error (``docs/tracer.md``, standard
        errors). Interpolation is linear, so these are exactly the error components of the
        interpolated values, with the correlations between points that share bins or
        rays (the exit operator spreads each ray over the top interface's lobe).
        """
        if self._closed:
            return np.zeros((1, *np.broadcast(theta_i, theta_r, phi_r).shape))
        q = self.values(p)  # missing names take the current values
        ti, tr, pr = np.broadcast_arrays(
            np.asarray(theta_i, float), np.asarray(theta_r, float), np.asarray(phi_r, float)
        )
        return q["scale"] * self._maps_at(q, ti, tr, pr, wavelength)[1]

    def point_variance(
        self,
        p: Mapping[str, float],
        theta_i: NDArray,
        theta_r: NDArray,
        phi_r: NDArray,
        wavelength: NDArray | None,
    ) -> NDArray[np.float64]:
        """Monte Carlo variance of :meth:`evaluate` at every point [sr^-2].

        The sum of squares of :meth:`point_noise` (the squared standard error from the
        spread of the tracer's independent ray batches).
        """
        n = self.point_noise(p, theta_i, theta_r, phi_r, wavelength)
        return np.asarray(np.sum(n * n, axis=0), float)

    def hemispherical(
        self, theta_i_deg: ArrayLike, params: Mapping[str, float] | None = None
    ) -> NDArray[np.float64] | None:
        """The traced albedo [1] (S0 map integrated over the hemisphere) plus ``kd``."""
        from ..tracer import Grid, trace
        from ..tracer.operator import memory_cache

        p = self.values(params)
        if self._grid is None:
            self._grid = (2.0, 4.0)
            self.options["grid"] = "2x4"
        out = []
        for t in np.atleast_1d(np.asarray(theta_i_deg, float)):
            cfg = self._config(p, float(t), self._wl_default)
            if self._closed:
                omega = Grid(*self._grid).cos_solid_angle_sr
                albedo = float((self._closed_map(cfg) * omega).sum())
            else:
                with memory_cache(self._operators):
                    albedo = trace(cfg).albedo()
            out.append(albedo + (p["kd"] if self._floor else 0.0))
        return np.asarray(out, float).reshape(np.shape(theta_i_deg))


def _bilinear(m: NDArray, u: NDArray, v: NDArray) -> NDArray[np.float64]:
    """Bilinear interpolation of maps (..., n_theta, n_phi) at fractional bin indices.

    ``u`` = theta / step, clipped to the polar range; ``v`` = phi / step, periodic.
    """
    nt, nph = m.shape[-2:]
    u = np.clip(u, 0.0, nt - 1.0)
    i0 = np.minimum(np.floor(u).astype(int), nt - 2)
    a = u - i0
    j0 = np.floor(v).astype(int) % nph
    b = v - np.floor(v)
    j1 = (j0 + 1) % nph
    return np.asarray(
        (1 - a) * (1 - b) * m[..., i0, j0]
        + (1 - a) * b * m[..., i0, j1]
        + a * (1 - b) * m[..., i0 + 1, j0]
        + a * b * m[..., i0 + 1, j1],
        float,
    )
