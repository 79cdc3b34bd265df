"""A layer's material: a dispersion model, a reference or file table, a number, or a mixture.

:func:`as_material` turns what a user writes (a :class:`~labbrdf.nk.dispersion.Dispersion`,
a number, a name, a dict) into one; :class:`Roughness` is the Bruggeman effective medium of
the material below and the ambient, :class:`~labbrdf.films.ema.Ema` that of two or three
named constituents (``"ema(@film, void)"``).

A material named by a file (``{"model": "tabulated", "file": PATH}``) is read by the
caller's :data:`TableReader` (e.g. :func:`labbrdf.nk.tabulated_from_file`, which reads
ellipsometer exports through the instrument readers, a layer above the films): the films
never open such a file themselves.
"""

from __future__ import annotations

import os
import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from ..nk import dispersion as disp
from .ema import VOID, Ema
from .graded import Graded
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


Material = disp.Dispersion | Roughness | Ema | Graded

#: reads a material's table or ellipsometer file into its ``n, k``; supplied by whoever
#: builds a stack from a model file or a fit JSON (:func:`labbrdf.nk.tabulated_from_file`)
TableReader = Callable[[str | os.PathLike[str]], disp.Tabulated]

_EMA_NAME = re.compile(r"^ema\((.*)\)$")


def _constituent(c: Any, read_table: TableReader | None) -> disp.Dispersion | str:
    """An EMA constituent: ``void`` and ``@NAME`` stay strings, the rest a dispersion."""
    if isinstance(c, str) and (c.strip().lower() == VOID or c.strip().startswith("@")):
        return c.strip()
    m = as_material(c, read_table)
    if not isinstance(m, disp.Dispersion):
        raise FilmError(f"ema: constituent {c!r} is {m.name}; expected a material")
    return m


def _ema(m: Mapping[str, Any], read_table: TableReader | None = None) -> Ema:
    comps = m.get("components")
    if not isinstance(comps, (list, tuple)):
        raise FilmError("ema: expected components = [2 or 3 constituents]")
    bad = sorted(set(m) - {"model", "components", "fraction", "fraction3"})
    if bad:
        raise FilmError(f"ema: unknown key(s) {bad}; expected components, fraction, fraction3")
    fr = {k: m[k] for k in ("fraction", "fraction3") if k in m}
    for k, v in fr.items():
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            raise FilmError(f"ema: {k} must be a number, got {v!r}")
    return Ema(
        tuple(_constituent(c, read_table) for c in comps), **{k: float(v) for k, v in fr.items()}
    )


def as_material(m: Any, read_table: TableReader | None = None) -> Material:
    """A material from a Dispersion, a number, a table name, a model name or a dict.

    Numbers are constant indices; names are reference tables (``"si"``, ``"sio2"``) or
    registry names (default parameters).

    Parameters
    ----------
    m : Dispersion, Roughness, Ema, Graded, number, str or mapping
        The material as written (a mapping is a ``to_dict`` form).
    read_table : callable, optional
        Reads a ``{"model": "tabulated", "file": PATH}`` material (and such a constituent
        of a mixture or base of a graded material), e.g.
        :func:`labbrdf.nk.tabulated_from_file`. Without it such a material is refused.

    Raises
    ------
    FilmError
        An unknown name or form, or a file material without ``read_table``.
    """
    if isinstance(m, (disp.Dispersion, Roughness, Ema, Graded)):
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
        ema = _EMA_NAME.match(key)
        if ema:
            return _ema({"components": [c.strip() for c in ema.group(1).split(",")]})
        if key in disp.MODELS and key != "tabulated":
            return disp.MODELS[key]()
        if "+" in key:  # a sum of oscillator models, e.g. tauc_lorentz+drude
            return disp.Sum.of(key)
        raise FilmError(
            f"unknown material {m!r}: expected a reference table {sorted(disp.REFERENCE_TABLES)}, "
            f"a dispersion model {sorted(k for k in disp.MODELS if k != 'tabulated')}, "
            "'roughness' or 'ema(A, B[, C])' (constituents: materials, void, @LAYER)"
        )
    if isinstance(m, Mapping):
        model = str(m.get("model", "")).lower()
        if model == "roughness":
            return Roughness(float(m.get("fraction", 0.5)))
        if model == "ema":
            return _ema(m, read_table)
        if model == "graded":
            return _graded(m, read_table)
        if model == "tabulated" and "file" in m:
            return _table_file(str(m["file"]), read_table)
        return disp.from_dict(m)
    raise FilmError(f"material: expected a dispersion model, a number or a name, got {m!r}")


def _graded(m: Mapping[str, Any], read_table: TableReader | None) -> Graded:
    bad = sorted(set(m) - {"model", "base", "parameter", "top", "bottom", "shape", "sublayers"})
    if bad or not {"base", "parameter", "top", "bottom"} <= set(m):
        raise FilmError(
            f"graded: expected base, parameter, top, bottom (shape, sublayers); got {sorted(m)}"
        )
    base = as_material(m["base"], read_table)
    try:
        return Graded(
            base,
            str(m["parameter"]),
            float(m["top"]),
            float(m["bottom"]),
            float(m.get("shape", 1.0)),
            m.get("sublayers", 20),
        )
    except (TypeError, ValueError) as exc:
        raise FilmError(f"graded: {exc}") from None


def _table_file(path: str | os.PathLike[str], read_table: TableReader | None) -> disp.Tabulated:
    """A table or ellipsometer file's ``n, k``, read by the caller's ``read_table``."""
    if read_table is None:
        raise FilmError(
            f"material file {os.fspath(path)!r}: no table reader was given; pass "
            "read_table=labbrdf.nk.tabulated_from_file to read n,k tables and ellipsometer files"
        )
    return read_table(path)


def _with_params(m: Material, values: Mapping[str, float]) -> Material:
    if not values:
        return m
    if isinstance(m, Roughness):
        return Roughness(float(values.get("fraction", m.fraction)))
    if isinstance(m, (Ema, Graded)):
        return m.with_params(values)
    return type(m).from_params({**m.params, **values})
