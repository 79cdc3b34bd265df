"""JSON-safe copies of plain results, and the check of a JSON file labbrdf reads back.

:func:`jsonable` is the one sanitiser of the CLI, the fits, the report and the
height-map statistics; :func:`check_schema` checks a document against a small explicit
schema (the fit JSON of :mod:`labbrdf.films`) before any value of it is used, so that a
hand-edited file is refused by its key, never met as a ``TypeError`` deep inside.

Low-level: imports numpy only, so that every layer may use it.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["SchemaError", "check_schema", "jsonable"]


def jsonable(x: Any) -> Any:
    """A JSON-safe copy of ``x`` (``json.dumps(..., allow_nan=False)`` accepts it).

    Mappings become dicts with string keys, lists/tuples/arrays become lists, numpy
    scalars become Python numbers, NaN and infinities become None, paths and any other
    object become their ``str``.

    Parameters
    ----------
    x : Any
        A value built from mappings, sequences, numbers, strings and arrays.

    Returns
    -------
    Any
        The copy.
    """
    if isinstance(x, Mapping):
        return {str(k): jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [jsonable(v) for v in x]
    if isinstance(x, np.ndarray):
        return jsonable(x.tolist())
    if isinstance(x, (bool, np.bool_)):
        return bool(x)
    if isinstance(x, (int, np.integer)):
        return int(x)
    if isinstance(x, (float, np.floating)):
        v = float(x)
        return v if math.isfinite(v) else None
    if x is None or isinstance(x, str):
        return x
    if isinstance(x, Path):
        return str(x)
    return str(x)


class SchemaError(ValueError):
    """A JSON document that does not follow its schema; the message names the key."""


_TYPES: dict[str, tuple[type, ...]] = {
    "object": (dict,),
    "array": (list,),
    "string": (str,),
    "number": (int, float),
    "integer": (int,),
    "boolean": (bool,),
}

_NAMES = {
    "object": "an object",
    "array": "an array",
    "string": "a string",
    "number": "a number",
    "integer": "an integer",
    "boolean": "true or false",
}


def _kind(x: Any) -> str:
    for name in ("boolean", "integer", "number", "string", "array", "object"):
        if isinstance(x, _TYPES[name]):
            return _NAMES[name]
    return "null" if x is None else type(x).__name__


def _check_number(x: float, schema: Mapping[str, Any], at: str) -> None:
    try:
        v = float(x)
    except OverflowError:  # an integer beyond any float
        v = math.inf
    if not math.isfinite(v):
        raise SchemaError(f"{at}: expected a finite number, got {x!r:.40}")
    lo, hi = schema.get("min"), schema.get("max")
    if (lo is not None and v < lo) or (hi is not None and v > hi):
        rng = f"[{lo:g}, {hi:g}]" if lo is not None and hi is not None else ""
        rng = rng or (f">= {lo:g}" if lo is not None else f"<= {hi:g}")
        raise SchemaError(f"{at}: expected a number {'in ' if '[' in rng else ''}{rng}, got {v:g}")


def _check_object(x: dict, schema: Mapping[str, Any], at: str) -> None:
    props: Mapping[str, Any] = schema.get("properties", {})
    for key in schema.get("required", ()):
        if key not in x:
            raise SchemaError(f"{at}: missing the key {key!r}")
    extra = schema.get("additional", True)
    for key, value in x.items():
        sub = props.get(key, extra)
        if sub is False:
            raise SchemaError(f"{at}: unknown key {key!r}; expected {sorted(props)}")
        if sub is not True:
            check_schema(value, sub, f"{at}.{key}" if at else key)


def _check_array(x: list, schema: Mapping[str, Any], at: str) -> None:
    lo, hi = schema.get("min_items", 0), schema.get("max_items")
    if len(x) < lo or (hi is not None and len(x) > hi):
        want = f"exactly {lo}" if lo == hi else f"{lo} to {hi:,}" if hi is not None else f">= {lo}"
        raise SchemaError(f"{at}: expected {want} items, got {len(x):,}")
    items = schema.get("items")
    if items is not None:
        for j, v in enumerate(x):
            check_schema(v, items, f"{at}[{j}]")


def check_schema(x: Any, schema: Mapping[str, Any], at: str = "") -> None:
    """Check a parsed JSON value against a schema; raise on the first mismatch.

    The schema is a plain dict, a small subset of JSON Schema's ideas:
    ``type`` (``"object"``, ``"array"``, ``"string"``, ``"number"``, ``"integer"``,
    ``"boolean"``); for objects ``properties`` (key -> schema), ``required`` (keys) and
    ``additional`` (the schema of other keys; ``False`` refuses them, ``True``, the
    default, accepts anything); for arrays ``items``, ``min_items`` and ``max_items``; for
    numbers ``min`` and ``max`` (inclusive; a number must always be finite, and true/false
    is not a number); for strings ``max_length``; for any value ``enum`` (the allowed
    values); for objects also ``select``, a pair (key, value -> schema) that checks the
    object against the schema its ``key`` chooses (that key must be required and its
    values an ``enum`` of the choices). The checks descend only as deep as the schema does.

    Parameters
    ----------
    x : Any
        The value (from :func:`json.loads`).
    schema : mapping
        Its schema.
    at : str
        The key path of ``x``, for messages (``stack.layers[0].thickness_nm``).

    Raises
    ------
    SchemaError
        Naming the key path, what was expected and what was found.
    """
    want = schema.get("type")
    where = at or "the document"
    if want is not None:
        ok = isinstance(x, _TYPES[want]) and not (isinstance(x, bool) and want != "boolean")
        if not ok:
            raise SchemaError(f"{where}: expected {_NAMES[want]}, got {_kind(x)}")
    if "enum" in schema and x not in schema["enum"]:
        raise SchemaError(f"{where}: expected one of {sorted(schema['enum'])}, got {x!r}")
    if want in ("number", "integer"):
        _check_number(x, schema, where)
    elif want == "string" and len(x) > schema.get("max_length", len(x)):
        raise SchemaError(f"{where}: longer than {schema['max_length']} characters")
    elif want == "object":
        _check_object(x, schema, at)
        if "select" in schema:  # the schema of the rest depends on one key's value
            key, options = schema["select"]
            check_schema(x, options[x[key]], at)
    elif want == "array":
        _check_array(x, schema, where)
