"""Film model files (TOML): one model read with every error naming the file and the line.

:func:`load_model` reads a file into a :class:`~labbrdf.films.FilmModel`;
:func:`load_samples` its ``[samples]`` table (several samples in one fit);
:func:`named_inputs` lists the table files a model or a fit JSON names (inputs of whoever
reads it, never to be overwritten).
"""

from __future__ import annotations

import math
import os
import re
import tomllib
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from ..nk import dispersion as disp
from ..outputs import InputFileError, read_input_file
from .fitjson import _fit_doc
from .graded import Graded
from .layers import Layer, free_parameters
from .limits import (
    MAX_LAYERS,
    MAX_MODEL_BYTES,
    MAX_THICKNESS_NM,
    FilmError,
    check_wavelength_range,
)
from .materials import (
    Material,
    Roughness,
    TableReader,
    _table_file,
    _with_params,
    as_material,
)
from .model import FilmModel
from .modelsamples import ModelSamples, parse_samples, sample_files
from .nonuniform import MAX_SPREAD
from .spreads import MAX_ANGLE_SPREAD_DEG, MAX_BANDWIDTH_NM
from .stack import Stack

_LAYER_KEYS = {
    "name",
    "material",
    "model",
    "file",
    "reference",
    "thickness_nm",
    "fraction",
    "coherent",
    "components",
    "graded",
    "sublayers",
}


_BEAM_KEYS = {  # top-level spreads: name -> (largest value, what it is)
    "thickness_spread": (MAX_SPREAD, "a relative spread"),
    "bandwidth_nm": (MAX_BANDWIDTH_NM, "a bandwidth (FWHM) [nm]"),
    "angle_spread_deg": (MAX_ANGLE_SPREAD_DEG, "an angle spread (1 sigma) [deg]"),
}
_TOP_KEYS = ("ambient", "wavelength_nm", *_BEAM_KEYS, "substrate", "layer", "samples")


class _KeyLines:
    """Where each table and key of a TOML text is: one light scan of the lines.

    :mod:`tomllib` gives no line numbers for values; this finds the line of
    ``[table]`` / ``[[table]]`` headers and of ``key =`` lines inside them, so that every
    error of a model file names its line.
    """

    _HEADER = re.compile(r"^\[\[\s*([\w.-]+)\s*\]\]$|^\[\s*([\w.-]+)\s*\]$")
    _KEY = re.compile(r"^\"?([\w.-]+)\"?\s*=")

    def __init__(self, text: str) -> None:
        self.lines: dict[tuple[str, int, str | None], int] = {}
        table, count = "", {"": 0}
        for lineno, raw in enumerate(text.splitlines(), 1):
            line = raw.split("#", 1)[0].strip()
            head = self._HEADER.match(line)
            if head:
                table = head.group(1) or head.group(2)
                count[table] = count.get(table, -1) + 1
                self.lines.setdefault((table, count[table], None), lineno)
                continue
            key = self._KEY.match(line)
            if key:
                self.lines.setdefault((table, count[table], key.group(1)), lineno)

    def __call__(self, table: str, index: int | None = None, key: str | None = None) -> int:
        """1-based line of ``key`` in the ``index``-th ``table`` (its header if no key)."""
        j = index or 0
        return self.lines.get((table, j, key)) or self.lines.get((table, j, None)) or 1


def _number(x: Any, where: str) -> float:
    """A finite number of a model file (never true/false, NaN or infinite)."""
    if isinstance(x, bool) or not isinstance(x, (int, float)):
        raise FilmError(f"{where}: expected a number, got {x!r}")
    v = float(x)
    if not math.isfinite(v):
        raise FilmError(f"{where}: expected a finite number, got {x!r}")
    return v


def _box(lo: float, hi: float, where: str) -> tuple[float, float]:
    if not lo < hi:
        raise FilmError(f"{where}: impossible bounds [{lo:g}, {hi:g}] (need min < max)")
    return lo, hi


def _spec(value: Any, where: str) -> tuple[float, tuple[float, float] | None]:
    """A number (fixed), [min, max] (fitted from the middle) or {value, min, max, vary}.

    Every number must be finite: a NaN or an infinity is refused naming ``where``.
    """
    if isinstance(value, list):
        if len(value) != 2:
            raise FilmError(f"{where}: expected [min, max] (two numbers), got {len(value)} items")
        lo, hi = _box(_number(value[0], where), _number(value[1], where), where)
        return (lo + hi) / 2, (lo, hi)
    if isinstance(value, dict):
        bad = sorted(set(value) - {"value", "min", "max", "vary"})
        if bad:
            raise FilmError(f"{where}: unknown key(s) {bad}; expected value, min, max, vary")
        if "value" not in value and not ("min" in value and "max" in value):
            raise FilmError(f"{where}: give value, or min and max")
        vary = value.get("vary", "min" in value or "max" in value)
        if not isinstance(vary, bool):
            raise FilmError(f"{where}: vary must be true or false, got {vary!r}")
        if not vary:
            return _number(value["value"], where), None
        lo, hi = _box(_number(value.get("min"), where), _number(value.get("max"), where), where)
        v = _number(value["value"], where) if "value" in value else (lo + hi) / 2
        if not lo <= v <= hi:
            raise FilmError(f"{where}: value {v:g} outside [{lo:g}, {hi:g}]")
        return v, (lo, hi)
    try:
        return _number(value, where), None
    except FilmError:
        raise FilmError(
            f"{where}: expected a finite number, [min, max] or {{value, min, max}}, got {value!r}"
        ) from None


def _named_file(value: str, base: Path) -> Path:
    """The path of a ``file = ...`` of a model file: relative to the model's folder."""
    p = Path(value)
    return p if p.is_absolute() else base / p


def _material_of(
    tbl: Mapping[str, Any], base: Path, at: Any, read_table: TableReader | None
) -> Material:
    """The material a [substrate] or [[layer]] table names (before its parameters)."""
    kinds = [k for k in ("material", "model", "file", "reference") if k in tbl]
    if len(kinds) != 1:
        raise FilmError(
            f"{at(None)}: give exactly one of material = NAME (si, sio2, roughness, or a "
            "dispersion model), model = NAME, file = PATH, reference = NAME"
        )
    kind = kinds[0]
    val = tbl[kind]
    if not isinstance(val, str):
        raise FilmError(f"{at(kind)}: {kind} must be a string")
    if "components" in tbl and val.strip().lower() != "ema":
        raise FilmError(f'{at("components")}: components belong to material = "ema"')
    try:
        if kind == "file":
            return _table_file(_named_file(val, base), read_table)
        if val.strip().lower() == "ema":
            return _ema_of(tbl.get("components"), base, read_table)
        return as_material(val)
    except (FilmError, disp.DispersionError) as exc:
        raise FilmError(
            f"{at(kind if 'components' not in tbl else 'components')}: {exc}"
        ) from None


def _graded_of(m: Material, tbl: Mapping[str, Any], at: Any) -> Material:
    """``graded = "PARAM"`` (and ``sublayers = N``): the material graded in that parameter."""
    key = "graded" if "graded" in tbl else "sublayers"
    p = tbl.get("graded")
    if not isinstance(p, str):
        raise FilmError(f'{at(key)}: graded = "PARAM" names the parameter that varies')
    n = tbl.get("sublayers", 20)
    if isinstance(n, bool) or not isinstance(n, int):
        raise FilmError(f"{at('sublayers')}: sublayers must be an integer, got {n!r}")
    if isinstance(m, (Roughness, Graded)) or not hasattr(m, "params") or p not in m.params:
        raise FilmError(
            f"{at('graded')}: {p!r} is not a parameter of {m.name}; parameters: "
            f"{sorted(getattr(m, 'params', {}))}"
        )
    try:
        return Graded(m, p, m.params[p], m.params[p], 1.0, n)
    except FilmError as exc:
        raise FilmError(f"{at(key)}: {exc}") from None


def _ema_of(components: Any, base: Path, read_table: TableReader | None) -> Material:
    """``material = "ema"``, ``components = [...]``: names, @LAYER, void, {model...}, {file}."""
    if not isinstance(components, list):
        raise FilmError('material = "ema" needs components = [2 or 3 constituents]')
    comps: list[Any] = []
    for c in components:
        if isinstance(c, dict) and set(c) == {"file"} and isinstance(c["file"], str):
            comps.append(_table_file(_named_file(c["file"], base), read_table))
        elif isinstance(c, (str, dict)):
            comps.append(c)
        else:
            raise FilmError(
                f"constituent {c!r}: expected a name, 'void', '@LAYER', "
                "{model = ..., ...} or {file = ...}"
            )
    return as_material({"model": "ema", "components": comps})


def _material_from_table(
    tbl: Mapping[str, Any],
    where: str,
    base: Path,
    lines: _KeyLines,
    at_table: tuple[str, int | None],
    read_table: TableReader | None,
) -> tuple[Material, dict[str, float], dict[str, tuple[float, float]]]:
    """(material, parameter values, free boxes) of a [substrate] or [[layer]] table."""

    def at(key: str | None) -> str:
        return f"{where}, line {lines(*at_table, key)}"

    m = _material_of(tbl, base, at, read_table)
    if "graded" in tbl or "sublayers" in tbl:
        m = _graded_of(m, tbl, at)
    values: dict[str, float] = {}
    free: dict[str, tuple[float, float]] = {}
    known = set(m.params)
    for key, v in tbl.items():
        if key in _LAYER_KEYS and key not in known:
            continue
        if key not in known:
            raise FilmError(
                f"{at(key)}: unknown parameter {key!r} for {m.name}; parameters: "
                f"{sorted(known) or 'none (a table)'}"
            )
        values[key], box = _spec(v, f"{at(key)}: {key}")
        if box is not None:
            free[key] = box
    if values:
        try:
            m = _with_params(m, values)
        except (disp.DispersionError, FilmError) as exc:
            raise FilmError(f"{at(None)}: {exc}") from None
    return m, values, free


def _read_model(path: str | os.PathLike[str]) -> tuple[Path, str, dict[str, Any]]:
    """(path, text, parsed document) of a model file: a regular TOML file within the caps."""
    p = Path(path)
    try:
        raw = read_input_file(p, max_bytes=MAX_MODEL_BYTES, what="model file")
    except InputFileError as exc:
        raise FilmError(str(exc)) from None
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError:
        raise FilmError(f"{p}: not a UTF-8 text file (expected a TOML model)") from None
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise FilmError(f"{p}: not valid TOML ({exc})") from None
    except RecursionError:
        raise FilmError(f"{p}: not a film model (arrays or tables nested too deeply)") from None
    except ValueError as exc:  # e.g. an integer of more digits than Python converts
        raise FilmError(f"{p}: not a film model ({exc})") from None
    return p, text, doc


def _check_top(doc: Mapping[str, Any], where: str, text: str, lines: _KeyLines) -> None:
    """Only the known top-level keys; at most :data:`MAX_LAYERS` layers."""
    top_bad = sorted(set(doc) - set(_TOP_KEYS))
    if top_bad:
        key = top_bad[0]
        k = re.escape(key)
        pattern = rf"^\s*(\[\[\s*{k}\s*\]\]|\[\s*{k}\s*\]|\"?{k}\"?\s*=)"
        line = next((i for i, raw in enumerate(text.splitlines(), 1) if re.match(pattern, raw)), 1)
        raise FilmError(
            f"{where}, line {line}: unknown key or table {key!r}; expected ambient, "
            "wavelength_nm, thickness_spread, bandwidth_nm, angle_spread_deg, [substrate], "
            "[[layer]], [samples]"
        )
    layers = doc.get("layer", [])
    if not isinstance(layers, list) or not all(isinstance(t, dict) for t in layers):
        raise FilmError(f"{where}, line {lines('', 0, 'layer')}: 'layer' must be [[layer]] tables")
    if len(layers) > MAX_LAYERS:
        raise FilmError(
            f"{where}, line {lines('layer', MAX_LAYERS)}: {len(layers):,} layers; a model "
            f"may have at most {MAX_LAYERS} (labbrdf.films.MAX_LAYERS)"
        )
    if "substrate" not in doc or not isinstance(doc["substrate"], dict):
        raise FilmError(f"{where}, line 1: missing [substrate] table")


def _ambient_and_range(
    doc: Mapping[str, Any], where: str, lines: _KeyLines
) -> tuple[float, tuple[float, float] | None]:
    """``ambient`` (a finite real index >= 1) and ``wavelength_nm`` (a plausible range)."""
    ambient: Any = doc.get("ambient", 1.0)
    at = f"{where}, line {lines('', 0, 'ambient')}"
    if isinstance(ambient, bool) or not isinstance(ambient, (int, float)):
        raise FilmError(f"{at}: ambient must be a real index >= 1, got {ambient!r}")
    if not (math.isfinite(ambient) and ambient >= 1.0):
        raise FilmError(f"{at}: ambient must be a real index >= 1, got {ambient!r}")
    if "wavelength_nm" not in doc:
        return float(ambient), None
    at = f"{where}, line {lines('', 0, 'wavelength_nm')}"
    w = doc["wavelength_nm"]
    if not isinstance(w, list) or len(w) != 2:
        raise FilmError(f"{at}: wavelength_nm must be [min, max] with 0 < min < max")
    lo, hi = (_number(x, f"{at}: wavelength_nm") for x in w)
    try:
        return float(ambient), check_wavelength_range((lo, hi), "wavelength_nm")
    except FilmError as exc:
        raise FilmError(f"{at}: {exc}") from None


def _layer_of(
    tbl: Mapping[str, Any],
    j: int,
    where: str,
    base: Path,
    lines: _KeyLines,
    read_table: TableReader | None,
) -> tuple[Layer, dict[str, tuple[float, float]]]:
    """The ``j``-th [[layer]] table and its free boxes (``"<layer>.<name>"``)."""
    name = tbl.get("name", f"layer{j + 1}")
    if not isinstance(name, str):
        raise FilmError(f"{where}, line {lines('layer', j, 'name')}: name must be a string")
    if "thickness_nm" not in tbl:
        raise FilmError(f"{where}, line {lines('layer', j)}: layer {name!r} has no thickness_nm")
    m, values, mfree = _material_from_table(tbl, where, base, lines, ("layer", j), read_table)
    at = f"{where}, line {lines('layer', j, 'thickness_nm')}: thickness_nm"
    d, dbox = _spec(tbl["thickness_nm"], at)
    if d < 0 or (dbox is not None and dbox[0] < 0):
        raise FilmError(f"{at} must be >= 0")
    if max(d, dbox[1] if dbox else d) > MAX_THICKNESS_NM:
        raise FilmError(
            f"{at} must be <= {MAX_THICKNESS_NM:g} nm (labbrdf.films.MAX_THICKNESS_NM): "
            "thicker is a substrate, not a film"
        )
    coherent = tbl.get("coherent", True)
    if not isinstance(coherent, bool):
        raise FilmError(
            f"{where}, line {lines('layer', j, 'coherent')}: coherent must be true or false, "
            f"got {coherent!r}"
        )
    try:
        layer = Layer(m, d, name, coherent)
    except FilmError as exc:
        raise FilmError(f"{where}, line {lines('layer', j)}: {exc}") from None
    written = {**{k: mfree.get(k) for k in values}, "thickness_nm": dbox}
    return layer, free_parameters(layer, written)  # the one rule: labbrdf.films.layers


def _substrate_thickness(
    tbl: Mapping[str, Any], where: str, lines: _KeyLines
) -> tuple[float | None, tuple[float, float] | None]:
    """A [substrate]'s ``thickness_nm`` (a finite, incoherent substrate) and its box."""
    for key in ("coherent", "name", "fraction"):
        if key in tbl:
            raise FilmError(
                f"{where}, line {lines('substrate', None, key)}: {key!r} is a layer key; a "
                "substrate is semi-infinite, or incoherent with its thickness_nm"
            )
    if "thickness_nm" not in tbl:
        return None, None
    at = f"{where}, line {lines('substrate', None, 'thickness_nm')}: thickness_nm"
    d, box = _spec(tbl["thickness_nm"], at)
    if min(d, box[0] if box else d) <= 0 or max(d, box[1] if box else d) > MAX_THICKNESS_NM:
        raise FilmError(
            f"{at}: expected a thickness in (0, {MAX_THICKNESS_NM:g}] nm "
            "(labbrdf.films.MAX_THICKNESS_NM)"
        )
    return d, box


def load_model(path: str | os.PathLike[str], read_table: TableReader | None = None) -> FilmModel:
    """Read a film model file (TOML).

    Format::

        ambient = 1.0                  # optional, a number (lossless)
        wavelength_nm = [250, 1000]    # optional fit window [nm]
        thickness_spread = [0, 0.05]   # optional: relative 1-sigma thickness spread
        bandwidth_nm = [0, 5]          # optional: spectral bandwidth (Gaussian FWHM) [nm]
        angle_spread_deg = 0.2         # optional: 1-sigma angle-of-incidence spread [deg]

        [substrate]
        material = "si"                # si, sio2 (shipped tables), a model name, or
                                       # file = "ta.dat" (n,k table or ellipsometer file)
        thickness_nm = 1e6             # optional: a finite substrate, incoherent, with
                                       # the ambient behind it (backside reflection)

        [[layer]]                      # top first; repeat for more layers
        name = "oxide"
        material = "cauchy"            # constant, cauchy, sellmeier, tauc_lorentz, drude,
                                       # lorentz, roughness, si, sio2; or file = "...";
                                       # "ema(@oxide, void)" (a Bruggeman mixture), or
                                       # "ema" with components = ["@oxide", "void", ...]
        thickness_nm = [0, 10]         # [min, max]: fitted, started mid-box
        A = [1.3, 1.7]
        B = 0.0036                     # a number: fixed
        C = {value = 0, min = -0.01, max = 0.01}   # full form (vary = false to fix)
                                       # not written: fitted in its default box
                                       # (labbrdf.films.layers.default_boxes)
        coherent = true                # false: a thick layer, added in intensity
        # graded = "A"                 # A varies from A_top to A_bottom (set those, and
        # sublayers = 20               # shape = 1: linear) in 20 slices

    A ``file`` is relative to the model file's folder, and is an input of the command
    that reads the model (:func:`named_inputs`). The file is at most
    :data:`MAX_MODEL_BYTES` and names at most :data:`MAX_LAYERS` layers, each at most
    :data:`MAX_THICKNESS_NM` thick; every number is finite.

    Parameters
    ----------
    path : path-like
        The model file.
    read_table : callable, optional
        Reads a ``file = ...`` material (``labbrdf.films.materials.TableReader``, e.g.
        :func:`labbrdf.nk.tabulated_from_file`); without it a model naming a file is refused.

    Raises
    ------
    FilmError
        Naming the file and the line: TOML syntax, an unknown key, layer or parameter,
        a NaN or infinite number, impossible bounds, a missing substrate, a file that is
        not a regular file or is over a cap.
    """
    p, text, doc = _read_model(path)
    where, lines = str(p), _KeyLines(text)
    _check_top(doc, where, text, lines)
    ambient, wl_range = _ambient_and_range(doc, where, lines)
    sub, _, sub_free = _material_from_table(
        doc["substrate"], where, p.parent, lines, ("substrate", None), read_table
    )
    if isinstance(sub, Roughness):
        raise FilmError(f"{where}, line {lines('substrate')}: roughness is a layer")
    sub_d, sub_box = _substrate_thickness(doc["substrate"], where, lines)
    layers = []
    free: dict[str, tuple[float, float]] = {f"substrate.{k}": b for k, b in sub_free.items()}
    if sub_box is not None:
        free["substrate.thickness_nm"] = sub_box
    seen: set[str] = set()
    for j, tbl in enumerate(doc.get("layer", [])):
        layer, layer_free = _layer_of(tbl, j, where, p.parent, lines, read_table)
        if layer.name and (layer.name in seen or layer.name in ("substrate", "ambient", "stack")):
            raise FilmError(
                f"{where}, line {lines('layer', j, 'name')}: layer name {layer.name!r} is "
                "repeated or reserved ('substrate', 'ambient', 'stack'); expected a unique name"
            )
        seen.add(layer.name)
        layers.append(layer)
        free.update(layer_free)
    beam: dict[str, float] = {}
    for key, (top, what) in _BEAM_KEYS.items():
        if key not in doc:
            continue
        at = f"{where}, line {lines('', 0, key)}: {key}"
        beam[key], box = _spec(doc[key], at)
        if box is not None:
            free[f"stack.{key}"] = box
        lo, hi = box or (beam[key], beam[key])
        if not 0.0 <= lo <= hi <= top:
            raise FilmError(f"{at}: expected {what} in [0, {top:g}]")
    try:
        st = Stack(layers, sub, ambient, sub_d, **beam)
    except FilmError as exc:
        raise FilmError(f"{where}: {exc}") from None
    return FilmModel(st, free, wl_range, where)


def load_samples(path: str | os.PathLike[str]) -> ModelSamples | None:
    """The ``[samples]`` table of a model file (:mod:`~labbrdf.films.modelsamples`), or None.

    Raises
    ------
    FilmError
        As :func:`load_model`, naming the file and the line.
    """
    p, text, doc = _read_model(path)
    return parse_samples(doc, str(p), _KeyLines(text), p.parent)


def _model_files(doc: Mapping[str, Any], base: Path) -> list[Path]:
    """The ``file = ...`` paths of a parsed model file, as :func:`load_model` opens them."""
    tables = [doc.get("substrate")]
    layers = doc.get("layer")
    tables += layers if isinstance(layers, list) else []
    for t in list(tables):
        comps = t.get("components") if isinstance(t, dict) else None
        tables += comps if isinstance(comps, list) else []
    named = [
        _named_file(t["file"], base)
        for t in tables
        if isinstance(t, dict) and isinstance(t.get("file"), str)
    ]
    return named + sample_files(doc, base)  # the [samples] data files are inputs too


def named_inputs(path: str | os.PathLike[str], kind: str) -> list[Path]:
    """The files a film model file or a film fit JSON names: inputs of whoever reads it.

    Parameters
    ----------
    path : path-like
        The model file (``kind="model"``, :func:`load_model`) or the fit JSON
        (``kind="fit"``, :func:`read_fit_json`).
    kind : {"model", "fit"}
        Which of the two.

    Returns
    -------
    list of Path
        The ``file`` tables, as the loader opens them (a model's relative to its folder).
        A command that writes must refuse every one of them as an output.

    Raises
    ------
    FilmError
        The file cannot be read as that kind (the loader's own message).
    """
    if kind == "model":
        p, _, doc = _read_model(path)
        return _model_files(doc, p.parent)
    if kind == "fit":
        _, doc = _fit_doc(path)
        st = doc["stack"]
        mats = [st.get("ambient"), st["substrate"], *(x["material"] for x in st.get("layers", []))]
        for m in list(mats):
            comps = m.get("components") if isinstance(m, dict) else None
            mats += comps if isinstance(comps, list) else []
        return [Path(m["file"]) for m in mats if isinstance(m, dict) and "file" in m]
    raise ValueError(f"kind: expected 'model' or 'fit', got {kind!r}")
