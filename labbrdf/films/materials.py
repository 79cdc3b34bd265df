"""A layer's material: a dispersion model, a reference or file table, a number, or roughness.

:func:`as_material` turns what a user writes (a :class:`~labbrdf.nk.dispersion.Dispersion`,
a number, a name, a dict) into one; :class:`Roughness` is the Bruggeman effective medium of
the material below and the ambient.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from ..nk import dispersion as disp
from .limits import FilmError


@dataclass(frozen=True)
class Roughness:
    """Bruggeman effective-medium roughness layer material.

    A ``fraction`` of the medium below, the rest ambient (Aspnes, Theeten & Hottier,
    Phys. Rev. B 20, 3292 (1979); the default 0.5 is
    theirs). Used as a :class:`Layer` material; evaluated by :meth:`Stack.indices`.
    """

    fraction: float = 0.5
    name = "roughness"

    def __post_init__(self) -> None:
        if not 0.0 <= self.fraction <= 1.0:
            raise FilmError(f"roughness: fraction must be in [0, 1], got {self.fraction}")

    @property
    def params(self) -> dict[str, float]:
        """name -> value."""
        return {"fraction": float(self.fraction)}

    def bounds(self) -> dict[str, tuple[float, float]]:
        """Default search box."""
        return {"fraction": (0.0, 1.0)}

    def units(self) -> dict[str, str]:
        """Units of every parameter."""
        return {"fraction": "1"}

    def to_dict(self) -> dict[str, Any]:
        """JSON-safe form."""
        return {"model": "roughness", "fraction": float(self.fraction)}


Material = disp.Dispersion | Roughness


def as_material(m: Any) -> Material:
    """A material from a Dispersion, a number, a table name, a model name or a dict.

    Numbers are constant indices; names are reference tables (``"si"``, ``"sio2"``) or
    registry names (default parameters).
    """
    if isinstance(m, (disp.Dispersion, Roughness)):
        return m
    if isinstance(m, (int, float, complex)) and not isinstance(m, bool):
        c = complex(m)
        return disp.Constant(c.real, c.imag)
    if isinstance(m, str):
        key = m.lower().strip()
        if key in disp.REFERENCE_TABLES:
            return disp.Tabulated.reference(key)
        if key == "roughness":
            return Roughness()
        if key in disp.MODELS and key != "tabulated":
            return disp.MODELS[key]()
        if "+" in key:  # a sum of oscillator models, e.g. tauc_lorentz+drude
            return disp.Sum.of(key)
        raise FilmError(
            f"unknown material {m!r}: expected a reference table {sorted(disp.REFERENCE_TABLES)}, "
            f"a dispersion model {sorted(k for k in disp.MODELS if k != 'tabulated')} or "
            "'roughness'"
        )
    if isinstance(m, Mapping):
        model = str(m.get("model", "")).lower()
        if model == "roughness":
            return Roughness(float(m.get("fraction", 0.5)))
        if model == "tabulated" and "file" in m:
            return _table_file(str(m["file"]))
        return disp.from_dict(m)
    raise FilmError(f"material: expected a dispersion model, a number or a name, got {m!r}")


def _table_file(path: str | os.PathLike[str]) -> disp.Tabulated:
    """A table or ellipsometer file's ``n, k`` (:func:`labbrdf.nk.tabulated_from_file`)."""
    from ..nk.reading import tabulated_from_file  # the dataset layer: pandas and the adapters

    return tabulated_from_file(path)


def _with_params(m: Material, values: Mapping[str, float]) -> Material:
    if not values:
        return m
    if isinstance(m, Roughness):
        return Roughness(float(values.get("fraction", m.fraction)))
    return type(m).from_params({**m.params, **values})
