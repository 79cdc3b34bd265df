"""Thin-film stacks as objects: layers, a stack, model files, and the film fit.

Objects and workflow (layer b): a :class:`Stack` of :class:`Layer` s over a substrate
computes psi/Delta, reflectance and transmittance with :mod:`labbrdf.stack` (the one
coherent multilayer) from :mod:`labbrdf.dispersion` materials; :func:`fit_film` fits its
thicknesses and dispersion parameters to psi/Delta (all angles), polarised or unpolarised
reflectance and transmittance rows of one or several files of one sample, through the one
fitting core (:func:`labbrdf.fitting.fit`, global then local, weighted by the files'
sigmas); :class:`FilmFit` reports thicknesses and n, k with intervals, chi2/nu beside
Woollam's MSE, correlations and identifiability flags.

Parameter names are ``"<layer>.<parameter>"``: ``"oxide.thickness_nm"``, ``"oxide.A"``,
``"substrate.omega_p"``, ``"rough.fraction"``.

>>> from labbrdf.films import Layer, Stack
>>> s = Stack([Layer("sio2", 2.0, name="oxide")], substrate="si")
>>> psi, delta = s.psi_delta(633.0, 70.0)
"""

from __future__ import annotations

import json
import math
import os
import re
import tomllib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import dispersion as disp
from . import stack as stk
from .errors import LabbrdfError
from .jsonsafe import SchemaError, check_schema
from .outputs import InputFileError, read_input_file

if TYPE_CHECKING:  # at run time through __getattr__ below (the fit imports this module)
    from .fitting.film import FilmFit, fit_film, woollam_mse

__all__ = [
    "FILM_QUANTITIES",
    "MAX_FIT_JSON_BYTES",
    "MAX_INDEX",
    "MAX_LAYERS",
    "MAX_MODEL_BYTES",
    "MAX_TABLE_POINTS",
    "MAX_THICKNESS_NM",
    "WAVELENGTH_LIMITS_NM",
    "FilmError",
    "FilmFit",
    "FilmModel",
    "Layer",
    "Roughness",
    "Stack",
    "check_wavelength_range",
    "fit_film",
    "load_model",
    "named_inputs",
    "read_fit_json",
    "woollam_mse",
]

#: dataset quantities a film fit uses (psi/Delta at any angle; specular R and T, by
#: polarisation channel ``s``/``p`` or unpolarised)
FILM_QUANTITIES = ("psi", "delta", "reflectance", "transmittance")

#: wavelength at which a fit summary quotes each layer's n, k [nm] (He-Ne line)
NK_REPORT_NM = 633.0

#: the most layers a stack may have, whoever builds it (a model file, a fit JSON,
#: ``--layer``, the library): real coatings have a few to a few hundred; the cap keeps a
#: crafted file from building thousands of layers
MAX_LAYERS = 500

#: the thickest layer a model file or fit JSON may state [nm] (10 mm): thicker is a
#: substrate, not a coherent film
MAX_THICKNESS_NM = 1.0e7

#: the wavelengths a model or fit may state [nm]: 1 nm (soft X-rays) to 1 mm (far IR)
WAVELENGTH_LIMITS_NM = (1.0, 1.0e6)

#: the largest index modulus |n + ik| a fit JSON's stack may have over its fitted range [1]
#: (metals in the far infrared reach a few hundred)
MAX_INDEX = 1.0e4

#: largest film model file (TOML) read [bytes]: a model of MAX_LAYERS layers is ~50 kB
MAX_MODEL_BYTES = 1 << 20

#: largest film fit JSON read [bytes]: its tables may hold many rows
MAX_FIT_JSON_BYTES = 64 << 20

#: most rows of a table inside a fit JSON
MAX_TABLE_POINTS = 1_000_000


class FilmError(LabbrdfError, ValueError):
    """A bad film model (file, layer or parameter) or film data."""


# --------------------------------------------------------------------------------------
# materials, layers, stacks
# --------------------------------------------------------------------------------------


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
    from .nk import tabulated_from_file  # the dataset layer: pandas and the adapters

    return tabulated_from_file(path)


def _with_params(m: Material, values: Mapping[str, float]) -> Material:
    if not values:
        return m
    if isinstance(m, Roughness):
        return Roughness(float(values.get("fraction", m.fraction)))
    return type(m).from_params({**m.params, **values})


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
    """

    material: Any
    thickness_nm: float
    name: str = ""

    def __post_init__(self) -> None:
        object.__setattr__(self, "material", as_material(self.material))
        d = float(self.thickness_nm)
        if not (math.isfinite(d) and d >= 0):
            raise FilmError(f"layer {self.name!r}: thickness_nm must be >= 0, got {d}")
        object.__setattr__(self, "thickness_nm", d)

    @property
    def params(self) -> dict[str, float]:
        """``thickness_nm`` and the material's parameters."""
        return {"thickness_nm": self.thickness_nm, **self.material.params}

    def to_dict(self) -> dict[str, Any]:
        """JSON-safe form."""
        return {
            "name": self.name,
            "thickness_nm": self.thickness_nm,
            "material": self.material.to_dict(),
        }


class Stack:
    """Ambient / layers (top first) / substrate.

    Parameters
    ----------
    layers : sequence of Layer
        Top (next to the ambient) first.
    substrate : material
        Semi-infinite substrate (see :func:`as_material`).
    ambient : material
        Semi-infinite, lossless ambient; default 1 (vacuum/air).
    """

    def __init__(self, layers: Sequence[Layer], substrate: Any, ambient: Any = 1.0) -> None:
        layers = list(layers)
        if len(layers) > MAX_LAYERS:
            raise FilmError(
                f"{len(layers):,} layers; a stack may have at most {MAX_LAYERS} "
                "(labbrdf.films.MAX_LAYERS)"
            )
        named = []
        for j, lay in enumerate(layers, 1):
            if not isinstance(lay, Layer):
                raise FilmError(f"layers[{j - 1}]: expected a Layer, got {type(lay).__name__}")
            named.append(lay if lay.name else Layer(lay.material, lay.thickness_nm, f"layer{j}"))
        names = [lay.name for lay in named]
        dup = sorted({n for n in names if names.count(n) > 1})
        if dup:
            raise FilmError(f"layer names must be unique; repeated: {dup}")
        if set(names) & {"substrate", "ambient"}:
            raise FilmError("'substrate' and 'ambient' are reserved names")
        self.layers: tuple[Layer, ...] = tuple(named)
        sub, amb = as_material(substrate), as_material(ambient)
        if isinstance(sub, Roughness) or isinstance(amb, Roughness):
            raise FilmError("roughness is a layer, not a substrate or ambient")
        self.substrate: disp.Dispersion = sub
        self.ambient: disp.Dispersion = amb

    # ---- optics
    def _ambient_nk(self, lam: NDArray) -> NDArray:
        n0 = self.ambient.nk(lam)
        if np.any(np.asarray(n0).imag != 0):
            raise FilmError("ambient: must be lossless (k = 0)")
        return np.asarray(n0)

    def indices(self, wavelength_nm: ArrayLike) -> list[NDArray[np.complex128]]:
        """``[N_ambient, N_layer1, ..., N_substrate]`` at the wavelengths [1].

        A :class:`Roughness` layer is the Bruggeman mixture (:func:`labbrdf.stack.bruggeman`)
        of the medium directly below it and the ambient.
        """
        lam = np.asarray(wavelength_nm, float)
        n_amb = self._ambient_nk(lam)
        below = np.asarray(self.substrate.nk(lam))
        out = [below]
        for lay in reversed(self.layers):
            m = lay.material
            if isinstance(m, Roughness):
                n = np.sqrt(stk.bruggeman(below * below, n_amb * n_amb + 0j, m.fraction))
                n = np.where(n.imag < 0, -n, n)
            else:
                n = np.asarray(m.nk(lam))
            out.append(n)
            below = n
        out.append(n_amb)
        return out[::-1]

    def _thicknesses(self) -> list[float]:
        return [lay.thickness_nm for lay in self.layers]

    def _grid(self, wavelength_nm: ArrayLike, theta_deg: ArrayLike):
        lam = np.asarray(wavelength_nm, float)
        return self.indices(lam), self._thicknesses(), lam, np.asarray(theta_deg, float)

    def psi_delta(
        self, wavelength_nm: ArrayLike, theta_deg: ArrayLike
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """psi, Delta [deg] (Nebraska convention, Delta in [0, 360)); inputs broadcast."""
        return stk.ellipsometry(*self._grid(wavelength_nm, theta_deg))

    def reflectance(
        self, wavelength_nm: ArrayLike, theta_deg: ArrayLike
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """R_s, R_p [1]; inputs broadcast."""
        return stk.reflectance(*self._grid(wavelength_nm, theta_deg))

    def transmittance(
        self, wavelength_nm: ArrayLike, theta_deg: ArrayLike
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """T_s, T_p into the substrate [1]; inputs broadcast."""
        return stk.transmittance(*self._grid(wavelength_nm, theta_deg))

    def amplitudes(self, wavelength_nm: ArrayLike, theta_deg: ArrayLike):
        """r_s, r_p, t_s, t_p (:func:`labbrdf.stack.amplitudes`); inputs broadcast."""
        return stk.amplitudes(*self._grid(wavelength_nm, theta_deg))

    def nk(self, wavelength_nm: ArrayLike) -> dict[str, NDArray[np.complex128]]:
        """Complex index of every layer (by name, top first) and of the substrate."""
        idx = self.indices(wavelength_nm)
        out = {lay.name: idx[j + 1] for j, lay in enumerate(self.layers)}
        out["substrate"] = idx[-1]
        return out

    # ---- parameters
    def values(self) -> dict[str, float]:
        """Every parameter as ``"<layer>.<name>"`` -> value (substrate and ambient too)."""
        out: dict[str, float] = {}
        for lay in self.layers:
            out.update({f"{lay.name}.{k}": v for k, v in lay.params.items()})
        out.update({f"substrate.{k}": v for k, v in self.substrate.params.items()})
        return out

    def units(self) -> dict[str, str]:
        """Units of every parameter of :meth:`values`."""
        out: dict[str, str] = {}
        for lay in self.layers:
            out[f"{lay.name}.thickness_nm"] = "nm"
            out.update({f"{lay.name}.{k}": u for k, u in lay.material.units().items()})
        out.update({f"substrate.{k}": u for k, u in self.substrate.units().items()})
        return out

    def with_values(self, values: Mapping[str, float]) -> Stack:
        """A copy with the parameters ``values`` (``"<layer>.<name>"`` -> value) replaced."""
        per: dict[str, dict[str, float]] = {}
        known = self.values()
        for key, v in values.items():
            if key not in known:
                raise FilmError(f"unknown stack parameter {key!r}; parameters: {sorted(known)}")
            owner, name = key.rsplit(".", 1)
            per.setdefault(owner, {})[name] = float(v)
        layers = []
        for lay in self.layers:
            p = dict(per.get(lay.name, {}))
            d = p.pop("thickness_nm", lay.thickness_nm)
            layers.append(Layer(_with_params(lay.material, p), d, lay.name))
        sub = _with_params(self.substrate, per.get("substrate", {}))
        return Stack(layers, sub, self.ambient)

    # ---- serialisation
    def to_dict(self) -> dict[str, Any]:
        """JSON-safe form (inverse: :meth:`from_dict`)."""
        return {
            "ambient": self.ambient.to_dict(),
            "layers": [lay.to_dict() for lay in self.layers],
            "substrate": self.substrate.to_dict(),
        }

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> Stack:
        """A stack from :meth:`to_dict`'s form."""
        try:
            layers = [
                Layer(as_material(x["material"]), float(x["thickness_nm"]), str(x.get("name", "")))
                for x in d.get("layers", [])
            ]
            return cls(layers, as_material(d["substrate"]), as_material(d.get("ambient", 1.0)))
        except KeyError as exc:
            raise FilmError(f"stack: missing key {exc}") from None

    @classmethod
    def from_fit_json(cls, path: str | os.PathLike[str]) -> Stack:
        """The best-fit stack of a :meth:`FilmFit.save_json` file (:func:`read_fit_json`)."""
        return read_fit_json(path)[0]

    def __repr__(self) -> str:
        inner = ", ".join(
            f"{lay.name}: {lay.material.name} {lay.thickness_nm:.4g} nm" for lay in self.layers
        )
        return f"Stack([{inner}], substrate={self.substrate.name})"


# --------------------------------------------------------------------------------------
# film model: a stack plus the parameters to fit
# --------------------------------------------------------------------------------------


@dataclass
class FilmModel:
    """A stack and the parameters a fit varies.

    Parameters
    ----------
    stack : Stack
        Starting values of every parameter.
    free : dict
        ``"<layer>.<name>"`` -> (min, max) of each varying parameter.
    wavelength_range_nm : tuple, optional
        Only data in [min, max] are fitted.
    source : str
        The model file, for messages.
    """

    stack: Stack
    free: dict[str, tuple[float, float]] = field(default_factory=dict)
    wavelength_range_nm: tuple[float, float] | None = None
    source: str = "<model>"

    @classmethod
    def cauchy_on_silicon(cls) -> FilmModel:
        """The stated default for one transparent layer on silicon.

        A Cauchy layer (``A`` in [1.3, 2.6], ``B`` in [0, 0.1] um^2, ``C = 0``, ``k = 0``,
        thickness in [0, 1000] nm) on crystalline Si (Green 2008 table), fitted over the
        table's 250-1450 nm: a native or thermal oxide, nitride or polymer film on a wafer.
        """
        layer = Layer(disp.Cauchy(A=1.5, B=0.005), 100.0, "film")
        free = {"film.thickness_nm": (0.0, 1000.0), "film.A": (1.3, 2.6), "film.B": (0.0, 0.1)}
        return cls(Stack([layer], "si"), free, (250.0, 1450.0), "default: Cauchy layer on Si")

    @classmethod
    def default(cls, stack: Stack, thickness_max_nm: float | None = None) -> FilmModel:
        """The default fit of a stack.

        Vary every layer's thickness and every parametric layer material's parameters
        (default boxes of :mod:`labbrdf.dispersion`); the substrate and tables stay fixed.
        Thickness box: [0, max(3 d, 20 nm)] unless ``thickness_max_nm`` is given.
        """
        free: dict[str, tuple[float, float]] = {}
        for lay in stack.layers:
            hi = thickness_max_nm or max(3 * lay.thickness_nm, 20.0)
            free[f"{lay.name}.thickness_nm"] = (0.0, float(hi))
            if isinstance(lay.material, disp.Tabulated):
                continue
            for k, b in lay.material.bounds().items():
                if isinstance(lay.material, disp.Cauchy) and k in ("exponent", "band_edge"):
                    continue  # fixed unless asked: k_amp = 0 keeps the layer transparent
                if isinstance(lay.material, disp.Cauchy) and k == "k_amp":
                    continue
                free[f"{lay.name}.{k}"] = b
        return cls(stack, free)


# --------------------------------------------------------------------------------------
# TOML model files
# --------------------------------------------------------------------------------------

_LAYER_KEYS = {"name", "material", "model", "file", "reference", "thickness_nm", "fraction"}
_TOP_KEYS = ("ambient", "wavelength_nm", "substrate", "layer")


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


def _material_of(tbl: Mapping[str, Any], base: Path, at: Any) -> Material:
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
    try:
        if kind == "file":
            return _table_file(_named_file(val, base))
        return as_material(val)
    except (FilmError, disp.DispersionError) as exc:
        raise FilmError(f"{at(kind)}: {exc}") from None


def _material_from_table(
    tbl: Mapping[str, Any], where: str, base: Path, lines: _KeyLines, table: str, index: int | None
) -> tuple[Material, dict[str, float], dict[str, tuple[float, float]]]:
    """(material, parameter values, free boxes) of a [substrate] or [[layer]] table."""

    def at(key: str | None) -> str:
        return f"{where}, line {lines(table, index, key)}"

    m = _material_of(tbl, base, at)
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
            "wavelength_nm, [substrate], [[layer]]"
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
    tbl: Mapping[str, Any], j: int, where: str, base: Path, lines: _KeyLines
) -> tuple[Layer, dict[str, tuple[float, float]]]:
    """The ``j``-th [[layer]] table and its free boxes (``"<layer>.<name>"``)."""
    name = tbl.get("name", f"layer{j + 1}")
    if not isinstance(name, str):
        raise FilmError(f"{where}, line {lines('layer', j, 'name')}: name must be a string")
    if "thickness_nm" not in tbl:
        raise FilmError(f"{where}, line {lines('layer', j)}: layer {name!r} has no thickness_nm")
    m, _, mfree = _material_from_table(tbl, where, base, lines, "layer", j)
    at = f"{where}, line {lines('layer', j, 'thickness_nm')}: thickness_nm"
    d, dbox = _spec(tbl["thickness_nm"], at)
    if d < 0 or (dbox is not None and dbox[0] < 0):
        raise FilmError(f"{at} must be >= 0")
    if max(d, dbox[1] if dbox else d) > MAX_THICKNESS_NM:
        raise FilmError(
            f"{at} must be <= {MAX_THICKNESS_NM:g} nm (labbrdf.films.MAX_THICKNESS_NM): "
            "thicker is a substrate, not a film"
        )
    free = {f"{name}.{k}": b for k, b in mfree.items()}
    if dbox is not None:
        free[f"{name}.thickness_nm"] = dbox
    try:
        return Layer(m, d, name), free
    except FilmError as exc:
        raise FilmError(f"{where}, line {lines('layer', j)}: {exc}") from None


def load_model(path: str | os.PathLike[str]) -> FilmModel:
    """Read a film model file (TOML).

    Format::

        ambient = 1.0                  # optional, a number (lossless)
        wavelength_nm = [250, 1000]    # optional fit window [nm]

        [substrate]
        material = "si"                # si, sio2 (shipped tables), a model name, or
                                       # file = "ta.dat" (n,k table or ellipsometer file)

        [[layer]]                      # top first; repeat for more layers
        name = "oxide"
        material = "cauchy"            # constant, cauchy, sellmeier, tauc_lorentz, drude,
                                       # lorentz, roughness, si, sio2; or file = "..."
        thickness_nm = [0, 10]         # [min, max]: fitted, started mid-box
        A = [1.3, 1.7]
        B = 0.0036                     # a number: fixed
        C = {value = 0, min = -0.01, max = 0.01}   # full form (vary = false to fix)

    A ``file`` is relative to the model file's folder, and is an input of the command
    that reads the model (:func:`named_inputs`). The file is at most
    :data:`MAX_MODEL_BYTES` and names at most :data:`MAX_LAYERS` layers, each at most
    :data:`MAX_THICKNESS_NM` thick; every number is finite.

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
        doc["substrate"], where, p.parent, lines, "substrate", None
    )
    if isinstance(sub, Roughness):
        raise FilmError(f"{where}, line {lines('substrate')}: roughness is a layer")
    layers = []
    free: dict[str, tuple[float, float]] = {f"substrate.{k}": b for k, b in sub_free.items()}
    seen: set[str] = set()
    for j, tbl in enumerate(doc.get("layer", [])):
        layer, layer_free = _layer_of(tbl, j, where, p.parent, lines)
        if layer.name and (layer.name in seen or layer.name in ("substrate", "ambient")):
            raise FilmError(
                f"{where}, line {lines('layer', j, 'name')}: layer name {layer.name!r} is "
                "repeated or reserved ('substrate', 'ambient'); expected a unique name"
            )
        seen.add(layer.name)
        layers.append(layer)
        free.update(layer_free)
    try:
        st = Stack(layers, sub, ambient)
    except FilmError as exc:
        raise FilmError(f"{where}: {exc}") from None
    return FilmModel(st, free, wl_range, where)


def _model_files(doc: Mapping[str, Any], base: Path) -> list[Path]:
    """The ``file = ...`` paths of a parsed model file, as :func:`load_model` opens them."""
    tables = [doc.get("substrate")]
    layers = doc.get("layer")
    tables += layers if isinstance(layers, list) else []
    return [
        _named_file(t["file"], base)
        for t in tables
        if isinstance(t, dict) and isinstance(t.get("file"), str)
    ]


# --------------------------------------------------------------------------------------
# film fit JSON (FilmFit.save_json): its schema, read back
# --------------------------------------------------------------------------------------


def check_wavelength_range(rng: Sequence[float], what: str) -> tuple[float, float]:
    """A wavelength range [nm]: finite, ordered, within :data:`WAVELENGTH_LIMITS_NM`.

    Raises
    ------
    FilmError
        Naming ``what``.
    """
    lo, hi = (float(x) for x in rng)
    a, b = WAVELENGTH_LIMITS_NM
    if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
        raise FilmError(f"{what}: [{lo:g}, {hi:g}] is not a range [min, max] with min < max")
    if lo < a or hi > b:
        raise FilmError(
            f"{what}: [{lo:g}, {hi:g}] nm lies outside the wavelengths of optics "
            f"[{a:g}, {b:g}] nm (labbrdf.films.WAVELENGTH_LIMITS_NM)"
        )
    return lo, hi


def _fit_json_schema() -> dict[str, Any]:
    """The schema of what :meth:`FilmFit.save_json` writes and its readers use."""
    number = {"type": "number"}
    column = {"type": "array", "items": {"type": "number", "min": 0.0}, "min_items": 2}
    column["max_items"] = MAX_TABLE_POINTS
    model = {"type": "string", "enum": sorted({*disp.MODELS, "roughness"})}
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
    by_model.update(tabulated=table, roughness=rough)
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


def _tabulated(stack: Stack) -> list[tuple[str, disp.Tabulated]]:
    mats = [("ambient", stack.ambient), ("substrate", stack.substrate)]
    mats += [(lay.name, lay.material) for lay in stack.layers]
    return [(name, m) for name, m in mats if isinstance(m, disp.Tabulated)]


def _check_indices(stack: Stack, rng: tuple[float, float], where: str) -> None:
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


def read_fit_json(path: str | os.PathLike[str]) -> tuple[Stack, tuple[float, float]]:
    """The best-fit stack and the fitted wavelength range of a film fit JSON.

    The file (:meth:`labbrdf.FilmFit.save_json`, ``labbrdf film --fit-json``) is checked
    against the schema of what labbrdf writes before any value is used: the types and keys
    of ``stack`` (at most :data:`MAX_LAYERS` layers, thicknesses in [0,
    :data:`MAX_THICKNESS_NM`] nm, finite numbers, tables of at most
    :data:`MAX_TABLE_POINTS` rows) and ``wavelength_range_nm`` (finite, ordered, within
    :data:`WAVELENGTH_LIMITS_NM` and inside every table of the stack: a fit never used
    wavelengths its tables do not cover), and every medium's index over that range
    (finite, ``n > 0``, ``k >= 0``, ``|N| <=`` :data:`MAX_INDEX`). A ``file`` table is
    an input of the command (:func:`named_inputs`). The file is a regular file of at most
    :data:`MAX_FIT_JSON_BYTES`.

    Parameters
    ----------
    path : path-like
        The fit JSON.

    Returns
    -------
    (Stack, (float, float))
        The stack and the fitted range [nm].

    Raises
    ------
    FilmError
        Naming the file and the key: not JSON, not a film fit, a wrong type, a missing
        key, an implausible value.
    """
    p, doc = _fit_doc(path)
    try:
        stack = Stack.from_dict(doc["stack"])
    except (FilmError, disp.DispersionError) as exc:
        raise FilmError(f"{p}: stack: {exc}") from None
    try:
        rng = check_wavelength_range(doc["wavelength_range_nm"], "wavelength_range_nm")
    except FilmError as exc:
        raise FilmError(f"{p}: {exc}") from None
    _check_indices(stack, rng, str(p))
    for name, table in _tabulated(stack):
        if not table.covers(np.asarray(rng)):
            lo, hi = table.range_nm
            raise FilmError(
                f"{p}: wavelength_range_nm [{rng[0]:g}, {rng[1]:g}] nm reaches beyond the "
                f"{name} table ({lo:g}-{hi:g} nm), which the fit could not have used; "
                "expected the range the fit was made over"
            )
    return stack, rng


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
        return [Path(m["file"]) for m in mats if isinstance(m, dict) and "file" in m]
    raise ValueError(f"kind: expected 'model' or 'fit', got {kind!r}")


# the fit lives with the fitting core (labbrdf.fitting.film), which imports this module's
# objects; it is re-exported here lazily (PEP 562), so either module may be imported first
_FIT_NAMES = ("FilmFit", "fit_film", "woollam_mse")


def __getattr__(name: str) -> Any:
    if name in _FIT_NAMES:
        from .fitting import film as _fit

        return getattr(_fit, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
