"""The film fit JSON's schema and its checked reading, below the stack it describes.

:func:`_fit_doc` reads a file written by ``labbrdf film --fit-json`` within the caps of
:mod:`labbrdf.films.limits` and checks it against the schema of what labbrdf writes;
:func:`labbrdf.films.read_fit_json` then builds the stack and checks its indices with
:func:`_check_indices`.
"""

from __future__ import annotations

import json
import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from ..jsonsafe import SchemaError, check_schema
from ..nk import dispersion as disp
from ..outputs import InputFileError, read_input_file
from .graded import MAX_SUBLAYERS
from .limits import (
    MAX_FIT_JSON_BYTES,
    MAX_INDEX,
    MAX_LAYERS,
    MAX_TABLE_POINTS,
    MAX_THICKNESS_NM,
    WAVELENGTH_LIMITS_NM,
    FilmError,
)


def _fit_json_schema() -> dict[str, Any]:
    """The schema of what :meth:`FilmFit.save_json` writes and its readers use."""
    number = {"type": "number"}
    column = {"type": "array", "items": {"type": "number", "min": 0.0}, "min_items": 2}
    column["max_items"] = MAX_TABLE_POINTS
    model = {"type": "string", "enum": sorted({*disp.MODELS, "roughness", "ema", "graded"})}
    table = {
        "type": "object",
        "properties": {
            "model": model,
            "reference": {"type": "string", "enum": sorted(disp.REFERENCE_TABLES)},
            "file": {"type": "string", "max_length": 4096},
            "source": {"type": "string", "max_length": 4096},
            "wavelength_nm": column,
            "n": column,
            "k": column,
        },
        "additional": False,
    }
    rough = {
        "type": "object",
        "properties": {"model": model, "fraction": {"type": "number", "min": 0.0, "max": 1.0}},
        "additional": False,
    }
    params = {"type": "object", "properties": {"model": model}, "additional": number}
    by_model: dict[str, Any] = dict.fromkeys(disp.MODELS, params)
    fraction = {"type": "number", "min": 0.0, "max": 1.0}
    ema = {
        "type": "object",
        "required": ["components"],
        "properties": {
            "model": model,
            "components": {"type": "array", "min_items": 2, "max_items": 3},
            "fraction": fraction,
            "fraction3": fraction,
        },
        "additional": False,
    }
    graded = {
        "type": "object",
        "required": ["base", "parameter", "top", "bottom"],
        "properties": {
            "model": model,
            "base": {"type": "object"},
            "parameter": {"type": "string", "max_length": 100},
            "top": number,
            "bottom": number,
            "shape": number,
            "sublayers": {"type": "integer", "min": 1, "max": MAX_SUBLAYERS},
        },
        "additional": False,
    }
    by_model.update(tabulated=table, roughness=rough, ema=ema, graded=graded)
    material = {
        "type": "object",
        "required": ["model"],
        "properties": {"model": model},
        "additional": True,
        "select": ("model", by_model),
    }
    layer = {
        "type": "object",
        "required": ["material", "thickness_nm"],
        "properties": {
            "name": {"type": "string", "max_length": 200},
            "thickness_nm": {"type": "number", "min": 0.0, "max": MAX_THICKNESS_NM},
            "material": material,
            "coherent": {"type": "boolean"},
        },
        "additional": False,
    }
    a, b = WAVELENGTH_LIMITS_NM
    return {
        "type": "object",
        "required": ["stack", "wavelength_range_nm"],
        "properties": {
            "kind": {"type": "string", "enum": ["labbrdf film fit"]},
            "sources": {"type": "array", "items": {"type": "string"}},
            "stack": {
                "type": "object",
                "required": ["substrate"],
                "properties": {
                    "ambient": material,
                    "substrate": material,
                    "layers": {"type": "array", "items": layer, "max_items": MAX_LAYERS},
                    "thickness_spread": {"type": "number", "min": 0.0, "max": 0.1},
                    "bandwidth_nm": {"type": "number", "min": 0.0, "max": 20.0},
                    "angle_spread_deg": {"type": "number", "min": 0.0, "max": 2.0},
                    "substrate_thickness_nm": {
                        "type": "number",
                        "min": 0.0,
                        "max": MAX_THICKNESS_NM,
                    },
                },
                "additional": False,
            },
            "wavelength_range_nm": {
                "type": "array",
                "items": {"type": "number", "min": a, "max": b},
                "min_items": 2,
                "max_items": 2,
            },
        },
    }


def _check_tables(stack_doc: Mapping[str, Any], where: str) -> None:
    """A tabulated material gives one of reference, file or columns of one length."""
    mats = [
        ("stack.ambient", stack_doc.get("ambient")),
        ("stack.substrate", stack_doc["substrate"]),
    ]
    mats += [(f"stack.layers[{j}].material", x["material"]) for j, x in
             enumerate(stack_doc.get("layers", []))]  # fmt: skip
    for at, m in mats:
        if not isinstance(m, dict) or m.get("model") != "tabulated":
            continue
        given = [k for k in ("reference", "file", "wavelength_nm") if k in m]
        cols = [len(m[k]) for k in ("wavelength_nm", "n", "k") if k in m]
        if len(given) != 1 or ("wavelength_nm" in m and ("n" not in m or len(set(cols)) != 1)):
            raise FilmError(
                f"{where}: {at}: a tabulated material gives one of 'reference', 'file' or "
                "the columns 'wavelength_nm', 'n' (and 'k') of one length"
            )


def _tabulated(stack: Any) -> list[tuple[str, disp.Tabulated]]:
    mats = [("ambient", stack.ambient), ("substrate", stack.substrate)]
    mats += [(lay.name, lay.material) for lay in stack.layers]
    for lay in stack.layers:  # the constituents of a mixture
        comps = getattr(lay.material, "components", ())
        mats += [(f"{lay.name} constituent {j + 1}", c) for j, c in enumerate(comps)]
    return [(name, m) for name, m in mats if isinstance(m, disp.Tabulated)]


def _check_indices(stack: Any, rng: tuple[float, float], where: str) -> None:
    """Every medium's index is physical over the fitted range: finite, n > 0, k >= 0.

    Checked on 65 wavelengths spanning the range, with ``|N| <=`` :data:`MAX_INDEX`.
    """
    names = ["ambient", *(lay.name for lay in stack.layers), "substrate"]
    grid = np.linspace(rng[0], rng[1], 65)
    cover = [m.covers(grid) for _, m in _tabulated(stack)]
    if not all(cover):
        return  # the range check that follows names the table
    try:
        with np.errstate(all="ignore"):
            indices = stack.indices(grid)
    except (FilmError, disp.DispersionError, ValueError) as exc:
        raise FilmError(f"{where}: stack: {exc}") from None
    for name, n in zip(names, indices, strict=True):
        n = np.asarray(n, complex)
        ok = np.isfinite(n) & (n.real > 0) & (n.imag >= 0) & (np.abs(n) <= MAX_INDEX)
        if not np.all(ok):
            bad = float(grid[np.argmin(ok)])
            raise FilmError(
                f"{where}: stack: the {name} index at {bad:g} nm is {complex(n[np.argmin(ok)])}; "
                f"expected finite n > 0, k >= 0 and |n + ik| <= {MAX_INDEX:g} over the fitted "
                "range (labbrdf.films.MAX_INDEX)"
            )


def _fit_doc(path: str | os.PathLike[str]) -> tuple[Path, dict[str, Any]]:
    """(path, document) of a film fit JSON: a regular file within the caps, schema-checked."""
    p = Path(path)
    hint = "expected a film fit written by labbrdf film --fit-json"
    try:
        raw = read_input_file(p, max_bytes=MAX_FIT_JSON_BYTES, what="film fit JSON")
        doc = json.loads(raw.decode("utf-8"))
    except InputFileError as exc:
        raise FilmError(str(exc)) from None
    except UnicodeDecodeError:
        raise FilmError(f"{p}: not a UTF-8 text file; {hint}") from None
    except json.JSONDecodeError as exc:
        raise FilmError(f"{p}, line {exc.lineno}: not JSON ({exc.msg})") from None
    except RecursionError:
        raise FilmError(f"{p}: arrays or objects nested too deeply; {hint}") from None
    except ValueError as exc:  # an integer of more digits than Python converts
        raise FilmError(f"{p}: not JSON ({exc}); {hint}") from None
    if not isinstance(doc, dict) or "stack" not in doc:
        raise FilmError(
            f"{p}: not a film fit (no 'stack'); write one with labbrdf film --fit-json"
        )
    try:
        check_schema(doc, _fit_json_schema())
    except SchemaError as exc:
        raise FilmError(f"{p}: {exc}; {hint}") from None
    _check_tables(doc["stack"], str(p))
    return p, doc
