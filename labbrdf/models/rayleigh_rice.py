"""Rayleigh-Rice BRDF model: a smooth surface's scatter from a PSD model and its index.

Physics layer: numpy only (the scatter is :mod:`labbrdf.roughness.rayleigh_rice`). The
parameters are those of the surface's isotropic 2-D PSD; the substrate's index ``n + ik``
is an option (given, or from an ellipsometer file with ``labbrdf fit --nk-from``). Fitted to
a measured BRDF, it is the scatterometer's inverse problem: the PSD over the spatial
frequencies the measured directions see. Derivation and conventions:
``docs/rayleigh-rice.md``.

References
----------
.. [1] T. A. Germer, Appl. Opt. 36, 8798-8805 (1997), eqs. (3)-(7). doi:10.1364/AO.36.008798
.. [2] E. L. Church, P. Z. Takacs, T. A. Leonard, "The prediction of BRDFs from surface
   profile measurements", Proc. SPIE 1165, 136-150 (1989) (the K-correlation, or ABC, PSD).
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..films import FilmError, Stack, read_fit_json
from ..roughness import psd_models
from ..roughness.rayleigh_rice import POLARIZATIONS, brdf, mueller_brdf
from ..roughness.rr_stack import INTERFACES, mueller_brdf_stack, stack_brdf, stack_layers
from .base import Model, ModelError, Parameters

__all__ = ["PSD_FORMS", "RayleighRice", "psd_function"]

#: PSD forms the model fits (:data:`labbrdf.roughness.psd_models.PSD_MODELS`); the fractal
#: has no finite sigma and a unit that depends on its exponent, so it is left out
PSD_FORMS: tuple[str, ...] = ("k-correlation", "gaussian", "exponential")

#: fitted unit of each PSD unit, and its factor to SI: lengths in um, areas^2 in um^4
_FIT_UNITS = {"m^4": ("um4", 1e-24), "m": ("um", 1e-6), "1": ("1", 1.0)}

#: (start, min, max, log) of each fitted parameter, in the fitted units
_RANGES: dict[str, tuple[float, float, float, bool]] = {
    "A": (1e-4, 1e-12, 1e4, True),
    "B": (10.0, 1e-2, 1e4, True),
    "C": (1.5, 0.05, 8.0, False),
    "sigma": (1e-3, 1e-5, 0.1, True),
    "corr_length": (5.0, 1e-2, 1e3, True),
}


def psd_function(
    form: str, p: Mapping[str, float]
) -> Callable[[NDArray[np.float64], NDArray[np.float64]], NDArray[np.float64]]:
    """The 2-D PSD ``psd2d(fx, fy)`` [m^4] of fx, fy [cycles/m] for the model's parameters.

    The form's 2-D PSD of :mod:`labbrdf.roughness.psd_models` (``k-correlation``:
    ``A / (1 + (B f)^2)^((C+1)/2)``; ``gaussian``, ``exponential``: sigma and correlation
    length), with the fitted parameters in um (A in um^4) converted to SI.
    """
    if form not in PSD_FORMS:
        raise ModelError(f"PSD form {form!r} unknown; forms are {list(PSD_FORMS)}")
    m = psd_models.get(form)
    args = tuple(
        float(p[name]) * _FIT_UNITS[unit][1]
        for name, unit in zip(m.param_names, m.units, strict=True)
    )

    def psd2d(fx: NDArray, fy: NDArray) -> NDArray[np.float64]:
        return m.psd_2d(np.hypot(fx, fy), *args)

    return psd2d


class RayleighRice(Model):
    """First-order vector perturbation (Rayleigh-Rice) BRDF of a smooth surface [sr^-1].

    ``f = (16 pi^2 / lambda^4) cos ti cos tr Q PSD2(fx, fy)`` with Germer's (1997)
    polarization factors for the incident ``polarization`` (all scattered light detected).

    Other Parameters
    ----------------
    n, k : float
        Substrate index ``N = n + ik`` (ambient 1); ``labbrdf fit --nk-from FILE`` sets
        them from an ellipsometer file.
    psd : {"k-correlation", "gaussian", "exponential"}, default "k-correlation"
        The PSD form whose parameters are fitted (:mod:`labbrdf.roughness.psd_models`).
    wavelength_nm : float, optional
        The vacuum wavelength [nm]; default: the data's (a ``.bsdf`` file states one only in
        a comment, so give it where the file does not).
    polarization : {"unpolarized", "s", "p"}, default "unpolarized"
    free_index : bool, default False
        Fit the substrate index too: parameters ``n_sub`` in [0.01, 20] and ``k_sub`` in
        [0, 50], started at the options ``n``, ``k``. The index and the PSD's amplitude are
        strongly correlated (both scale the BRDF): expect wide intervals unless the data
        span angles where the polarization factors differ.
    film : path-like or labbrdf.films.Stack, optional
        A coated sample: a film fit's JSON (``labbrdf film --fit-json``, read by
        :func:`labbrdf.films.read_fit_json`) or a ``labbrdf.films.Stack``. Its layers
        and substrate replace ``n``, ``k`` (leave them out); the scatter is that of the
        stack's rough interfaces (:mod:`labbrdf.roughness.rr_stack`), each with the fitted
        PSD.
    interfaces : {"correlated", "uncorrelated", "substrate", "top"}, default "correlated"
        With ``film``: every interface rough with the same heights (a conformal coating on a
        polished substrate), every one rough with independent heights, or only the
        substrate's or the top interface rough.

    Parameters: k-correlation ``A`` [um^4] in [1e-12, 1e4] (log), ``B`` [um] in
    [1e-2, 1e4] (log), ``C`` [1] in [0.05, 8]; gaussian and exponential ``sigma`` [um] in
    [1e-5, 0.1] (log), ``corr_length`` [um] in [1e-2, 1e3] (log).

    Notes
    -----
    Valid for ``4 pi sigma cos theta / lambda << 1`` (the Rayleigh criterion's smooth side)
    and small slopes; the specular beam is not part of it (points at the specular
    direction of a measured file include it: mask them). Reciprocal (Mueller transpose
    rule, ``docs/rayleigh-rice.md``). The index does not depend on wavelength: fit one
    wavelength at a time.
    """

    name = "rayleigh_rice"
    reference = (
        "Rayleigh-Rice first-order vector perturbation theory: Germer, Appl. Opt. 36, 8798 "
        "(1997); Stover, Optical Scattering 3rd ed. (2012) ch. 5; K-correlation PSD: Church, "
        "Takacs & Leonard, Proc. SPIE 1165 (1989)"
    )
    doi = "10.1364/AO.36.008798"
    reciprocity_note = (
        "rayleigh_rice is reciprocal: f(i, r) = f(r, i) for unpolarized light (Q and "
        "cos\u03b8i cos\u03b8r PSD(|f|) are symmetric)."
    )

    def __init__(
        self,
        n: float | None = None,
        k: float | None = None,
        psd: str = "k-correlation",
        wavelength_nm: float | None = None,
        polarization: str = "unpolarized",
        free_index: bool = False,
        film: Any = None,
        interfaces: str = "correlated",
        **options: Any,
    ) -> None:
        if options:
            raise ModelError(
                f"model 'rayleigh_rice' got unknown options {sorted(options)}; options are "
                "['n', 'k', 'psd', 'wavelength_nm', 'polarization', 'free_index', 'film', "
                "'interfaces']"
            )
        self._stack, self._range, film_opts = _film(film, interfaces, n, k, free_index)
        if self._stack is not None:
            n, k = 1.0, 0.0  # a stand-in: the stack's substrate is the index
        if psd not in PSD_FORMS:
            raise ModelError(
                f"rayleigh_rice option 'psd' must be one of {list(PSD_FORMS)}; got {psd!r}"
            )
        if polarization not in POLARIZATIONS:
            raise ModelError(
                f"rayleigh_rice option 'polarization' must be one of {list(POLARIZATIONS)}; "
                f"got {polarization!r}"
            )
        if n is None:
            raise ModelError(
                "rayleigh_rice needs the substrate index: n= (and k=), or --nk-from FILE"
            )
        kk = 0.0 if k is None else float(k)
        if not (math.isfinite(n) and math.isfinite(kk) and n >= 0 and kk >= 0 and n + kk > 0):
            raise ModelError(
                f"rayleigh_rice options n, k must be finite, >= 0 and not both 0; got n={n!r}, "
                f"k={k!r}"
            )
        if wavelength_nm is not None and not (math.isfinite(wavelength_nm) and wavelength_nm > 0):
            raise ModelError(
                f"rayleigh_rice option 'wavelength_nm' must be > 0 [nm]; got {wavelength_nm!r}"
            )
        self.N = complex(float(n), kk)
        self._psd = psd
        self._wl = None if wavelength_nm is None else float(wavelength_nm)
        self._pol = polarization
        self._free = bool(free_index)
        self._interfaces = interfaces
        opts: dict[str, Any] = {"n": float(n), "k": kk, "psd": psd, "polarization": polarization}
        if self._wl is not None:
            opts["wavelength_nm"] = self._wl
        if self._free:
            opts["free_index"] = True
        if film_opts:
            del opts["n"], opts["k"]
            opts.update(film_opts)
        super().__init__(**opts)

    def default_params(self) -> Parameters:
        """The PSD form's parameters in um (A in um^4), log-scaled where positive."""
        p = Parameters()
        m = psd_models.get(self._psd)
        for name, unit in zip(m.param_names, m.units, strict=True):
            start, lo, hi, log = _RANGES[name]
            p.add(name, start, lo, hi, units=_FIT_UNITS[unit][0], log=log, description=name)
        if self._free:
            n0, k0 = self.N.real, self.N.imag
            p.add("n_sub", n0, 0.01, max(20.0, n0), description="substrate n (start: option n)")
            p.add("k_sub", k0, 0.0, max(50.0, k0), description="substrate k (start: option k)")
        return p

    @property
    def stack(self) -> Stack | None:
        """The film stack of the ``film`` option (None for a bare surface)."""
        return self._stack

    def index(self, params: Mapping[str, float] | None = None) -> complex:
        """The substrate's ``n + ik``: the option's, or the fitted ``n_sub``, ``k_sub``."""
        if self._stack is not None:
            raise ModelError("rayleigh_rice with a film: the stack gives the indices")
        if not self._free:
            return self.N
        v = self.values(params)
        return complex(v["n_sub"], v["k_sub"])

    def is_reciprocal(self, params: Mapping[str, float] | None = None) -> bool:
        """True for unpolarized light (module docstring)."""
        return self._pol == "unpolarized"

    def psd2d(
        self, params: Mapping[str, float] | None = None
    ) -> Callable[[NDArray[np.float64], NDArray[np.float64]], NDArray[np.float64]]:
        """The PSD [m^4] of fx, fy [cycles/m] for ``params`` (default: current values)."""
        return psd_function(self._psd, self.values(params))

    def _wavelength_m(self, wavelength: NDArray | None) -> NDArray[np.float64]:
        if self._wl is not None:
            return np.asarray(self._wl * 1e-9)
        wl = None if wavelength is None else np.asarray(wavelength, float)
        if wl is None or wl.size == 0 or not np.all(np.isfinite(wl) & (wl > 0)):
            raise ModelError(
                "rayleigh_rice needs the wavelength: the data state none; give the option "
                "wavelength_nm=NM"
            )
        return wl * 1e-9

    def _evaluate(
        self,
        p: Mapping[str, float],
        theta_i: NDArray,
        theta_r: NDArray,
        phi_r: NDArray,
        wavelength: NDArray | None,
    ) -> NDArray:
        lam = np.broadcast_to(self._wavelength_m(wavelength), np.shape(theta_r))
        psd = psd_function(self._psd, p)
        index = complex(p["n_sub"], p["k_sub"]) if self._free else self.N
        up = (theta_i >= 0) & (theta_i <= math.pi / 2) & (theta_r >= 0) & (theta_r <= math.pi / 2)
        out = np.zeros(np.shape(theta_r))
        pol: Any = self._pol
        for w in np.unique(lam):
            sel = up & (lam == w)
            geometry = (theta_i[sel], theta_r[sel], phi_r[sel], float(w))
            if self._stack is None:
                out[sel] = brdf(*geometry, index, psd, pol)
            else:
                layers = self._layers(float(w))
                out[sel] = stack_brdf(*geometry, *layers, psd, self._interfaces, pol)
        return out

    def _layers(self, wavelength_m: float) -> tuple[NDArray, NDArray]:
        """The film stack's indices and thicknesses [m] at one wavelength [m]."""
        assert self._stack is not None
        wl_nm = wavelength_m * 1e9
        if self._range is not None and not self._range[0] <= wl_nm <= self._range[1]:
            lo, hi = self._range
            raise ModelError(
                f"rayleigh_rice: {wl_nm:g} nm lies outside the film fit's range "
                f"{lo:g}-{hi:g} nm; expected a film fit that covers the BRDF's wavelength"
            )
        try:
            return stack_layers(self._stack, wl_nm)
        except (ValueError, FilmError) as exc:
            raise ModelError(f"rayleigh_rice option 'film': {exc}") from None

    def mueller(
        self,
        theta_i: NDArray,
        theta_r: NDArray,
        phi_r: NDArray | float = math.pi,
        wavelength_nm: float | None = None,
        params: Mapping[str, float] | None = None,
    ) -> NDArray[np.float64]:
        """The Mueller BRDF (..., 4, 4) [sr^-1], LB convention (:func:`mueller_brdf`)."""
        lam = float(
            self._wavelength_m(None if wavelength_nm is None else np.asarray(wavelength_nm))
        )
        if self._stack is None:
            return mueller_brdf(
                theta_i, theta_r, phi_r, lam, self.index(params), self.psd2d(params)
            )
        psd = self.psd2d(params)
        layers = self._layers(lam)
        if self._interfaces == "correlated":
            return mueller_brdf_stack(theta_i, theta_r, phi_r, lam, *layers, psd, "correlated")
        m_if = layers[0].size - 1
        one = {"substrate": m_if - 1, "top": 0}.get(self._interfaces)
        psds = [psd if one is None or j == one else None for j in range(m_if)]
        return mueller_brdf_stack(theta_i, theta_r, phi_r, lam, *layers, psds)


def _film(
    film: Any, interfaces: str, n: float | None, k: float | None, free_index: bool
) -> tuple[Stack | None, tuple[float, float] | None, dict[str, Any]]:
    """The ``film`` option: its stack, the fit's wavelength range and the options to keep."""
    if interfaces not in INTERFACES:
        raise ModelError(
            f"rayleigh_rice option 'interfaces' must be one of {list(INTERFACES)}; "
            f"got {interfaces!r}"
        )
    if film is None:
        if interfaces != "correlated":
            raise ModelError("rayleigh_rice option 'interfaces' needs the option 'film'")
        return None, None, {}
    if n is not None or k is not None or free_index:
        raise ModelError(
            "rayleigh_rice: the film's stack gives the substrate's index; leave out n, k, "
            "free_index (and --nk-from)"
        )
    # a material named by a file (an n,k table, an ellipsometer file) is read as the film
    # commands read it; the reader sits in the files layer, below the models
    from ..nk.reading import tabulated_from_file

    rng: tuple[float, float] | None
    if isinstance(film, (Stack, Mapping)):  # a Stack, or its dict (the model's options)
        try:
            stack = film if isinstance(film, Stack) else Stack.from_dict(film, tabulated_from_file)
        except (FilmError, ValueError) as exc:
            raise ModelError(f"rayleigh_rice option 'film': {exc}") from None
        rng = None
        shown: Any = stack.to_dict()
    elif isinstance(film, (str, os.PathLike)):
        try:
            stack, rng = read_fit_json(film, tabulated_from_file)
        except FilmError as exc:
            raise ModelError(f"rayleigh_rice option 'film': {exc}") from None
        shown = os.fspath(film)
    else:
        raise ModelError(
            f"rayleigh_rice option 'film' must be a film fit JSON path or a Stack; got {film!r}"
        )
    try:
        stack_layers(stack, 0.5 * (rng[0] + rng[1]) if rng else 633.0)
    except (ValueError, FilmError) as exc:
        raise ModelError(f"rayleigh_rice option 'film': {exc}") from None
    return stack, rng, {"film": shown, "interfaces": interfaces}
