"""The thin-film stack: layers over a substrate, its indices, psi/Delta, R and T.

A :class:`Stack` of :class:`~labbrdf.Layer` s over a substrate computes psi/Delta,
reflectance and transmittance with the transfer matrices of :mod:`labbrdf.films.matrices`
(the one coherent multilayer) from :mod:`labbrdf.nk.dispersion` materials. A stack is read
back from a film fit's JSON by :func:`read_fit_json` (:mod:`labbrdf.films.fitjson` checks it).

Parameter names are ``"<layer>.<parameter>"``: ``"oxide.thickness_nm"``, ``"oxide.A"``,
``"substrate.omega_p"``, ``"rough.fraction"``.

>>> from labbrdf.films import Layer, Stack
>>> s = Stack([Layer("sio2", 2.0, name="oxide")], substrate="si")
>>> psi, delta = s.psi_delta(633.0, 70.0)
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..nk import dispersion as disp
from . import matrices as stk
from .fitjson import _check_indices, _fit_doc, _tabulated
from .layers import Layer
from .limits import MAX_LAYERS, FilmError, check_wavelength_range
from .materials import Roughness, _with_params, as_material

__all__ = ["Stack", "read_fit_json"]


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

        A :class:`Roughness` layer is the Bruggeman mixture
        (:func:`labbrdf.films.matrices.bruggeman`) of the medium directly below it and the
        ambient.
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
        """r_s, r_p, t_s, t_p (:func:`labbrdf.films.matrices.amplitudes`); inputs broadcast."""
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
