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

import math
import os
from collections.abc import Mapping, Sequence
from dataclasses import replace
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..nk import dispersion as disp
from . import incoherent as inc
from . import matrices as stk
from . import nonuniform, spreads
from .ema import Ema
from .fitjson import _check_indices, _fit_doc, _tabulated
from .graded import Graded
from .layers import Layer
from .limits import MAX_LAYERS, MAX_THICKNESS_NM, FilmError, check_wavelength_range
from .materials import Roughness, TableReader, _with_params, as_material

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
    substrate_thickness_nm : float, optional
        A substrate of this thickness [nm] with the ambient behind it: an incoherent slab
        whose backside reflection adds in intensity (:mod:`labbrdf.films.incoherent`), as
        for a film on a glass slide. Default: semi-infinite (no backside reflection: a
        wafer, or a roughened or index-matched back).
    thickness_spread : float, optional
        Relative 1-sigma spread of every coherent layer's thickness over the measured spot,
        in [0, 0.1] [1] (:func:`labbrdf.films.nonuniform.spread_sums`): the parameter
        ``stack.thickness_spread``. Default: none (not a parameter).
    bandwidth_nm : float, optional
        Full width at half maximum of the instrument's Gaussian spectral band [nm], in [0,
        20] (:func:`labbrdf.films.spreads.beam_sums`): the parameter ``stack.bandwidth_nm``.
    angle_spread_deg : float, optional
        1-sigma Gaussian spread of the angle of incidence [deg], in [0, 2]: the parameter
        ``stack.angle_spread_deg``.

    Notes
    -----
    A stack with an incoherent layer or a finite substrate has no amplitudes; its psi and
    Delta are those of the incoherent sum of the reflected light (:meth:`psi_delta`), which
    is partly depolarized (:meth:`depolarization`, :meth:`mueller`).
    """

    def __init__(
        self,
        layers: Sequence[Layer],
        substrate: Any,
        ambient: Any = 1.0,
        substrate_thickness_nm: float | None = None,
        thickness_spread: float | None = None,
        bandwidth_nm: float | None = None,
        angle_spread_deg: float | None = None,
    ) -> None:
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
            named.append(lay if lay.name else replace(lay, name=f"layer{j}"))
        names = [lay.name for lay in named]
        dup = sorted({n for n in names if names.count(n) > 1})
        if dup:
            raise FilmError(f"layer names must be unique; repeated: {dup}")
        if set(names) & {"substrate", "ambient", "stack"}:
            raise FilmError("'substrate', 'ambient' and 'stack' are reserved names")
        self.layers: tuple[Layer, ...] = tuple(named)
        sub, amb = as_material(substrate), as_material(ambient)
        for m in (sub, amb):
            if isinstance(m, (Roughness, Ema, Graded)):
                raise FilmError(f"{m.name} is a layer, not a substrate or ambient")
        assert isinstance(sub, disp.Dispersion) and isinstance(amb, disp.Dispersion)
        _check_references(self.layers)
        self.substrate: disp.Dispersion = sub
        self.ambient: disp.Dispersion = amb
        self.substrate_thickness_nm = _substrate_thickness(substrate_thickness_nm)
        self.thickness_spread = _spread(thickness_spread)
        self.bandwidth_nm = _beam_value(bandwidth_nm, spreads.MAX_BANDWIDTH_NM, "bandwidth_nm")
        self.angle_spread_deg = _beam_value(
            angle_spread_deg, spreads.MAX_ANGLE_SPREAD_DEG, "angle_spread_deg"
        )

    @property
    def coherent(self) -> bool:
        """True when every layer is coherent, the substrate semi-infinite and no spread."""
        flat = not (self.thickness_spread or self.bandwidth_nm or self.angle_spread_deg)
        return (
            flat and self.substrate_thickness_nm is None and all(x.coherent for x in self.layers)
        )

    @property
    def depolarizing(self) -> bool:
        """True when the model can depolarize: a spread parameter, a thick layer or backside.

        Any of ``stack.thickness_spread``, ``stack.bandwidth_nm``, ``stack.angle_spread_deg``
        present (even at 0: a fit may move it), an incoherent layer or a finite substrate.
        """
        beam = (self.thickness_spread, self.bandwidth_nm, self.angle_spread_deg)
        return (
            any(v is not None for v in beam)
            or self.substrate_thickness_nm is not None
            or not all(x.coherent for x in self.layers)
        )

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
        ambient; an :class:`~labbrdf.films.ema.Ema` layer that of its constituents
        (:func:`labbrdf.films.ema.bruggeman_mix`), ``@NAME`` ones taken from the
        material of the layer ``NAME``.
        A :class:`~labbrdf.films.graded.Graded` layer gives its index at mid-depth here; the
        optics use its slices.
        """
        lam = np.asarray(wavelength_nm, float)
        n_amb = self._ambient_nk(lam)
        below = np.asarray(self.substrate.nk(lam))
        out = [below]
        for lay in reversed(self.layers):
            m = lay.material.at(0.5) if isinstance(lay.material, Graded) else lay.material
            below = self._layer_index(m, lam, below, n_amb)
            out.append(below)
        out.append(n_amb)
        return out[::-1]

    def _layer_index(
        self,
        m: Any,
        lam: NDArray,
        below: NDArray,
        n_amb: NDArray,
        memo: dict[int, tuple[Any, NDArray]] | None = None,
    ) -> NDArray:
        """The index of one homogeneous layer material (a mixture from its constituents).

        ``memo`` keeps each plain material's index by identity for one evaluation: an
        ``@NAME`` constituent is then the index its layer has, computed once.
        """
        memo = {} if memo is None else memo
        if isinstance(m, Roughness):
            n = np.sqrt(stk.bruggeman(below * below, n_amb * n_amb + 0j, m.fraction))
        elif isinstance(m, Ema):
            eps = [self._constituent(c, lam, n_amb, memo) ** 2 for c in m.components]
            n = np.sqrt(m.mix(eps))
        else:
            return _memo_nk(m, lam, memo)
        return np.asarray(np.where(n.imag < 0, -n, n))

    def _optical(self, lam: NDArray) -> tuple[list[NDArray], list[float], list[bool]]:
        """Indices, thicknesses and coherence flags as computed (graded layers in slices)."""
        n_amb = self._ambient_nk(lam)
        below = np.asarray(self.substrate.nk(lam))
        n_out, d_out, c_out = [below], [], []
        memo: dict[int, tuple[Any, NDArray]] = {}
        for lay in reversed(self.layers):
            m = lay.material
            parts = m.slices()[::-1] if isinstance(m, Graded) else [m]
            for part in parts:
                below = self._layer_index(part, lam, below, n_amb, memo)
                n_out.append(below)
                d_out.append(lay.thickness_nm / len(parts))
                c_out.append(lay.coherent)
        n_out.append(n_amb)
        return n_out[::-1], d_out[::-1], c_out[::-1]

    def _constituent(
        self, c: Any, lam: NDArray, n_amb: NDArray, memo: dict[int, tuple[Any, NDArray]]
    ) -> NDArray:
        """The index of an EMA constituent: a material, or ``@NAME`` of the stack."""
        if not isinstance(c, str):
            return np.asarray(c.nk(lam), complex)
        ref = c[1:]
        if ref == "ambient":
            return np.asarray(n_amb, complex)
        if ref == "substrate":
            return np.asarray(self.substrate.nk(lam), complex)
        (lay,) = (x for x in self.layers if x.name == ref)
        return np.asarray(_memo_nk(lay.material, lam, memo), complex)

    def _thicknesses(self) -> list[float]:
        return [lay.thickness_nm for lay in self.layers]

    def _grid(self, wavelength_nm: ArrayLike, theta_deg: ArrayLike):
        lam = np.asarray(wavelength_nm, float)
        n, d, _ = self._optical(lam)
        return n, d, lam, np.asarray(theta_deg, float)

    def intensity_sums(self, wavelength_nm: ArrayLike, theta_deg: ArrayLike) -> inc.IntensitySums:
        """R_s, R_p, the s-p cross term X and T_s, T_p (:func:`~.incoherent.intensity_sums`).

        Any stack, coherent or not; inputs broadcast. With a finite substrate the medium
        behind it is the ambient and T is the light that leaves the backside.
        """
        lam = np.asarray(wavelength_nm, float)
        n, d, flags = self._optical(lam)
        if self.substrate_thickness_nm is not None:
            n, d, flags = [*n, n[0]], [*d, self.substrate_thickness_nm], [*flags, False]
        th = np.asarray(theta_deg, float)
        spread = self.thickness_spread

        def sums(lam_k: NDArray, th_k: NDArray) -> inc.IntensitySums:
            if spread:  # indices held at the centre wavelengths (spreads.beam_sums, Notes)
                return nonuniform.spread_sums(n, d, flags, lam_k, th_k, spread)
            return inc.intensity_sums(n, d, flags, lam_k, th_k)

        if not (self.bandwidth_nm or self.angle_spread_deg):
            return sums(lam, th)
        path = sum(
            float(np.max(np.abs(np.real(nj)))) * dj
            for nj, dj, c in zip(n[1:-1], d, flags, strict=True)
            if c
        )
        return spreads.beam_sums(
            sums, lam, th, self.bandwidth_nm or 0.0, self.angle_spread_deg or 0.0, path
        )

    def psi_delta(
        self, wavelength_nm: ArrayLike, theta_deg: ArrayLike
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """psi, Delta [deg] (Nebraska convention, Delta in [0, 360)); inputs broadcast.

        With incoherent layers: psi from ``R_p / R_s`` and Delta the phase of the cross
        term (:func:`labbrdf.films.incoherent.ellipsometry`).
        """
        if self.coherent:
            return stk.ellipsometry(*self._grid(wavelength_nm, theta_deg))
        psi, delta, _ = inc.ellipsometry(self.intensity_sums(wavelength_nm, theta_deg))
        return psi, delta

    def depolarization(
        self, wavelength_nm: ArrayLike, theta_deg: ArrayLike
    ) -> NDArray[np.float64]:
        """``1 - sqrt(N^2 + C^2 + S^2)`` of the reflected light [1] (0 for a coherent stack)."""
        return inc.ellipsometry(self.intensity_sums(wavelength_nm, theta_deg))[2]

    def mueller(self, wavelength_nm: ArrayLike, theta_deg: ArrayLike) -> NDArray[np.float64]:
        """Mueller matrix of the specular reflection, shape ``(..., 4, 4)`` [1]."""
        return inc.mueller(self.intensity_sums(wavelength_nm, theta_deg))

    def reflectance(
        self, wavelength_nm: ArrayLike, theta_deg: ArrayLike
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """R_s, R_p [1]; inputs broadcast."""
        if self.coherent:
            return stk.reflectance(*self._grid(wavelength_nm, theta_deg))
        sums = self.intensity_sums(wavelength_nm, theta_deg)
        return sums.Rs, sums.Rp

    def transmittance(
        self, wavelength_nm: ArrayLike, theta_deg: ArrayLike
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """T_s, T_p into the substrate (out of its back if it is finite) [1]; inputs broadcast."""
        if self.coherent:
            return stk.transmittance(*self._grid(wavelength_nm, theta_deg))
        sums = self.intensity_sums(wavelength_nm, theta_deg)
        return sums.Ts, sums.Tp

    def amplitudes(self, wavelength_nm: ArrayLike, theta_deg: ArrayLike):
        """r_s, r_p, t_s, t_p (:func:`labbrdf.films.matrices.amplitudes`); inputs broadcast.

        Raises
        ------
        FilmError
            The stack has an incoherent layer or a finite substrate (no amplitudes).
        """
        if not self.coherent:
            raise FilmError(
                "a stack with an incoherent layer, a finite substrate or a thickness spread "
                "has no amplitudes; "
                "use intensity_sums, reflectance or psi_delta"
            )
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
        if self.substrate_thickness_nm is not None:
            out["substrate.thickness_nm"] = self.substrate_thickness_nm
        for k, v in self._beam().items():
            out[f"stack.{k}"] = v
        return out

    def _beam(self) -> dict[str, float]:
        """The spread parameters that are present, by name."""
        beam = {
            "thickness_spread": self.thickness_spread,
            "bandwidth_nm": self.bandwidth_nm,
            "angle_spread_deg": self.angle_spread_deg,
        }
        return {k: v for k, v in beam.items() if v is not None}

    def units(self) -> dict[str, str]:
        """Units of every parameter of :meth:`values`."""
        out: dict[str, str] = {}
        for lay in self.layers:
            out[f"{lay.name}.thickness_nm"] = "nm"
            out.update({f"{lay.name}.{k}": u for k, u in lay.material.units().items()})
        out.update({f"substrate.{k}": u for k, u in self.substrate.units().items()})
        if self.substrate_thickness_nm is not None:
            out["substrate.thickness_nm"] = "nm"
        beam_units = {"thickness_spread": "1", "bandwidth_nm": "nm", "angle_spread_deg": "deg"}
        for k in self._beam():
            out[f"stack.{k}"] = beam_units[k]
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
            layers.append(replace(lay, material=_with_params(lay.material, p), thickness_nm=d))
        p = dict(per.get("substrate", {}))
        d_sub = p.pop("thickness_nm", self.substrate_thickness_nm)
        beam = {**self._beam(), **per.get("stack", {})}
        return Stack(layers, _with_params(self.substrate, p), self.ambient, d_sub, **beam)

    # ---- serialisation
    def to_dict(self) -> dict[str, Any]:
        """JSON-safe form (inverse: :meth:`from_dict`)."""
        out: dict[str, Any] = {
            "ambient": self.ambient.to_dict(),
            "layers": [lay.to_dict() for lay in self.layers],
            "substrate": self.substrate.to_dict(),
        }
        if self.substrate_thickness_nm is not None:
            out["substrate_thickness_nm"] = self.substrate_thickness_nm
        out.update(self._beam())
        return out

    @classmethod
    def from_dict(cls, d: Mapping[str, Any], read_table: TableReader | None = None) -> Stack:
        """A stack from :meth:`to_dict`'s form.

        ``read_table`` reads a material named by a file (:func:`as_material`, e.g.
        :func:`labbrdf.nk.tabulated_from_file`); without it such a stack is refused.
        """
        try:
            layers = [
                Layer(
                    as_material(x["material"], read_table),
                    float(x["thickness_nm"]),
                    str(x.get("name", "")),
                    bool(x.get("coherent", True)),
                )
                for x in d.get("layers", [])
            ]
            sub = as_material(d["substrate"], read_table)
            amb = as_material(d.get("ambient", 1.0), read_table)
            beam = {
                k: d[k] for k in ("thickness_spread", "bandwidth_nm", "angle_spread_deg") if k in d
            }
            return cls(layers, sub, amb, d.get("substrate_thickness_nm"), **beam)
        except KeyError as exc:
            raise FilmError(f"stack: missing key {exc}") from None

    @classmethod
    def from_fit_json(
        cls, path: str | os.PathLike[str], read_table: TableReader | None = None
    ) -> Stack:
        """The best-fit stack of a :meth:`FilmFit.save_json` file (:func:`read_fit_json`)."""
        return read_fit_json(path, read_table)[0]

    def __repr__(self) -> str:
        inner = ", ".join(
            f"{lay.name}: {lay.material.name} {lay.thickness_nm:.4g} nm"
            + ("" if lay.coherent else " incoherent")
            for lay in self.layers
        )
        d = self.substrate_thickness_nm
        thick = "" if d is None else f", substrate_thickness_nm={d:.6g}"
        for k, v in self._beam().items():
            thick += f", {k}={v:.4g}"
        return f"Stack([{inner}], substrate={self.substrate.name}{thick})"


def _memo_nk(m: Any, lam: NDArray, memo: dict[int, tuple[Any, NDArray]]) -> NDArray:
    """``m.nk(lam)``, computed once per evaluation (``memo`` holds ``m``: its id stays its)."""
    if id(m) not in memo:
        memo[id(m)] = (m, np.asarray(m.nk(lam)))
    return memo[id(m)][1]


def _check_references(layers: Sequence[Layer]) -> None:
    """Every ``@NAME`` of an EMA names another layer of plain material, or the media."""
    kinds = {lay.name: lay.material for lay in layers}
    for lay in layers:
        m = lay.material.base if isinstance(lay.material, Graded) else lay.material
        if not isinstance(m, Ema):
            continue
        for ref in m.references:
            if ref in ("substrate", "ambient"):
                continue
            if ref not in kinds or ref == lay.name:
                others = sorted(set(kinds) - {lay.name})
                raise FilmError(
                    f"layer {lay.name!r}: ema constituent '@{ref}' names no other layer; "
                    f"expected one of {others + ['substrate', 'ambient']}"
                )
            if isinstance(kinds[ref], (Roughness, Ema, Graded)):
                raise FilmError(
                    f"layer {lay.name!r}: ema constituent '@{ref}' is itself a mixture or "
                    "graded; expected a layer of one material"
                )


def _spread(s: Any) -> float | None:
    """None (no parameter) or a relative thickness spread in [0, MAX_SPREAD]."""
    if s is None:
        return None
    try:
        v = float(s)
    except (TypeError, ValueError):
        raise FilmError(f"thickness_spread: expected a number, got {s!r}") from None
    if not 0.0 <= v <= nonuniform.MAX_SPREAD:
        raise FilmError(
            f"thickness_spread: expected a relative spread in [0, {nonuniform.MAX_SPREAD}], "
            f"got {s!r}"
        )
    return v


def _beam_value(v: Any, top: float, what: str) -> float | None:
    """None (no parameter) or a bandwidth / angle spread in [0, top]."""
    if v is None:
        return None
    try:
        x = float(v)
    except (TypeError, ValueError):
        raise FilmError(f"{what}: expected a number, got {v!r}") from None
    if not 0.0 <= x <= top:
        raise FilmError(f"{what}: expected a value in [0, {top:g}], got {v!r}")
    return x


def _substrate_thickness(d: Any) -> float | None:
    """None (semi-infinite) or a finite thickness in (0, MAX_THICKNESS_NM] [nm]."""
    if d is None:
        return None
    try:
        v = float(d)
    except (TypeError, ValueError):
        raise FilmError(f"substrate_thickness_nm: expected a number, got {d!r}") from None
    if not (math.isfinite(v) and 0.0 < v <= MAX_THICKNESS_NM):
        raise FilmError(
            f"substrate_thickness_nm: expected a thickness in (0, {MAX_THICKNESS_NM:g}] nm "
            f"(labbrdf.films.MAX_THICKNESS_NM), got {d!r}"
        )
    return v


def read_fit_json(
    path: str | os.PathLike[str], read_table: TableReader | None = None
) -> tuple[Stack, tuple[float, float]]:
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
    read_table : callable, optional
        Reads a material named by a file (:func:`labbrdf.nk.tabulated_from_file`); without
        it a stack naming a file is refused.

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
        stack = Stack.from_dict(doc["stack"], read_table)
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
