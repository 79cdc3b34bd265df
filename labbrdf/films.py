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

if TYPE_CHECKING:  # at run time through __getattr__ below (the fit imports this module)
    from .fitting.film import FilmFit, fit_film, woollam_mse

__all__ = [
    "FILM_QUANTITIES",
    "FilmError",
    "FilmFit",
    "FilmModel",
    "Layer",
    "Roughness",
    "Stack",
    "fit_film",
    "load_model",
    "woollam_mse",
]

#: dataset quantities a film fit uses (psi/Delta at any angle; specular R and T, by
#: polarisation channel ``s``/``p`` or unpolarised)
FILM_QUANTITIES = ("psi", "delta", "reflectance", "transmittance")

#: wavelength at which a fit summary quotes each layer's n, k [nm] (He-Ne line)
NK_REPORT_NM = 633.0


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
        """The best-fit stack of a :meth:`FilmFit.save_json` file."""
        p = Path(path)
        try:
            doc = json.loads(p.read_text("utf-8"))
        except OSError as exc:
            raise FilmError(f"{p}: cannot read ({exc.strerror})") from None
        except json.JSONDecodeError as exc:
            raise FilmError(f"{p}, line {exc.lineno}: not JSON ({exc.msg})") from None
        if not isinstance(doc, dict) or "stack" not in doc:
            raise FilmError(
                f"{p}: not a film fit (no 'stack'); write one with labbrdf film --json"
            )
        return cls.from_dict(doc["stack"])

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


def _key_line(text: str, table: str, index: int | None, key: str | None) -> int:
    """1-based line of ``key`` inside table ``table`` (the ``index``-th ``[[table]]``)."""
    cur, count, first = "", -1, 0
    for lineno, raw in enumerate(text.splitlines(), 1):
        line = raw.split("#", 1)[0].strip()
        m = re.match(r"^\[\[\s*([\w.-]+)\s*\]\]$", line) or re.match(
            r"^\[\s*([\w.-]+)\s*\]$", line
        )
        if m:
            cur = m.group(1)
            if cur == table:
                count += 1
                if (index is None or count == index) and not first:
                    first = lineno
                    if key is None:
                        return lineno
            continue
        if cur == table and (index is None or count == index) and key is not None:
            if re.match(rf"^\"?{re.escape(key)}\"?\s*=", line):
                return lineno
    return first or 1


def _spec(value: Any, where: str) -> tuple[float, tuple[float, float] | None]:
    """A number (fixed), [min, max] (fitted from the middle) or {value, min, max, vary}."""
    if isinstance(value, bool):
        raise FilmError(f"{where}: expected a number, [min, max] or {{value, min, max}}")
    if isinstance(value, (int, float)):
        return float(value), None
    if isinstance(value, list):
        if len(value) != 2 or not all(
            isinstance(v, (int, float)) and not isinstance(v, bool) for v in value
        ):
            raise FilmError(f"{where}: expected [min, max] (two numbers), got {value!r}")
        lo, hi = float(value[0]), float(value[1])
        if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
            raise FilmError(f"{where}: impossible bounds [{lo:g}, {hi:g}] (need min < max)")
        return (lo + hi) / 2, (lo, hi)
    if isinstance(value, dict):
        bad = sorted(set(value) - {"value", "min", "max", "vary"})
        if bad:
            raise FilmError(f"{where}: unknown key(s) {bad}; expected value, min, max, vary")
        if "value" not in value and not ("min" in value and "max" in value):
            raise FilmError(f"{where}: give value, or min and max")
        lo = float(value.get("min", -math.inf))
        hi = float(value.get("max", math.inf))
        v = float(value.get("value", (lo + hi) / 2))
        vary = bool(value.get("vary", "min" in value or "max" in value))
        if vary:
            if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
                raise FilmError(f"{where}: impossible bounds [{lo:g}, {hi:g}] (need min < max)")
            if not lo <= v <= hi:
                raise FilmError(f"{where}: value {v:g} outside [{lo:g}, {hi:g}]")
            return v, (lo, hi)
        return v, None
    raise FilmError(f"{where}: expected a number, [min, max] or {{value, min, max}}")


def _material_from_table(
    tbl: Mapping[str, Any], where: str, base: Path, text: str, table: str, index: int | None
) -> tuple[Material, dict[str, float], dict[str, tuple[float, float]]]:
    """(material, parameter values, free boxes) of a [substrate] or [[layer]] table."""

    def at(key: str | None) -> str:
        return f"{where}, line {_key_line(text, table, index, key)}"

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
    if kind == "file":
        p = Path(val)
        p = p if p.is_absolute() else base / p
        try:
            m: Material = _table_file(p)
        except disp.DispersionError as exc:
            raise FilmError(f"{at(kind)}: {exc}") from None
    else:
        try:
            m = as_material(val)
        except (FilmError, disp.DispersionError) as exc:
            raise FilmError(f"{at(kind)}: {exc}") from None
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
        try:
            values[key], box = _spec(v, f"{at(key)}: {key}")
        except (TypeError, ValueError) as exc:
            if isinstance(exc, FilmError):
                raise
            raise FilmError(f"{at(key)}: {key}: {exc}") from None
        if box is not None:
            free[key] = box
    if values:
        try:
            m = _with_params(m, values)
        except (disp.DispersionError, FilmError) as exc:
            raise FilmError(f"{at(None)}: {exc}") from None
    return m, values, free


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

    Raises
    ------
    FilmError
        Naming the file and the line: TOML syntax, an unknown key, layer or parameter,
        impossible bounds, a missing substrate.
    """
    p = Path(path)
    try:
        text = p.read_text("utf-8")
    except OSError as exc:
        raise FilmError(f"{p}: cannot read the model file ({exc.strerror})") from None
    except UnicodeDecodeError:
        raise FilmError(f"{p}: not a UTF-8 text file (expected a TOML model)") from None
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise FilmError(f"{p}: not valid TOML ({exc})") from None
    where = str(p)
    top_bad = sorted(set(doc) - {"ambient", "wavelength_nm", "substrate", "layer"})
    if top_bad:
        key = top_bad[0]
        k = re.escape(key)
        pattern = rf"^\s*(\[\[\s*{k}\s*\]\]|\[\s*{k}\s*\]|\"?{k}\"?\s*=)"
        line = next((i for i, raw in enumerate(text.splitlines(), 1) if re.match(pattern, raw)), 1)
        raise FilmError(
            f"{where}, line {line}: unknown key or table {key!r}; expected ambient, "
            "wavelength_nm, [substrate], [[layer]]"
        )
    ambient: Any = doc.get("ambient", 1.0)
    if isinstance(ambient, bool) or not isinstance(ambient, (int, float)) or not ambient >= 1.0:
        ln = next(
            (i for i, r in enumerate(text.splitlines(), 1) if r.strip().startswith("ambient")), 1
        )
        raise FilmError(f"{where}, line {ln}: ambient must be a real index >= 1, got {ambient!r}")
    wl_range = None
    if "wavelength_nm" in doc:
        ln = next(
            (
                i
                for i, r in enumerate(text.splitlines(), 1)
                if r.strip().startswith("wavelength_nm")
            ),
            1,
        )
        w = doc["wavelength_nm"]
        if (
            not isinstance(w, list)
            or len(w) != 2
            or not all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in w)
            or not 0 < w[0] < w[1]
        ):
            raise FilmError(
                f"{where}, line {ln}: wavelength_nm must be [min, max] with 0 < min < max"
            )
        wl_range = (float(w[0]), float(w[1]))
    if "substrate" not in doc or not isinstance(doc["substrate"], dict):
        raise FilmError(f"{where}, line 1: missing [substrate] table")
    sub, _, sub_free = _material_from_table(
        doc["substrate"], where, p.parent, text, "substrate", None
    )
    if isinstance(sub, Roughness):
        raise FilmError(
            f"{where}, line {_key_line(text, 'substrate', None, None)}: roughness is a layer"
        )
    layers_doc = doc.get("layer", [])
    if not isinstance(layers_doc, list):
        raise FilmError(f"{where}: 'layer' must be an array of tables ([[layer]])")
    layers = []
    free: dict[str, tuple[float, float]] = {f"substrate.{k}": b for k, b in sub_free.items()}
    for j, tbl in enumerate(layers_doc):
        name = str(tbl.get("name", f"layer{j + 1}"))
        line = _key_line(text, "layer", j, None)
        if "thickness_nm" not in tbl:
            raise FilmError(f"{where}, line {line}: layer {name!r} has no thickness_nm")
        m, _, mfree = _material_from_table(tbl, where, p.parent, text, "layer", j)
        d, dbox = _spec(
            tbl["thickness_nm"],
            f"{where}, line {_key_line(text, 'layer', j, 'thickness_nm')}: thickness_nm",
        )
        if d < 0 or (dbox is not None and dbox[0] < 0):
            raise FilmError(
                f"{where}, line {_key_line(text, 'layer', j, 'thickness_nm')}: "
                "thickness_nm must be >= 0"
            )
        layers.append(Layer(m, d, name))
        if dbox is not None:
            free[f"{name}.thickness_nm"] = dbox
        free.update({f"{name}.{k}": b for k, b in mfree.items()})
    try:
        st = Stack(layers, sub, float(ambient))
    except FilmError as exc:
        raise FilmError(f"{where}: {exc}") from None
    return FilmModel(st, free, wl_range, where)


# the fit lives with the fitting core (labbrdf.fitting.film), which imports this module's
# objects; it is re-exported here lazily (PEP 562), so either module may be imported first
_FIT_NAMES = ("FilmFit", "fit_film", "woollam_mse")


def __getattr__(name: str) -> Any:
    if name in _FIT_NAMES:
        from .fitting import film as _fit

        return getattr(_fit, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
