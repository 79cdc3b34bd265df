"""One homogeneous layer of a stack, and the one grammar and rule for a layer's values."""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from ..nk import dispersion as disp
from .graded import Graded
from .limits import MAX_THICKNESS_NM, FilmError
from .materials import _with_params, as_material


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


# --------------------------------------------------------------------------- a layer's values
#
# One grammar and one rule for the values of a layer, shared by the model file (TOML,
# :func:`labbrdf.films.load_model`) and the command line (``labbrdf film --layer``):
#
# - a parameter written as a number is fixed at it (TOML ``A = 1.9``, ``--layer ...:A=1.9``);
# - a parameter written as a box is fitted in it, started mid-box (TOML ``A = [1.5, 2.2]``,
#   ``--layer ...:A=1.5..2.2``; TOML also ``{value, min, max, vary}``);
# - a parameter of a layer's material (a dispersion model, a roughness layer's fraction)
#   that is not written is fitted in its default box (:func:`default_boxes`), started at the
#   model's default value, except those the model fixes by default (Cauchy's absorption,
#   a B-spline's knot range: ``Dispersion.fixed_by_default``); a table has
#   none. The substrate's parameters stay at their values unless a box is written.


def default_boxes(material: Any) -> dict[str, tuple[float, float]]:
    """The default search box of each parameter a layer's material frees when not written.

    Every parameter of a dispersion model (:meth:`labbrdf.nk.dispersion.Dispersion.bounds`)
    except those it fixes by default
    (:meth:`labbrdf.nk.dispersion.Dispersion.fixed_by_default`: Cauchy's absorption, a
    B-spline's knot range), and a roughness layer's fraction
    (:meth:`labbrdf.films.Roughness.bounds`); none for a table.
    """
    if isinstance(material, disp.Tabulated) or not hasattr(material, "bounds"):
        return {}
    fixed = getattr(material, "fixed_by_default", None)
    skip = fixed() if callable(fixed) else frozenset()
    return {k: b for k, b in material.bounds().items() if k not in skip}


def free_parameters(
    layer: Layer, written: Mapping[str, tuple[float, float] | None]
) -> dict[str, tuple[float, float]]:
    """The fitted parameters of a layer, ``"<layer>.<name>"`` -> (min, max).

    Parameters
    ----------
    layer : Layer
        The layer, with the values written for it.
    written : mapping
        Each parameter written for the layer (``thickness_nm`` included) -> its box, or
        None where it is written as a number (fixed).

    Returns
    -------
    dict
        The written boxes (in their order), then the default box of every material
        parameter not written (:func:`default_boxes`).
    """
    free = {k: b for k, b in written.items() if b is not None}
    free.update({k: b for k, b in default_boxes(layer.material).items() if k not in written})
    return {f"{layer.name}.{k}": b for k, b in free.items()}


def parse_value(text: str, where: str) -> tuple[float, tuple[float, float] | None]:
    """``V`` (fixed) or ``LO..HI`` (fitted, started mid-box), the command line's value.

    Raises
    ------
    FilmError
        Not a number or a box, or impossible bounds (the message starts with ``where``).
    """
    lo_s, sep, hi_s = text.partition("..")
    try:
        if not sep:
            return float(text), None
        lo, hi = float(lo_s), float(hi_s)
    except ValueError:
        raise FilmError(f"{where}: {text!r} is not a number or LO..HI") from None
    if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
        raise FilmError(f"{where}: impossible bounds {text!r} (need LO < HI)")
    return (lo + hi) / 2, (lo, hi)


LAYER_KEYWORDS = "incoherent, graded=PARAM, sublayers=N"
"""The keyword fields of a ``--layer`` beside its parameters (the TOML keys ``coherent =
false``, ``graded = "PARAM"``, ``sublayers = N``)."""


def _keywords(fields: list[str], name: str) -> tuple[dict[str, Any], list[str]]:
    """The keyword fields of a layer (``incoherent``, ``graded=P``, ``sublayers=N``), the rest."""
    kw: dict[str, Any] = {}
    rest = []
    for item in fields:
        key, sep, val = item.partition("=")
        if key == "incoherent":
            if sep:
                raise FilmError(f"{name}: {item!r}: expected 'incoherent' alone (no value)")
            kw["coherent"] = False
        elif key == "graded":
            if not val:
                raise FilmError(
                    f"{name}: {item!r}: expected graded=PARAM (the parameter that varies)"
                )
            kw["graded"] = val
        elif key == "sublayers":
            try:
                kw["sublayers"] = int(val)
            except ValueError:
                raise FilmError(f"{name}: {item!r}: expected sublayers=N, an integer") from None
        else:
            rest.append(item)
    if "sublayers" in kw and "graded" not in kw:
        raise FilmError(f"{name}: sublayers=N needs graded=PARAM (the parameter that varies)")
    return kw, rest


def _graded(m: Any, kw: Mapping[str, Any], name: str) -> Any:
    """The material graded in ``kw["graded"]`` (top = bottom = its value, linear), or ``m``."""
    p = kw.get("graded")
    if p is None:
        return m
    if isinstance(m, Graded) or p not in getattr(m, "params", {}):
        raise FilmError(
            f"{name}: graded={p}: expected one of the parameters of {m.name}: "
            f"{sorted(getattr(m, 'params', {})) or 'none (a table)'}"
        )
    try:
        return Graded(m, p, m.params[p], m.params[p], 1.0, kw.get("sublayers", 20))
    except FilmError as exc:
        raise FilmError(f"{name}: {exc}") from None


def parse_layer(
    spec: str, j: int, material_of: Callable[[str], Any]
) -> tuple[Layer, dict[str, tuple[float, float]]]:
    """A layer and its fitted parameters from ``NAME:MATERIAL:THICKNESS[:FIELD ...]``.

    Each FIELD is ``PARAM=V`` (fixed), ``PARAM=LO..HI`` (fitted) or a keyword: ``incoherent``
    (a thick layer added in intensity, TOML ``coherent = false``), ``graded=PARAM`` (that
    parameter varies through the layer from ``PARAM_top`` to ``PARAM_bottom``, TOML
    ``graded = "PARAM"``) and ``sublayers=N`` (its slices, default 20).

    Parameters
    ----------
    spec : str
        The layer, e.g. ``"oxide:cauchy:0..20:A=1.3..1.7"`` (an empty name is ``layer<j>``),
        ``"glass:sio2:1e6:incoherent"``, ``"f:cauchy:100..300:graded=A:A_top=1.9..2.3"``.
    j : int
        Its place from the top, from 1.
    material_of : callable
        The material of the MATERIAL field (a name, or a table file read by the caller).

    Returns
    -------
    (Layer, dict)
        The layer (its values, mid-box where a box is given) and its fitted parameters
        (:func:`free_parameters`: unwritten dispersion parameters free in their default
        box).

    Raises
    ------
    FilmError
        A malformed field, an unknown parameter, a bad value (the message starts with the
        layer's name).
    """
    fields = spec.split(":")
    if len(fields) < 3:
        raise FilmError(
            f"{spec!r}: expected NAME:MATERIAL:THICKNESS[:PARAM=V|LO..HI ...], "
            "e.g. oxide:cauchy:0..20:A=1.3..1.7"
        )
    name, mat, thick = fields[0] or f"layer{j}", fields[1], fields[2]
    d, dbox = parse_value(thick, f"{name}: thickness")
    kw, items = _keywords(fields[3:], name)
    try:
        m = material_of(mat)
    except ValueError as exc:
        raise FilmError(f"{name}: {exc}") from None
    m = _graded(m, kw, name)
    values: dict[str, float] = {}
    written: dict[str, tuple[float, float] | None] = {}
    for item in items:
        key, sep, val = item.partition("=")
        if not sep or key not in m.params:
            raise FilmError(
                f"{name}: {item!r}: expected PARAM=V or PARAM=LO..HI with PARAM "
                f"one of {sorted(m.params) or 'none (a table)'}, or a keyword "
                f"({LAYER_KEYWORDS})"
            )
        values[key], written[key] = parse_value(val, f"{name}: {key}")
    try:
        layer = Layer(_with_params(m, values), d, name, kw.get("coherent", True))
    except ValueError as exc:
        raise FilmError(f"{name}: {exc}") from None
    return layer, free_parameters(layer, {**written, "thickness_nm": dbox})


#: the stack-wide values of the command line: option -> (Stack keyword, largest value)
STACK_OPTIONS = {
    "--thickness-spread": ("thickness_spread", 0.1),
    "--bandwidth": ("bandwidth_nm", 20.0),
    "--angle-spread": ("angle_spread_deg", 2.0),
    "--substrate-thickness": ("substrate_thickness_nm", MAX_THICKNESS_NM),
}


def parse_stack_values(
    written: Mapping[str, str | None],
) -> tuple[dict[str, float], dict[str, tuple[float, float]]]:
    """The stack-wide values of the command line (``--bandwidth 0..5`` ...).

    The grammar of :func:`parse_value`, the ranges of ``labbrdf.films.Stack``.

    Parameters
    ----------
    written : mapping
        Option (a key of :data:`STACK_OPTIONS`) -> its text, or None where not given.

    Returns
    -------
    (dict, dict)
        The :class:`Stack` keywords and the fitted parameters (``"stack.bandwidth_nm"``,
        ``"substrate.thickness_nm"`` -> box).

    Raises
    ------
    FilmError
        A value that is not a number or a box, or outside its range (naming the option).
    """
    kw: dict[str, float] = {}
    free: dict[str, tuple[float, float]] = {}
    for opt, text in written.items():
        if text is None:
            continue
        key, top = STACK_OPTIONS[opt]
        v, box = parse_value(text, opt)
        lo, hi = box or (v, v)
        low_ok = lo > 0 if key == "substrate_thickness_nm" else lo >= 0
        if not (low_ok and hi <= top):
            kind = "(0" if key == "substrate_thickness_nm" else "[0"
            raise FilmError(f"{opt} {text}: expected a value or LO..HI in {kind}, {top:g}]")
        kw[key] = v
        if box is not None:
            owner = "substrate.thickness_nm" if key == "substrate_thickness_nm" else f"stack.{key}"
            free[owner] = box
    return kw, free
