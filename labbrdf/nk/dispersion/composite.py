"""Sums of oscillator models: e.g. Tauc-Lorentz + Drude for a transparent conducting oxide."""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np
from numpy.typing import ArrayLike

from .base import ComplexArray, Dispersion, DispersionError, _sqrt_eps
from .drude import Drude
from .tauc_lorentz import TaucLorentz

#: ``<model><j>_<parameter>``: parameter of component ``j`` (from 1) of a sum
_PREFIXED = re.compile(r"^([a-z][a-z_]*[a-z])(\d+)_(.+)$")


def _model_class(name: str) -> type[Dispersion]:
    """The Dispersion subclass registered as ``name`` that can be a term of a sum."""
    todo = list(Dispersion.__subclasses__())
    seen: dict[str, type[Dispersion]] = {}
    while todo:
        sub = todo.pop()
        seen[sub.name] = sub
        todo.extend(sub.__subclasses__())
    cls = seen.get(name)
    if cls is None or cls is Sum or not _is_term(cls):
        terms = sorted(k for k, c in seen.items() if c is not Sum and _is_term(c))
        raise DispersionError(f"sum: {name!r} cannot be a term; terms are {terms}")
    return cls


def _is_term(cls: type[Dispersion]) -> bool:
    try:
        return "eps_inf" in cls().params
    except (TypeError, DispersionError):  # no valid default instance (a table)
        return False


@dataclass(frozen=True)
class Sum(Dispersion):
    """Sum of oscillator models: ``eps = eps_inf + sum_j (eps_j - eps_inf_j)``.

    Each term is a model with an ``eps_inf`` (``tauc_lorentz``, ``cody_lorentz``,
    ``drude``, ``lorentz``, ``gaussian``, ``bspline``); its own ``eps_inf`` is held at 0
    and the sum has one. The sum of Kramers-Kronig-consistent terms is consistent
    (the transform is linear). Parameters are the union of the terms' with the prefix
    ``<model><j>_`` (``j`` from 1): ``eps_inf, tauc_lorentz1_A, ..., drude2_omega_p, ...``.
    As a material it is named by its terms joined with ``+``: ``tauc_lorentz+drude``
    (:meth:`of`); ``sum`` alone is Tauc-Lorentz + a Drude term of ``omega_p = 2`` eV.

    Parameters
    ----------
    eps_inf : float
        [1]
    terms : tuple of Dispersion
        The terms (their ``eps_inf`` is set to 0).
    """

    name: ClassVar[str] = "sum"
    BOUNDS: ClassVar[dict[str, tuple[float, float]]] = {"eps_inf": (0.5, 10.0)}

    eps_inf: float = 1.0
    terms: tuple[Dispersion, ...] = field(
        default=(TaucLorentz(eps_inf=0.0), Drude(eps_inf=0.0, omega_p=2.0))
    )

    def __post_init__(self) -> None:
        terms = tuple(self.terms)
        if not terms:
            raise DispersionError("sum: needs at least one term")
        fixed = []
        for t in terms:
            _model_class(t.name)
            fixed.append(
                t
                if t.params["eps_inf"] == 0
                else type(t).from_params({**t.params, "eps_inf": 0.0})
            )
        object.__setattr__(self, "terms", tuple(fixed))

    @classmethod
    def of(cls, spec: str) -> Sum:
        """The sum ``"name+name+..."`` of the terms' default models, ``eps_inf = 1``."""
        names = [s.strip().lower() for s in spec.split("+")]
        return cls(terms=tuple(_model_class(n)() for n in names))

    @property
    def params(self) -> dict[str, float]:
        """name -> value of every parameter (plain floats)."""
        out = {"eps_inf": float(self.eps_inf)}
        for j, t in enumerate(self.terms, 1):
            out.update({f"{t.name}{j}_{k}": v for k, v in t.params.items() if k != "eps_inf"})
        return out

    @classmethod
    def from_params(cls, params: Mapping[str, float]) -> Sum:
        """A sum from ``params`` (``eps_inf`` and ``<model><j>_<parameter>`` names)."""
        p = dict(params)
        eps_inf = float(p.pop("eps_inf", 1.0))
        groups: dict[int, tuple[str, dict[str, float]]] = {}
        for key, value in p.items():
            m = _PREFIXED.match(key)
            if m is None or m.group(3) == "eps_inf":
                raise DispersionError(
                    f"sum: parameter {key!r}: expected eps_inf or <model><j>_<parameter> "
                    "(e.g. tauc_lorentz1_A), the terms' own eps_inf excluded"
                )
            model, j, sub = m.group(1), int(m.group(2)), m.group(3)
            if groups.setdefault(j, (model, {}))[0] != model:
                raise DispersionError(f"sum: term {j} is both {groups[j][0]} and {model}")
            groups[j][1][sub] = float(value)
        if sorted(groups) != list(range(1, len(groups) + 1)):
            raise DispersionError(f"sum: terms numbered {sorted(groups)}; expected 1, 2, ...")
        terms = tuple(
            _model_class(model).from_params({**sub, "eps_inf": 0.0})
            for model, sub in (groups[j] for j in sorted(groups))
        )
        return cls(eps_inf=eps_inf, terms=terms)

    def bounds(self) -> dict[str, tuple[float, float]]:
        """Default search box: ``eps_inf``'s and each term's, prefixed."""
        out = dict(self.BOUNDS)
        for j, t in enumerate(self.terms, 1):
            out.update({f"{t.name}{j}_{k}": b for k, b in t.bounds().items() if k != "eps_inf"})
        return out

    def units(self) -> dict[str, str]:
        """Units of every parameter."""
        out = {"eps_inf": "1"}
        for j, t in enumerate(self.terms, 1):
            out.update({f"{t.name}{j}_{k}": u for k, u in t.units().items() if k != "eps_inf"})
        return out

    def fixed_by_default(self) -> frozenset[str]:
        """The terms' fixed parameters, prefixed."""
        return frozenset(
            f"{t.name}{j}_{k}" for j, t in enumerate(self.terms, 1) for k in t.fixed_by_default()
        )

    def eps(self, wavelength_nm: ArrayLike) -> ComplexArray:
        """Dielectric function ``eps = N^2`` [1] at vacuum wavelength(s) [nm]."""
        out = self.eps_inf + sum(t.eps(wavelength_nm) for t in self.terms)
        return np.asarray(out, complex)

    def nk(self, wavelength_nm: ArrayLike) -> ComplexArray:
        """Complex index ``n + ik`` (``k >= 0``) at vacuum wavelength(s) [nm]."""
        return _sqrt_eps(self.eps(wavelength_nm))
