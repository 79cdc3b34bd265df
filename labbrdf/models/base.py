"""Parameters and the model base class shared by every reflectance/BRDF model.

Physics layer: numpy only (no pandas I/O, matplotlib or nlopt).
"""

from __future__ import annotations

import copy
import math
from abc import ABC, abstractmethod
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import LabbrdfError

__all__ = ["Model", "ModelError", "Parameter", "Parameters", "lambert"]


def lambert(theta_i: NDArray, theta_r: NDArray) -> NDArray:
    """Lambertian BRDF of unit albedo [sr^-1]: ``1 / pi`` above the surface, else 0.

    Both directions must be above the surface; the ``kd`` term of the models that have one.
    """
    up = (np.cos(theta_i) > 0) & (np.cos(theta_r) > 0)
    return np.where(up, 1.0 / np.pi, 0.0)


#: a detector azimuth within this of the specular half-plane (180 deg) is in the plane of
#: incidence [deg]: goniometers set the azimuth to well under a degree
PLANE_TOL_DEG = 1.0


class ModelError(LabbrdfError, ValueError):
    """Unknown model, option or parameter name, or an invalid parameter value."""


@dataclass
class Parameter:
    """One named model parameter (lmfit-like).

    Attributes
    ----------
    name : str
    value : float
        Current (initial, or fitted) value.
    min, max : float
        Bounds; global optimisers need both finite.
    vary : bool
        False keeps the parameter fixed at ``value`` during a fit.
    units : str
        Units in the labbrdf spelling: ``"1"``, ``"rad"``, ``"sr-1"``, ``"nm"``.
    log : bool
        Search on a log scale (needs ``min > 0``).
    description : str
    stderr : float or None
        1-sigma standard error, filled by a fit.
    ci95 : tuple of float or None
        95% interval, filled by a fit.
    correl : dict or None
        Correlation coefficients with the other varying parameters, filled by a fit.
    """

    name: str
    value: float
    min: float = -math.inf
    max: float = math.inf
    vary: bool = True
    units: str = "1"
    log: bool = False
    description: str = ""
    stderr: float | None = None
    ci95: tuple[float, float] | None = None
    correl: dict[str, float] | None = None

    def __post_init__(self) -> None:
        self.value = float(self.value)
        self.min = float(self.min)
        self.max = float(self.max)
        if self.min > self.max:
            raise ModelError(f"parameter {self.name!r}: min {self.min} > max {self.max}")
        if self.log and not self.min > 0:
            raise ModelError(f"parameter {self.name!r}: log scale needs min > 0")

    def check(self, value: Any) -> float:
        """``value`` as a float, if it is a finite number within ``[min, max]``.

        Parameters
        ----------
        value : float
            A value for this parameter (fixed, or a start), in its units.

        Returns
        -------
        float

        Raises
        ------
        ModelError
            ``value`` is not a number, is NaN or infinite, or lies outside the bounds;
            the message names the parameter and the allowed range.
        """
        allowed = f"{self.min:g} <= {self.name} <= {self.max:g}"
        try:
            v = float(value)
        except (TypeError, ValueError):
            raise ModelError(f"{self.name}={value!r}: expected a number, {allowed}") from None
        if not math.isfinite(v):
            raise ModelError(f"{self.name}={v!r}: expected a finite number, {allowed}")
        if not self.min <= v <= self.max:
            raise ModelError(f"{self.name}={v:g} is outside its bounds: expected {allowed}")
        return v

    def as_dict(self) -> dict[str, Any]:
        """JSON-safe dict."""
        return {
            "name": self.name,
            "value": self.value,
            "min": self.min,
            "max": self.max,
            "vary": self.vary,
            "units": self.units,
            "stderr": self.stderr,
            "ci95": list(self.ci95) if self.ci95 is not None else None,
        }


class Parameters(Mapping[str, Parameter]):
    """Ordered mapping name -> :class:`Parameter` with ``add``."""

    def __init__(self, params: Mapping[str, Parameter] | None = None) -> None:
        self._p: dict[str, Parameter] = dict(params or {})

    def add(
        self,
        name: str,
        value: float,
        min: float = -math.inf,
        max: float = math.inf,
        vary: bool = True,
        units: str = "1",
        **kw: Any,
    ) -> Parameter:
        """Add (or replace) the parameter ``name`` and return it (as lmfit's ``add``)."""
        p = Parameter(name, value, min, max, vary, units, **kw)
        self._p[name] = p
        return p

    def __getitem__(self, key: str) -> Parameter:
        try:
            return self._p[key]
        except KeyError:
            raise ModelError(
                f"unknown parameter {key!r}; parameters are {list(self._p)}"
            ) from None

    def __iter__(self) -> Iterator[str]:
        return iter(self._p)

    def __contains__(self, key: object) -> bool:
        return key in self._p

    def __len__(self) -> int:
        return len(self._p)

    def __repr__(self) -> str:
        inner = ", ".join(f"{k}={p.value:.6g}" for k, p in self._p.items())
        return f"Parameters({inner})"

    def copy(self) -> Parameters:
        """A deep copy (the parameters are independent of this set's)."""
        return Parameters(copy.deepcopy(self._p))

    def values(self) -> dict[str, float]:  # type: ignore[override]
        """name -> value (plain floats)."""
        return {k: p.value for k, p in self._p.items()}

    def varying(self) -> list[str]:
        """Names of the parameters that vary in a fit."""
        return [k for k, p in self._p.items() if p.vary]


class Model(ABC):
    """A reflectance/BRDF model: named parameters, a vectorised ``evaluate``, metadata.

    Subclasses set the class attributes and implement :meth:`_evaluate` (and
    :meth:`linear_components` when every term is linear in some parameters).

    Angles are in radians here, as in the papers; ``phi_r`` is the outward azimuth of the
    detector with the source at 0, so ``phi_r = pi`` is the specular half-plane.
    """

    #: registry name
    name: str = ""
    #: citation and DOI of the formula
    reference: str = ""
    doi: str = ""
    #: names of parameters that enter linearly (may be profiled out by least squares)
    linear: tuple[str, ...] = ()
    #: parameters that only shape the lobe away from the specular line: a fit to points on
    #: theta_r == theta_i alone cannot identify them (the fitting core refuses to vary them)
    specular_line_shape: tuple[str, ...] = ()
    #: dataset quantities the model describes (a fit to other data is refused): reflection
    #: models take BRDF and specular data, a transmission form ``("btdf",)``
    quantities: tuple[str, ...] = ("brdf", "specular_intensity")
    #: what the model's form says about reciprocity, a sentence for reports
    reciprocity_note: str = ""
    #: smallest step, as a fraction of a parameter's search range, at which finite
    #: differences of the model are meaningful; None for a smooth (closed-form) model. A
    #: Monte Carlo model with common random numbers is smooth only on larger scales (a ray
    #: that changes bin makes a small jump), so the fitter's difference steps and local
    #: tolerances are kept at or above it
    fd_rel_step: float | None = None
    #: the model's value carries a Monte Carlo error fixed by a seed (common random
    #: numbers): its fits are repeated over independent seeds (:meth:`reseeded`,
    #: :func:`labbrdf.fitting.fit` ``replicates``) to measure the estimate's seed spread
    stochastic: bool = False
    #: seed replicates of a fit when none are asked for (``fit(replicates=None)``)
    default_replicates: int = 1
    #: the geometry the model describes: ``"hemisphere"`` (any detector direction) or
    #: ``"specular_plane"`` (the plane of incidence on the specular side, detector azimuth
    #: phi_r = 180 deg: an in-plane model that ignores the azimuth). :meth:`outside_domain`
    #: tells a fit whose points lie outside it
    domain: str = "hemisphere"

    def __init__(self, **options: Any) -> None:
        self.options: dict[str, Any] = dict(options)
        self.params: Parameters = self.default_params()

    def outside_domain(self, theta_i_deg: ArrayLike, phi_r_deg: ArrayLike) -> str | None:
        """Why the points lie outside the model's :attr:`domain`, or None when they do not.

        Parameters
        ----------
        theta_i_deg, phi_r_deg : array_like
            Incidence angle and outward detector azimuth (source at 0) of every point [deg].

        Returns
        -------
        str or None
            For a ``"specular_plane"`` model: how many points lie more than
            :data:`PLANE_TOL_DEG` out of the specular half-plane and what to do instead.
        """
        if self.domain != "specular_plane":
            return None
        phi = np.broadcast_to(np.asarray(phi_r_deg, float), np.shape(theta_i_deg))
        off = np.abs((phi - 180.0 + 180.0) % 360.0 - 180.0) > PLANE_TOL_DEG
        off &= np.asarray(theta_i_deg, float) > 0  # at normal incidence any azimuth is in-plane
        if not off.any():
            return None
        return (
            f"{int(off.sum())} of {off.size} points lie out of the plane of incidence "
            f"(detector azimuth more than {PLANE_TOL_DEG:g} deg from 180 deg): {self.name} is "
            "a specular-plane model that ignores the azimuth, so its value there is the "
            "in-plane curve, not a prediction; fit the in-plane points only (select "
            "phi_r_deg = 180) or a hemispherical model (microfacet, five_param)"
        )

    def reseeded(self, seed: int) -> Model:
        """The same model with the Monte Carlo seed ``seed`` (stochastic models only).

        Raises
        ------
        ModelError
            The model is deterministic: it has no seed to change.
        """
        raise ModelError(
            f"model {self.name!r} is deterministic (no Monte Carlo seed): it has no seed "
            "replicates"
        )

    # ---------------------------------------------------------------- to implement
    @abstractmethod
    def default_params(self) -> Parameters:
        """Fresh Parameters with default values and the recommended bounds."""

    @abstractmethod
    def _evaluate(
        self,
        p: Mapping[str, float],
        theta_i: NDArray,
        theta_r: NDArray,
        phi_r: NDArray,
        wavelength: NDArray | None,
    ) -> NDArray:
        """The BRDF [sr^-1] for parameter values ``p`` (broadcast arrays, radians)."""

    def linear_components(
        self,
        p: Mapping[str, float],
        theta_i: NDArray,
        theta_r: NDArray,
        phi_r: NDArray,
        wavelength: NDArray | None,
    ) -> dict[str, NDArray] | None:
        """Basis functions b_j with f = sum_j p[j] * b_j over :attr:`linear`, or None."""
        return None

    def point_variance(
        self,
        p: Mapping[str, float],
        theta_i: NDArray,
        theta_r: NDArray,
        phi_r: NDArray,
        wavelength: NDArray | None,
    ) -> NDArray | None:
        """The model's own variance at every point [sr^-2] (Monte Carlo models), or None.

        A fit weighted by the data's sigma adds it to sigma^2 (in quadrature), so the
        residual weights and the reported uncertainties carry the model's noise. The
        default (a closed-form model) has none.
        """
        return None

    def point_noise(
        self,
        p: Mapping[str, float],
        theta_i: NDArray,
        theta_r: NDArray,
        phi_r: NDArray,
        wavelength: NDArray | None,
    ) -> NDArray | None:
        """Components n_k (K, ...) of the model's own noise [sr^-1], or None.

        The noise covariance between points is ``sum_k n_k n_k^T`` (its diagonal is
        :meth:`point_variance`). A fit weighted by the data's sigma uses it for the
        parameters' covariance (``labbrdf.fitting.uncertainty.noise_meat``). The default
        (a closed-form model) has none.
        """
        return None

    def is_reciprocal(self, params: Mapping[str, float] | None = None) -> bool:
        """Whether f(i, r) == f(r, i) for these parameter values."""
        return False

    def guess(self, theta_i: NDArray, theta_r: NDArray, value: NDArray) -> dict[str, float]:
        """Data-driven starting values (name -> value) from measured points, or ``{}``.

        ``theta_i``, ``theta_r`` [rad] and ``value`` (the measured BRDF [sr^-1]) are flat
        arrays of the points to be fitted. The fitting core's global stage keeps this point
        in its population, so a guess can only help. The default has none.
        """
        return {}

    def hemispherical(
        self, theta_i_deg: ArrayLike, params: Mapping[str, float] | None = None
    ) -> NDArray[np.float64] | None:
        """Closed-form directional-hemispherical reflectance [1], or None where there is none.

        :func:`labbrdf.integrate.hemispherical_reflectance` uses it when it exists and
        integrates the BRDF by quadrature otherwise.
        """
        return None

    # ---------------------------------------------------------------- public
    def values(self, params: Mapping[str, float] | Parameters | None = None) -> dict[str, float]:
        """Current values, updated from ``params`` (a mapping name -> value or Parameters)."""
        vals = self.params.values()
        if params is not None:
            for k, v in params.items():
                if k not in vals:
                    raise ModelError(
                        f"model {self.name!r} has no parameter {k!r}; parameters are {list(vals)}"
                    )
                vals[k] = float(v.value if isinstance(v, Parameter) else v)
        return vals

    def check_value(self, name: str, value: Any) -> float:
        """``value`` for the parameter ``name``, checked against its declared bounds.

        Every value a caller fixes or starts a parameter at goes through this check (the
        fitting core's :func:`~labbrdf.fitting.parameters.setup_params`), so a value the model
        was not made for never reaches its formula.

        Parameters
        ----------
        name : str
            A parameter of this model.
        value : float
            Its value, in the parameter's units.

        Returns
        -------
        float

        Raises
        ------
        ModelError
            An unknown name, or a value that is not finite or lies outside
            ``[min, max]`` (the message names the model, the parameter and the range).
        """
        if name not in self.params:
            raise ModelError(
                f"model {self.name!r} has no parameter {name!r}; parameters are "
                f"{list(self.params)}"
            )
        try:
            return self.params[name].check(value)
        except ModelError as exc:
            raise ModelError(f"model {self.name!r}: {exc}") from None

    def evaluate(
        self,
        theta_i: ArrayLike,
        theta_r: ArrayLike,
        phi_r: ArrayLike = np.pi,
        wavelength: ArrayLike | None = None,
        params: Mapping[str, float] | Parameters | None = None,
    ) -> NDArray[np.float64]:
        """The BRDF [sr^-1] at incidence ``theta_i`` and detector (``theta_r``, ``phi_r``) [rad].

        Inputs broadcast against each other; ``params`` overrides current values.
        """
        p = self.values(params)
        ti, tr, pr = np.broadcast_arrays(
            np.asarray(theta_i, float), np.asarray(theta_r, float), np.asarray(phi_r, float)
        )
        wl = None if wavelength is None else np.asarray(wavelength, float)
        return np.asarray(self._evaluate(p, ti, tr, pr, wl), dtype=float)

    __call__ = evaluate

    def describe(self) -> dict[str, Any]:
        """JSON-safe description: name, options, reference, DOI, parameters."""
        return {
            "model": self.name,
            "options": {
                k: (v if isinstance(v, str | int | float | bool | type(None)) else repr(v))
                for k, v in self.options.items()
            },
            "reference": self.reference,
            "doi": self.doi,
            "params": [self.params[k].as_dict() for k in self.params],
        }

    def __repr__(self) -> str:
        opts = ", ".join(f"{k}={v!r}" for k, v in self.options.items())
        return f"{type(self).__name__}({opts})"
