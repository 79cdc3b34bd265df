"""NeXus ellipsometry files (``.nxs``, HDF5, application definition ``NXellipsometry``).

NeXus stores a measurement in an HDF5 file: groups tagged with an ``NX_class`` attribute,
fields with a ``units`` attribute. An ``NXentry`` group whose ``definition`` field is
``NXellipsometry`` holds one ellipsometry measurement. Two layouts of the definition are
in use, and both are read:

current (``NXellipsometry`` extending ``NXoptical_spectroscopy``)
    ``/ENTRY/data_collection/measured_data`` of shape (N_measurements, N_observables,
    N_spectrum), ``measured_data_errors`` of the same shape (optional), ``data_type``
    (``Psi/Delta``), the spectral axis in a field named ``*_spectrum`` (e.g.
    ``wavelength_spectrum``) beside it, and the angles of incidence in
    ``/ENTRY/instrument/angle_of_incidence``; measurement i is taken at angle i.
draft of 2022 (definition version 0.0.2, as pyElli's example file)
    ``/ENTRY/sample/measured_data`` of shape (N_time, N_p1, N_angles, N_variables,
    N_wavelength), ``data_error`` of the same shape (or the text ``NOT_PROVIDED``),
    ``data_type`` (``psi/delta``) and ``column_names`` (``['psi', 'delta']``, the order of
    the variables), ``/ENTRY/instrument/spectrometer/wavelength`` and
    ``/ENTRY/instrument/angle_of_incidence``; a time series has its relative times in
    ``/ENTRY/sample/time_points``.

Units come from each field's ``units`` attribute: the spectral axis in angstrom, nm, um,
m, eV or cm-1 (converted to nm; eV with hc = 1239.841984 eV nm, CODATA 2018), the angles of
incidence in degrees or radians. Psi and Delta are in degrees unless ``measured_data``
says radians; where it states no unit (the 2022 draft writes ``NOT_PROVIDED``), degrees are
taken when the values show it (some Psi above pi/2 or some Delta beyond 2 pi, which radians
cannot reach), and the file is refused otherwise. Delta is wrapped into [0, 360).

Refused by name, with the reason: an HDF5 file that is not NeXus (no ``NXentry``), a NeXus
file of another application definition, a ``data_type`` other than Psi/Delta (Mueller
matrix, tan(Psi)/cos(Delta), N/C/S, Jones matrix, raw data, intensity: their sign and
normalisation conventions are not stated in the file), a measurement varied over another
parameter than the angle of incidence (and time, in the 2022 draft), and arrays whose
shapes disagree. Every array's shape and type are checked before it is read, so a file
that declares a huge dataset is refused before anything is allocated.

Reading needs :mod:`h5py` (the ``nexus`` extra: ``pip install labbrdf[nexus]``); the file is
opened read-only and without HDF5 file locking, so nothing is ever written to it. The HDF5
library follows the file's internal addresses without checking them, and a few damaged
bytes can make it loop forever: the file is read in a child process, which is stopped
after :data:`READ_TIMEOUT_S` seconds, and the file is refused (inside a daemonic process,
such as a dask worker, which may not start one, it is read in place).
"""

from __future__ import annotations

import multiprocessing as mp
import os
import threading
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from ..dataset import Measurement, wrap_delta
from ._base import MAX_POINTS, AdapterError, Example, Format, check_regular_file
from ._frame import build_frame, group_angles, measurement

__all__ = ["FORMATS", "HDF5_MAGIC", "is_hdf5", "read_nexus"]

INSTRUMENT = "nexus-nxellipsometry"

#: The HDF5 format signature, at offset 0 or after a user block of 512, 1024, 2048, ...
#: bytes.
HDF5_MAGIC = b"\x89HDF\r\n\x1a\n"
#: h c [eV nm] (CODATA 2018, exact)
_HC_EV_NM = 1239.8419843320026
#: spectral units attribute (lower case) -> (label, conversion of the values to nm)
_SPECTRAL_UNITS: dict[str, tuple[str, Any]] = {
    **{u: ("angstrom", lambda x: x / 10.0) for u in ("angstrom", "angstroms", "a", "å")},
    **{u: ("nm", lambda x: x) for u in ("nm", "nanometer", "nanometre", "nanometers")},
    **{u: ("um", lambda x: x * 1000.0) for u in ("um", "µm", "micrometer", "micron", "microns")},
    **{u: ("m", lambda x: x * 1e9) for u in ("m", "meter", "metre")},
    **{u: ("eV", lambda x: _HC_EV_NM / x) for u in ("ev", "electronvolt")},
    **{u: ("cm-1", lambda x: 1e7 / x) for u in ("cm-1", "1/cm", "cm^-1")},
}
_DEGREES = {"degree", "degrees", "deg", "°"}
_RADIANS = {"rad", "radian", "radians"}
#: a units attribute that states nothing
_NO_UNIT = {"", "not_provided", "none", "nx_any", "nx_angle"}
#: most values one numeric array may hold (the data array: N_spectrum x observables x ...)
MAX_VALUES = 4 * MAX_POINTS
#: most seconds the HDF5 library may take to read one file (a damaged file can make it loop)
READ_TIMEOUT_S = 60.0
#: most characters of a text field that is read (names, data type)
_MAX_TEXT = 1000


def is_hdf5(head: bytes) -> bool:
    """True when the bytes start with the HDF5 signature (at 0 or after a user block)."""
    return any(head[k : k + 8] == HDF5_MAGIC for k in (0, 512, 1024, 2048, 4096) if k < len(head))


def _import_h5py(path: str | os.PathLike[str]) -> Any:
    try:
        import h5py
    except ImportError:
        raise AdapterError(
            path,
            "is an HDF5 (NeXus) file; reading it needs the h5py package: "
            "pip install 'labbrdf[nexus]'",
        ) from None
    return h5py


def read_nexus(path: str | os.PathLike[str]) -> Measurement:
    """Read psi and Delta from a NeXus ``NXellipsometry`` file.

    Parameters
    ----------
    path : str or path-like
        The ``.nxs`` file.

    Returns
    -------
    Measurement
        ``psi`` and ``delta`` [deg] (sigma where the file has errors) against wavelength
        [nm] and angle of incidence [deg], theta_r = theta_i and phi_r = 180 deg (specular
        reflection); ``time_s`` for a time series. ``meta`` holds the definition, layout,
        entry names, the units found and the acquisition program.

    Raises
    ------
    AdapterError
        Not HDF5, not NeXus, not NXellipsometry, data that are not Psi/Delta, missing or
        inconsistent fields, units that cannot be told; each with the file and the HDF5
        path of the field.
    """
    check_regular_file(path)
    if os.path.getsize(path) == 0:
        raise AdapterError(path, "the file is empty")
    _import_h5py(path)
    if mp.current_process().daemon:  # a daemonic process may not start one (dask workers)
        return _read_here(os.fspath(path))
    return _read_in_child(path)


def _read_here(path: str) -> Measurement:
    h5py = _import_h5py(path)
    try:
        with h5py.File(path, "r", locking=False) as f:
            return _read_file(path, f)
    except AdapterError:
        raise
    except (OSError, RuntimeError, KeyError, ValueError, TypeError, IndexError) as exc:
        # a damaged HDF5 structure surfaces as one of these from the HDF5 library
        raise AdapterError(
            path, f"not a readable HDF5 file ({type(exc).__name__}: {str(exc)[:200]})"
        ) from None


def _child(path: str, conn: Any) -> None:
    """Read in a child process and send back (True, Measurement) or (False, error)."""
    result: tuple[bool, Any]
    try:
        result = (True, _read_here(path))
    except AdapterError as exc:
        result = (False, exc)
    except MemoryError:
        result = (False, AdapterError(path, "ran out of memory reading it (corrupt sizes?)"))
    conn.send(result)
    conn.close()


def _read_in_child(path: str | os.PathLike[str]) -> Measurement:
    """Read the file in a child process that is stopped after :data:`READ_TIMEOUT_S`.

    The HDF5 library trusts the file's internal addresses: a few damaged bytes (a heap
    reference of a text field) can make it loop forever or crash, which must not take the
    caller with it.
    """
    method = "fork" if "fork" in mp.get_all_start_methods() else "spawn"
    if threading.active_count() > 1:  # forking a threaded process is unsafe
        method = "spawn"
    ctx: Any = mp.get_context(method)
    receiver, sender = ctx.Pipe(duplex=False)
    proc = ctx.Process(target=_child, args=(os.fspath(path), sender), daemon=True)
    proc.start()
    sender.close()
    try:
        if not receiver.poll(READ_TIMEOUT_S):
            raise AdapterError(
                path,
                f"the HDF5 library did not finish reading the file in {READ_TIMEOUT_S:g} s "
                "(damaged internal structure?)",
            )
        try:
            ok, payload = receiver.recv()
        except EOFError:
            proc.join(5)
            raise AdapterError(
                path,
                f"the HDF5 library stopped while reading the file (exit code {proc.exitcode}; "
                "damaged internal structure?)",
            ) from None
    finally:
        if proc.is_alive():
            proc.kill()
        proc.join()
        receiver.close()
    if ok:
        return payload
    raise payload


def _read_file(path: str | os.PathLike[str], f: Any) -> Measurement:
    entries = _ellipsometry_entries(path, f)
    frames = []
    metas = []
    for name in entries:
        frame, meta = _read_entry(path, f[name], name)
        frames.append(frame)
        metas.append(meta)
    data = pd.concat(frames, ignore_index=True) if len(frames) > 1 else frames[0]
    meta = {
        "format": INSTRUMENT,
        "entries": metas,
        "angles_deg": group_angles(data["theta_i_deg"].to_numpy()),
        "wavelength_nm": [float(data["wavelength_nm"].min()), float(data["wavelength_nm"].max())],
        "delta_range": "[0, 360)",
        "delta_convention": "as written in the file (NXellipsometry does not state one)",
        "dropped_points": sum(m["dropped_points"] for m in metas),
    }
    return measurement(path, data, meta)


# ----------------------------------------------------------------------------- structure


def _attr_text(obj: Any, name: str) -> str:
    v = obj.attrs.get(name)
    if v is None:
        return ""
    if isinstance(v, np.ndarray):
        v = v.reshape(-1)[0] if v.size == 1 else ""
    if isinstance(v, bytes):
        v = v.decode("utf-8", "replace")
    return str(v)[:_MAX_TEXT].strip()


def _is_dataset(obj: Any) -> bool:
    return hasattr(obj, "shape") and hasattr(obj, "dtype")


def _text(path: str | os.PathLike[str], group: Any, name: str) -> str | None:
    """A scalar text field, or None when absent."""
    obj = group.get(name)
    if obj is None or not _is_dataset(obj):
        return None
    if obj.shape not in ((), (1,)) or obj.dtype.kind not in "SOU":
        return None
    if obj.dtype.kind in "SU" and obj.dtype.itemsize > 4 * _MAX_TEXT:
        return None
    v = obj[()]
    if isinstance(v, np.ndarray):
        v = v.reshape(-1)[0]
    if isinstance(v, bytes):
        v = v.decode("utf-8", "replace")
    return str(v)[:_MAX_TEXT].strip()


def _ellipsometry_entries(path: str | os.PathLike[str], f: Any) -> list[str]:
    """Names of the root's NXentry groups whose definition is NXellipsometry."""
    entries = [
        k
        for k in list(f.keys())[:1000]
        if _attr_text(f[k], "NX_class") in ("NXentry", "NXsubentry")
    ]
    if not entries:
        raise AdapterError(
            path,
            "an HDF5 file without a NeXus NXentry group: not a NeXus file; labbrdf reads HDF5 "
            "only as NeXus NXellipsometry",
        )
    defs = {k: _text(path, f[k], "definition") or "" for k in entries}
    ours = [k for k in entries if defs[k] == "NXellipsometry"]
    if not ours:
        found = sorted({d or "(none)" for d in defs.values()})
        raise AdapterError(
            path,
            f"a NeXus file of application definition {', '.join(found)}, not NXellipsometry: "
            "labbrdf reads NeXus only as NXellipsometry (psi/Delta)",
        )
    return ours


def _array(
    path: str | os.PathLike[str], group: Any, name: str, where: str, rank: tuple[int, ...]
) -> np.ndarray:
    """A numeric field of an allowed rank, its size checked before it is read."""
    obj = group.get(name)
    if obj is None or not _is_dataset(obj):
        raise AdapterError(path, f"no field {where}/{name}")
    if obj.dtype.kind not in "fiu" or obj.ndim not in rank:
        raise AdapterError(
            path,
            f"{where}/{name}: expected a numeric array of rank {' or '.join(map(str, rank))}, "
            f"found {obj.dtype} of shape {obj.shape}",
        )
    size = int(np.prod(obj.shape, dtype=np.int64)) if obj.ndim else 1
    if size > MAX_VALUES:
        raise AdapterError(
            path, f"{where}/{name} declares {size} values, over the limit of {MAX_VALUES}"
        )
    if size == 0:
        raise AdapterError(path, f"{where}/{name} is empty (shape {obj.shape})")
    return np.asarray(obj[()], dtype=float)


def _units(group: Any, name: str) -> str:
    obj = group.get(name)
    return _attr_text(obj, "units") if obj is not None else ""


# ----------------------------------------------------------------------------- layouts


class _Raw:
    """One entry's arrays in the file's units, psi/Delta first and second on axis 1."""

    def __init__(
        self,
        data: np.ndarray,
        sigma: np.ndarray | None,
        spectrum: tuple[np.ndarray, str, str],
        aoi: tuple[np.ndarray, str, str],
        data_where: str,
        layout: str,
        data_unit: str,
        time_s: np.ndarray | None = None,
    ) -> None:
        self.data = data  # (N_measurements, 2, N_spectrum)
        self.sigma = sigma
        self.spectrum, self.spectrum_unit, self.spectrum_where = spectrum
        self.aoi, self.aoi_unit, self.aoi_where = aoi
        self.data_where = data_where
        self.layout = layout
        self.data_unit = data_unit
        self.time_s = time_s


def _psi_delta_order(
    path: str | os.PathLike[str], data_type: str | None, names: list[str] | None, where: str
) -> tuple[int, int]:
    """Indices of psi and Delta among the observables, or refuse another data type."""
    if data_type is None and names is None:
        raise AdapterError(
            path, f"no {where}/data_type: cannot tell whether the data are Psi/Delta"
        )
    if data_type is not None and data_type.replace(" ", "").lower() != "psi/delta":
        raise AdapterError(
            path,
            f"{where}/data_type is {data_type!r}: labbrdf reads NXellipsometry Psi/Delta "
            "data only (the file does not state the sign and normalisation conventions "
            "other data types need); export Psi/Delta",
        )
    if names is None:
        return 0, 1
    low = [n.strip().lower() for n in names]
    if "psi" not in low or "delta" not in low:
        raise AdapterError(
            path, f"{where}/column_names is {names}: expected 'psi' and 'delta' among them"
        )
    return low.index("psi"), low.index("delta")


def _names(path: str | os.PathLike[str], group: Any, name: str, n: int, where: str) -> list[str]:
    """A short 1-d text array (column names) of ``n`` entries."""
    obj = group.get(name)
    if obj is None or not _is_dataset(obj) or obj.dtype.kind not in "SOU" or obj.ndim != 1:
        raise AdapterError(path, f"{where}/{name}: expected a list of {n} names")
    if obj.shape[0] != n or n > 64:
        raise AdapterError(path, f"{where}/{name} has {obj.shape[0]} names for {n} data columns")
    out = []
    for v in obj[()]:
        out.append((v.decode("utf-8", "replace") if isinstance(v, bytes) else str(v))[:100])
    return out


def _spectrum_field(path: str | os.PathLike[str], group: Any, where: str) -> str:
    """The one ``*_spectrum`` field of a data_collection group."""
    found = [k for k in list(group.keys())[:1000] if k.endswith("_spectrum")]
    if len(found) != 1:
        what = "no" if not found else f"{len(found)} ({', '.join(found)})"
        raise AdapterError(
            path, f"{where}: {what} spectral axis field (NAME_spectrum), expected one"
        )
    return found[0]


def _aoi(path: str | os.PathLike[str], entry: Any, name: str) -> tuple[np.ndarray, str, str]:
    where = f"/{name}/instrument"
    inst = entry.get("instrument")
    if inst is None:
        raise AdapterError(path, f"no {where} group (the angles of incidence are there)")
    a = _array(path, inst, "angle_of_incidence", where, (0, 1)).reshape(-1)
    return a, _units(inst, "angle_of_incidence"), f"{where}/angle_of_incidence"


def _errors(
    path: str | os.PathLike[str], group: Any, name: str, shape: tuple[int, ...], where: str
) -> np.ndarray | None:
    """The error array beside the data, None where the file has none (or a placeholder)."""
    obj = group.get(name)
    if obj is None or not _is_dataset(obj) or obj.dtype.kind not in "fiu":
        return None
    err = _array(path, group, name, where, (len(shape),))
    if err.shape != shape:
        raise AdapterError(
            path, f"{where}/{name} has shape {err.shape}, the data {shape}: expected the same"
        )
    return err


def _current(path: str | os.PathLike[str], entry: Any, name: str) -> _Raw:
    """The layout of the current definition (``data_collection``)."""
    where = f"/{name}/data_collection"
    dc = entry["data_collection"]
    data = _array(path, dc, "measured_data", where, (3,))
    n_meas, n_obs, n_spec = data.shape
    if n_obs != 2:
        raise AdapterError(
            path, f"{where}/measured_data has {n_obs} observables: expected 2 (Psi, Delta)"
        )
    i, j = _psi_delta_order(path, _text(path, dc, "data_type"), None, where)
    sname = _spectrum_field(path, dc, where)
    spectrum = _array(path, dc, sname, where, (1,))
    _check_len(path, f"{where}/{sname}", spectrum.size, n_spec, "N_spectrum of measured_data")
    aoi = _aoi(path, entry, name)
    if aoi[0].size != n_meas:
        raise AdapterError(
            path,
            f"{where}/measured_data holds {n_meas} measurements but {aoi[2]} has "
            f"{aoi[0].size} angles: a measurement varied over other parameters than the "
            "angle of incidence is not read",
        )
    sigma = _errors(path, dc, "measured_data_errors", data.shape, where)
    return _Raw(
        data[:, [i, j], :],
        None if sigma is None else sigma[:, [i, j], :],
        (spectrum, _units(dc, sname), f"{where}/{sname}"),
        aoi,
        f"{where}/measured_data",
        "NXellipsometry (data_collection)",
        _units(dc, "measured_data"),
    )


def _draft(path: str | os.PathLike[str], entry: Any, name: str) -> _Raw:
    """The layout of the 2022 draft (``sample/measured_data`` of rank 5)."""
    where = f"/{name}/sample"
    s = entry["sample"]
    data = _array(path, s, "measured_data", where, (5,))
    n_time, n_p1, n_ang, n_var, n_wl = data.shape
    if n_p1 != 1:
        raise AdapterError(
            path,
            f"{where}/measured_data is varied over {n_p1} values of "
            f"{_text(path, s, 'varied_parameters') or 'a parameter'}: only angle of incidence "
            "and time series are read",
        )
    names = _names(path, s, "column_names", n_var, where) if "column_names" in s else None
    if names is None and n_var != 2:
        raise AdapterError(path, f"{where}/measured_data has {n_var} columns and no names")
    i, j = _psi_delta_order(path, _text(path, s, "data_type"), names, where)
    spec_where = f"/{name}/instrument/spectrometer"
    spec = entry.get("instrument/spectrometer")
    if spec is None:
        raise AdapterError(path, f"no {spec_where} group (the wavelengths are there)")
    wl = _array(path, spec, "wavelength", spec_where, (1,))
    _check_len(path, f"{spec_where}/wavelength", wl.size, n_wl, "N_wavelength of measured_data")
    aoi = _aoi(path, entry, name)
    _check_len(path, aoi[2], aoi[0].size, n_ang, "N_angles of measured_data")
    sigma = _errors(path, s, "data_error", data.shape, where)
    time_s = _time_points(path, s, n_time, where) if n_time > 1 else None

    def flat(a: np.ndarray) -> np.ndarray:  # (time, angle) -> one measurement axis
        return a[:, 0][:, :, [i, j], :].reshape(n_time * n_ang, 2, n_wl)

    return _Raw(
        flat(data),
        None if sigma is None else flat(sigma),
        (wl, _units(spec, "wavelength"), f"{spec_where}/wavelength"),
        (np.tile(aoi[0], n_time), aoi[1], aoi[2]),
        f"{where}/measured_data",
        "NXellipsometry draft 2022 (sample/measured_data)",
        _units(s, "measured_data"),
        None if time_s is None else np.repeat(time_s, n_ang),
    )


_TIME_UNITS = {"s": 1.0, "second": 1.0, "seconds": 1.0, "ms": 1e-3, "min": 60.0, "h": 3600.0}


def _time_points(path: str | os.PathLike[str], s: Any, n: int, where: str) -> np.ndarray:
    t = _array(path, s, "time_points", where, (1,))
    _check_len(path, f"{where}/time_points", t.size, n, "N_time of measured_data")
    unit = _units(s, "time_points")
    if unit.lower() not in _TIME_UNITS:
        raise AdapterError(
            path, f"{where}/time_points: units {unit!r}, expected one of {sorted(_TIME_UNITS)}"
        )
    return t * _TIME_UNITS[unit.lower()]


def _check_len(path: str | os.PathLike[str], what: str, n: int, expected: int, of: str) -> None:
    if n != expected:
        raise AdapterError(path, f"{what} has {n} values, expected {expected} ({of})")


# ----------------------------------------------------------------------------- units


def _spectrum_nm(path: str | os.PathLike[str], raw: _Raw) -> tuple[np.ndarray, str]:
    x = raw.spectrum
    unit = raw.spectrum_unit
    conv = _SPECTRAL_UNITS.get(unit.lower())
    if conv is None:
        said = "states no unit" if unit.lower() in _NO_UNIT else f"has units {unit!r}"
        raise AdapterError(
            path,
            f"{raw.spectrum_where} {said}: expected one of angstrom, nm, um, m, eV, cm-1",
        )
    if not (np.isfinite(x).all() and x.min() > 0):
        raise AdapterError(
            path, f"{raw.spectrum_where}: every spectral value must be finite and > 0"
        )
    return conv[1](x), conv[0]


def _aoi_deg(path: str | os.PathLike[str], raw: _Raw) -> tuple[np.ndarray, str]:
    a, unit = raw.aoi, raw.aoi_unit.lower()
    if not np.isfinite(a).all():
        raise AdapterError(path, f"{raw.aoi_where}: every angle must be a finite number")
    if unit in _RADIANS:
        a, basis = np.degrees(a), "rad"
    elif unit in _DEGREES:
        basis = "deg"
    elif unit in _NO_UNIT and a.max() > np.pi / 2:
        basis = "deg (no unit stated; values above pi/2 cannot be radians)"
    else:
        said = "states no unit" if unit in _NO_UNIT else f"has units {raw.aoi_unit!r}"
        raise AdapterError(path, f"{raw.aoi_where} {said}: expected degrees or radians")
    if a.min() < 0 or a.max() >= 90:
        raise AdapterError(
            path, f"{raw.aoi_where}: angles of incidence must lie in [0, 90) deg, found {a}"
        )
    return a, basis


def _data_deg(path: str | os.PathLike[str], raw: _Raw, unit: str) -> tuple[float, str]:
    """Factor from the file's Psi/Delta to degrees, and how the unit was found."""
    u = unit.lower()
    if u in _DEGREES:
        return 1.0, "deg"
    if u in _RADIANS:
        return float(np.degrees(1.0)), "rad"
    if u not in _NO_UNIT:
        raise AdapterError(
            path, f"{raw.data_where} has units {unit!r}: expected degrees or radians"
        )
    with np.errstate(invalid="ignore"):
        psi_max = np.nanmax(raw.data[:, 0, :]) if np.isfinite(raw.data[:, 0, :]).any() else 0
        delta_max = np.nanmax(np.abs(raw.data[:, 1, :])) if np.isfinite(raw.data).any() else 0
    if psi_max > np.pi / 2 or delta_max > 2 * np.pi:
        return 1.0, "deg (no unit stated; values beyond the range of radians)"
    raise AdapterError(
        path,
        f"{raw.data_where} states no unit and its values (Psi <= pi/2, |Delta| <= 2 pi) could "
        "be radians or degrees: give it a units attribute ('degree' or 'rad')",
    )


# ----------------------------------------------------------------------------- entry


def _read_entry(path: str | os.PathLike[str], entry: Any, name: str) -> tuple[pd.DataFrame, dict]:
    if "data_collection" in entry and "measured_data" in entry["data_collection"]:
        raw = _current(path, entry, name)
    elif "sample" in entry and "measured_data" in entry["sample"]:
        raw = _draft(path, entry, name)
    else:
        raise AdapterError(
            path,
            f"/{name} (NXellipsometry) has no measured_data in data_collection or sample",
        )
    wl, spectral_unit = _spectrum_nm(path, raw)
    aoi, aoi_basis = _aoi_deg(path, raw)
    scale, data_basis = _data_deg(path, raw, raw.data_unit)
    frame, dropped = _frame(path, entry, name, raw, wl, aoi, scale)
    meta = {
        "entry": name,
        "layout": raw.layout,
        "definition_version": _attr_text(entry["definition"], "version"),
        "spectral_unit_in_file": spectral_unit,
        "angle_unit_in_file": aoi_basis,
        "psi_delta_unit_in_file": data_basis,
        "sigma": "measured errors" if raw.sigma is not None else "none in the file",
        "acquisition_program": _program(path, entry),
        "dropped_points": dropped,
    }
    return frame, meta


def _program(path: str | os.PathLike[str], entry: Any) -> str:
    for group in ("acquisition_program", "data_collection/data_software", "instrument/software"):
        g = entry.get(group)
        if g is not None and hasattr(g, "keys"):
            prog = _text(path, g, "program") or ""
            version = _text(path, g, "version") or ""
            if prog:
                return f"{prog} {version}".strip()
    return ""


def _sample(path: str | os.PathLike[str], entry: Any) -> str:
    s = entry.get("sample")
    for group, field in ((s, "sample_name"), (s, "name"), (entry, "title")):
        if group is not None and hasattr(group, "keys"):
            v = _text(path, group, field)
            if v and v != "NOT_PROVIDED":
                return v
    return Path(path).stem


def _frame(
    path: str | os.PathLike[str],
    entry: Any,
    name: str,
    raw: _Raw,
    wl: np.ndarray,
    aoi: np.ndarray,
    scale: float,
) -> tuple[pd.DataFrame, int]:
    """Psi rows then Delta rows, measurement by measurement; non-finite values dropped."""
    n_meas, _, n_spec = raw.data.shape
    wl_all = np.tile(wl, n_meas)
    theta = np.repeat(aoi, n_spec)
    values = [raw.data[:, k, :].reshape(-1) * scale for k in (0, 1)]
    sigmas = (
        [raw.sigma[:, k, :].reshape(-1) * scale for k in (0, 1)]
        if raw.sigma is not None
        else [np.full(wl_all.size, np.nan)] * 2
    )
    keep = [np.isfinite(v) for v in values]
    dropped = int(sum(np.count_nonzero(~k) for k in keep))
    counts = [int(np.count_nonzero(k)) for k in keep]
    value = np.concatenate([values[0][keep[0]], wrap_delta(values[1][keep[1]])])
    optional: dict[str, Any] = {}
    if raw.time_s is not None:
        t = np.repeat(raw.time_s, n_spec)
        optional["time_s"] = np.concatenate([t[keep[0]], t[keep[1]]])
    th = np.concatenate([theta[keep[0]], theta[keep[1]]])
    frame = build_frame(
        sample=_sample(path, entry),
        instrument=INSTRUMENT,
        source=Path(path).name,
        quantity=pd.Categorical.from_codes(
            np.repeat(np.array([0, 1], dtype=np.int8), counts), categories=["psi", "delta"]
        ),
        value=value,
        sigma=np.concatenate([sigmas[0][keep[0]], sigmas[1][keep[1]]]),
        unit="deg",
        wavelength_nm=np.concatenate([wl_all[keep[0]], wl_all[keep[1]]]),
        theta_i_deg=th,
        theta_r_deg=th.copy(),
        phi_r_deg=180.0,
        **optional,
    )
    return frame, dropped


def _sniff(head: bytes) -> bool:
    return is_hdf5(head)


FORMATS = (
    Format(
        "nexus-nxellipsometry",
        "NeXus NXellipsometry (HDF5 .nxs): psi/Delta, current layout and 2022 draft",
        (".nxs", ".nx5", ".h5", ".hdf5"),
        _sniff,
        read_nexus,
        ("psi", "delta"),
        keywords=(HDF5_MAGIC, b"NXellipsometry"),
        examples=(Example("nexus-nxellipsometry/SiO2onSi.ellips.nxs"),),
    ),
)
