"""One homogeneous layer of a stack: a material and a thickness."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from .limits import FilmError
from .materials import as_material


@dataclass(frozen=True)
class Layer:
    """One homogeneous layer.

    Parameters
    ----------
    material : Dispersion, Roughness, number or str
        See :func:`as_material`.
    thickness_nm : float
        Physical thickness >= 0 [nm].
    name : str
        Unique within a stack; default ``layer1``, ``layer2``, ... from the top.
    coherent : bool
        ``False`` for a thick layer whose multiple reflections add in intensity
        (:mod:`labbrdf.films.incoherent`): a glass slide, a thick sheet.
    """

    material: Any
    thickness_nm: float
    name: str = ""
    coherent: bool = True

    def __post_init__(self) -> None:
        object.__setattr__(self, "material", as_material(self.material))
        d = float(self.thickness_nm)
        if not (math.isfinite(d) and d >= 0):
            raise FilmError(f"layer {self.name!r}: thickness_nm must be >= 0, got {d}")
        object.__setattr__(self, "thickness_nm", d)
        if not isinstance(self.coherent, bool):
            raise FilmError(f"layer {self.name!r}: coherent must be True or False")

    @property
    def params(self) -> dict[str, float]:
        """``thickness_nm`` and the material's parameters."""
        return {"thickness_nm": self.thickness_nm, **self.material.params}

    def to_dict(self) -> dict[str, Any]:
        """JSON-safe form (``coherent`` only when false)."""
        out = {
            "name": self.name,
            "thickness_nm": self.thickness_nm,
            "material": self.material.to_dict(),
        }
        return out if self.coherent else {**out, "coherent": False}
