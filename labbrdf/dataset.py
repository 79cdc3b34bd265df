"""The common dataset: one tidy table for every instrument.

A :class:`Measurement` is a long ("tidy") :class:`pandas.DataFrame`, one measured value per
row, plus a JSON-safe ``meta`` dict. Every adapter returns one; every workflow (fit, report)
reads one. The schema (also in ``docs/conventions.md``, "The common dataset"):

==================  ========  ===============================================================
column              dtype     meaning
==================  ========  ===============================================================
``sample``          str       sample name (file header, else file stem)
``instrument``      str       instrument / software, e.g. ``woollam-wvase``
``source``          str       file name the row came from
``quantity``        category  one of :data:`QUANTITIES`
``value``           float     the value in canonical units (finite)
``sigma``           float     1-sigma uncertainty, NaN where the file has none
``unit``            str       ``deg``, ``1`` (fraction) or ``sr-1``
``wavelength_nm``   float     vacuum wavelength [nm]
``theta_i_deg``     float     angle of incidence [deg], NaN for normal-incidence/sphere data
``theta_r_deg``     float     detector polar angle [deg], NaN where not applicable
``phi_r_deg``       float     detector azimuth of the outward direction [deg], source at 0,
                              specular half-plane at 180; NaN where not applicable
==================  ========  ===============================================================

Optional columns (:data:`OPTIONAL_COLUMNS`) carry what some instruments add: ``time_s``
(time stamp of a kinetic series [s]), ``channel`` (polarisation or generalized-ellipsometry
channel: ``p``, ``s``, ``pp``, ``ps``, ``sp``; tristimulus channel ``X``, ``Y``, ``Z``;
``""`` for none, and a missing value, as when files with and without the column are
concatenated, becomes ``""``), ``x_mm``/``y_mm`` (stage position of the spot [mm]),
``sample_rotation_deg`` (rotation of an anisotropic sample about its normal [deg]),
``zone`` (nulling-ellipsometer zone of the row, e.g. Accurion zones 1-4: a whole number
>= 0 stored as float so that rows without one, as after concatenation, are NaN).
Canonical units: angles in degrees, Delta in [0, 360) (Nebraska convention), reflectance,
transmittance and depolarization as fractions. Quantity ``btdf`` [sr-1]: theta_r is
measured from the back normal and phi_r is the azimuth of the transmitted direction.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from . import outputs as _outputs
from .errors import LabbrdfError

__all__ = [
    "COLUMNS",
    "OPTIONAL_COLUMNS",
    "QUANTITIES",
    "DatasetError",
    "Measurement",
    "atomic_output",
    "concat",
    "empty_frame",
    "make_frame",
    "read",
    "read_csv",
    "read_parquet",
    "sidecar_path",
    "validate",
    "write",
    "write_csv",
    "write_parquet",
]

#: The required columns, in canonical order, with their dtypes.
COLUMNS: dict[str, str] = {
    "sample": "object",
    "instrument": "object",
    "source": "object",
    "quantity": "category",
    "value": "float64",
    "sigma": "float64",
    "unit": "object",
    "wavelength_nm": "float64",
    "theta_i_deg": "float64",
    "theta_r_deg": "float64",
    "phi_r_deg": "float64",
}

#: Optional columns a reader may add, with their dtypes.
OPTIONAL_COLUMNS: dict[str, str] = {
    "time_s": "float64",
    "channel": "object",
    "x_mm": "float64",
    "y_mm": "float64",
    "sample_rotation_deg": "float64",
    "zone": "float64",
}

_MUELLER = tuple(f"mueller_{i}{j}" for i in range(1, 5) for j in range(1, 5))

#: Allowed quantities and the unit each must carry.
QUANTITIES: dict[str, tuple[str, ...]] = {
    "psi": ("deg",),
    "delta": ("deg",),
    "reflectance": ("1",),
    "specular_intensity": ("1", "sr-1"),
    "hemispherical_reflectance": ("1",),
    "transmittance": ("1",),
    "absorbance": ("1",),
    "brdf": ("sr-1",),
    "btdf": ("sr-1",),
    "depolarization": ("1",),
    **{m: ("1",) for m in _MUELLER},
}

_QUANTITY_DTYPE = pd.CategoricalDtype(list(QUANTITIES))

_META_KEY = b"labbrdf.meta"
_CSV_META_PREFIX = "# labbrdf-meta: "


class DatasetError(LabbrdfError, ValueError):
    """A table does not follow the labbrdf schema; the message names column and rows."""


def _rows(mask: np.ndarray, limit: int = 8) -> str:
    idx = np.flatnonzero(mask)
    shown = ", ".join(str(i) for i in idx[:limit])
    more = f" and {idx.size - limit} more" if idx.size > limit else ""
    return f"rows {shown}{more}"


def _copy_on_write() -> bool:
    """True when pandas' Copy-on-Write is active (always from pandas 3)."""
    if int(pd.__version__.split(".")[0]) >= 3:
        return True
    return pd.get_option("mode.copy_on_write") is True  # pragma: no cover - pandas 2


def _in_range(a: np.ndarray, lo: float, hi: float, *, hi_open: bool = False) -> bool:
    """True when every value is finite and within [lo, hi] ([lo, hi) with ``hi_open``).

    Two reductions (min, max; NaN propagates into both) instead of several masks: the
    fast path of the range checks in :func:`validate`, which compute the exact row masks
    only when this says no.
    """
    if a.size == 0:
        return True
    mn, mx = float(a.min()), float(a.max())
    return (
        math.isfinite(mn) and math.isfinite(mx) and mn >= lo and (mx < hi if hi_open else mx <= hi)
    )


def _codes(col: pd.Series) -> tuple[np.ndarray, np.ndarray]:
    """Integer codes and the distinct values of a column (as ``pd.factorize``).

    A categorical without missing values gives its own codes and categories (no hashing
    of a million strings); anything else goes through :func:`pandas.factorize`, with
    missing values as a value of their own.
    """
    if isinstance(col.dtype, pd.CategoricalDtype):
        codes = col.cat.codes.to_numpy()
        if codes.size == 0 or codes.min() >= 0:
            return codes, np.asarray(col.cat.categories, dtype=object)
    codes, uniq = pd.factorize(col, use_na_sentinel=False)
    return codes, np.asarray(uniq, dtype=object)


def _is_code(codes: np.ndarray, which: np.ndarray) -> np.ndarray | None:
    """Row mask ``which[codes]`` (``which``: one flag per distinct value), None if all False.

    One integer comparison when a single distinct value is flagged (the usual case).
    """
    ks = np.flatnonzero(which)
    if ks.size == 0:
        return None
    return codes == ks[0] if ks.size == 1 else which[codes]


def _as_object(col: pd.Series) -> pd.Series:
    """A column as plain Python strings (dtype object) on a fresh RangeIndex.

    Categoricals are expanded by one take of their categories (much faster than
    ``astype(object)``); the Series wrapper keeps pandas >= 3 from re-inferring ``str``.
    """
    if isinstance(col.dtype, pd.CategoricalDtype):
        codes = col.cat.codes.to_numpy()
        if codes.size == 0 or codes.min() >= 0:
            cats = np.asarray(col.cat.categories, dtype=object)
            if cats.size == 1:  # one value (sample, source, ...): a fill, no gather
                values = np.empty(codes.size, dtype=object)
                values[:] = cats[0]
            else:
                values = cats.take(codes.astype(np.intp))
            return pd.Series(values, index=col.index, dtype=object, copy=False)
    return col.astype(object)


def validate(df: pd.DataFrame) -> pd.DataFrame:
    """Check a table against the schema and return it with canonical dtypes and order.

    Parameters
    ----------
    df : pandas.DataFrame
        The table to check.

    Returns
    -------
    pandas.DataFrame
        A copy with the canonical column order and dtypes and a fresh RangeIndex.

    Raises
    ------
    DatasetError
        Naming the column and the offending rows (positions in ``df``).

    Notes
    -----
    Written for tables of millions of rows (``benchmarks/bench_ingest.py``):
    string columns are checked on their distinct values when categorical, range checks
    first try two reductions and build the row masks only when a value is out of range,
    and columns that already have their canonical dtype are not copied (pandas'
    Copy-on-Write keeps the result independent of ``df``; without it, on pandas 2, the
    table is copied as before). Every check runs on every row.
    """
    _check_columns(df)
    idx = df.index
    fresh = isinstance(idx, pd.RangeIndex) and idx.start == 0 and idx.step == 1
    out = df if fresh else df.reset_index(drop=True)
    cols = list(COLUMNS) + [c for c in OPTIONAL_COLUMNS if c in out.columns]
    out = out[cols]
    if not _copy_on_write():  # pragma: no cover - pandas 2 without Copy-on-Write
        out = out.copy()

    unit_col = out["unit"]  # before the conversion below: factorizes fast if categorical
    _check_strings(out)
    floats = [c for c, t in {**COLUMNS, **OPTIONAL_COLUMNS}.items() if t == "float64"]
    for name in floats:
        if name not in out.columns or out[name].dtype == np.float64:
            continue
        try:
            out[name] = pd.to_numeric(out[name], errors="raise").astype("float64")
        except (TypeError, ValueError) as exc:
            raise DatasetError(f"column {name!r}: expected numbers ({exc})") from None
    qcodes, quniq, known = _check_quantities_and_units(out, unit_col)
    value = out["value"].to_numpy()
    _check_ranges(out, value)
    _check_psi_delta(value, qcodes, quniq)
    cat_index = np.array(
        [list(QUANTITIES).index(v) if k else -1 for v, k in zip(quniq, known, strict=True)],
        dtype=np.int8,
    )
    out["quantity"] = pd.Categorical.from_codes(cat_index[qcodes], dtype=_QUANTITY_DTYPE)
    return out


def _check_columns(df: pd.DataFrame) -> None:
    """Refuse anything but a non-empty DataFrame with the schema's columns, each once."""
    if not isinstance(df, pd.DataFrame):
        raise DatasetError(f"expected a pandas DataFrame, got {type(df).__name__}")
    missing = [c for c in COLUMNS if c not in df.columns]
    if missing:
        raise DatasetError(f"missing column(s) {missing}; required are {list(COLUMNS)}")
    extra = [c for c in df.columns if c not in COLUMNS and c not in OPTIONAL_COLUMNS]
    if extra:
        raise DatasetError(
            f"unknown column(s) {extra}; optional columns are {list(OPTIONAL_COLUMNS)}"
        )
    if not df.columns.is_unique:
        dup = sorted({str(c) for c in df.columns[df.columns.duplicated()]})
        raise DatasetError(f"duplicate column(s) {dup}; each column must appear once")
    if len(df) == 0:
        raise DatasetError("the table has no rows")


def _check_strings(out: pd.DataFrame) -> None:
    """Check the string columns and store them as object strings in ``out``."""
    for name in ("sample", "instrument", "source", "unit"):
        col = out[name]
        bad = _not_str(col, nonempty=True)
        if bad.any():
            raise DatasetError(f"column {name!r}: expected a non-empty string in {_rows(bad)}")
        out[name] = _as_object(col)
    if "channel" in out.columns:
        col = out["channel"]
        # a missing channel (NaN/None/NA, e.g. rows of a file without the column after
        # concat) is the empty string, as readers write it for rows without a channel
        missing = col.isna().to_numpy(bool)
        if missing.any():
            col = col.astype(object).where(~missing, "")
        bad = _not_str(col, nonempty=False)
        if bad.any():
            raise DatasetError(f"column 'channel': expected a string in {_rows(bad)}")
        out["channel"] = _as_object(col)


def _check_quantities_and_units(
    out: pd.DataFrame, unit_col: pd.Series
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Refuse an unknown quantity or a unit that does not fit its quantity.

    The checks work on the distinct values, not row by row. Returns the quantity codes of
    the rows, the distinct quantities and which of them are known.
    """
    qcodes, quniq = _codes(out["quantity"])
    quniq = np.array([str(v) for v in quniq], dtype=object)
    known = np.isin(quniq, list(QUANTITIES))
    if not known.all():
        bad = ~known[qcodes]
        if bad.any():
            q = quniq[qcodes]
            raise DatasetError(
                f"column 'quantity': unknown quantity {sorted(set(q[bad]))} in {_rows(bad)}; "
                f"allowed are {list(QUANTITIES)}"
            )
    ucodes, uuniq = _codes(unit_col)
    nu = len(uuniq)
    pair_bad = np.array(
        [[k and u not in QUANTITIES[q] for u in uuniq] for q, k in zip(quniq, known, strict=True)],
        dtype=bool,
    ).reshape(-1)
    if pair_bad.any():
        bad = pair_bad[qcodes.astype(np.int64) * nu + ucodes]
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            unit = out["unit"].to_numpy(dtype=object)
            q_i = quniq[qcodes[i]]
            raise DatasetError(
                f"column 'unit': {unit[i]!r} does not fit quantity {q_i!r} "
                f"(expected {QUANTITIES[q_i]}) in {_rows(bad)}"
            )
    return qcodes, quniq, known


def _check_ranges(out: pd.DataFrame, value: np.ndarray) -> None:
    """Check the range of the value, sigma, wavelength, angle and zone columns."""
    if not _in_range(value, -math.inf, math.inf):
        bad = ~np.isfinite(value)
        if bad.any():
            raise DatasetError(f"column 'value': expected finite numbers, NaN/inf in {_rows(bad)}")
    sigma = out["sigma"].to_numpy()
    if not _in_range(sigma, 0.0, math.inf):
        bad = np.isinf(sigma) | (sigma < 0)
        if bad.any():
            raise DatasetError(f"column 'sigma': expected >= 0 or NaN in {_rows(bad)}")
    wl = out["wavelength_nm"].to_numpy()
    if not (_in_range(wl, 0.0, math.inf) and wl.min() > 0):
        bad = ~(np.isfinite(wl) & (wl > 0))
        if bad.any():
            raise DatasetError(f"column 'wavelength_nm': expected finite > 0 in {_rows(bad)}")
    for name in ("theta_i_deg", "theta_r_deg"):
        a = out[name].to_numpy()
        if not _in_range(a, 0.0, 90.0):
            bad = np.isinf(a) | (a < 0) | (a > 90)
            if bad.any():
                raise DatasetError(f"column {name!r}: expected [0, 90] deg or NaN in {_rows(bad)}")
    if "zone" in out.columns:
        z = out["zone"].to_numpy()
        bad = ~np.isnan(z) & ~(np.isfinite(z) & (z >= 0) & (z == np.round(z)))
        if bad.any():
            raise DatasetError(f"column 'zone': expected an integer >= 0 or NaN in {_rows(bad)}")
    a = out["phi_r_deg"].to_numpy()
    if not _in_range(a, 0.0, 360.0, hi_open=True):
        bad = np.isinf(a) | (a < 0) | (a >= 360)
        if bad.any():
            raise DatasetError(f"column 'phi_r_deg': expected [0, 360) deg or NaN in {_rows(bad)}")


def _check_psi_delta(value: np.ndarray, qcodes: np.ndarray, quniq: np.ndarray) -> None:
    """Psi in [0, 90] deg and Delta in [0, 360) deg (the rows are found only when needed)."""
    psi = _is_code(qcodes, quniq == "psi") if not _in_range(value, 0.0, 90.0) else None
    if psi is not None and not _in_range(value[psi], 0.0, 90.0):
        bad = psi & ((value < 0) | (value > 90))
        if bad.any():
            raise DatasetError(f"column 'value': psi outside [0, 90] deg in {_rows(bad)}")
    delta = None
    if not _in_range(value, 0.0, 360.0, hi_open=True):
        delta = _is_code(qcodes, quniq == "delta")
    if delta is not None and not _in_range(value[delta], 0.0, 360.0, hi_open=True):
        bad = delta & ((value < 0) | (value >= 360))
        if bad.any():
            raise DatasetError(
                f"column 'value': delta outside [0, 360) deg (Nebraska convention) in {_rows(bad)}"
            )


def _not_str(col: pd.Series, *, nonempty: bool) -> np.ndarray:
    """True where a value is not a string (or is empty, with ``nonempty``); vectorised.

    Categorical and string-typed columns are checked on their distinct values; an object
    column is checked by pandas' type inference first, and row by row only when it holds
    something other than strings.
    """
    if isinstance(col.dtype, pd.CategoricalDtype):
        cats = col.cat.categories
        ok = np.array([isinstance(v, str) and (v != "" or not nonempty) for v in cats], bool)
        codes = col.cat.codes.to_numpy()
        if ok.size == 0:
            return np.ones(len(col), dtype=bool)
        if ok.all() and (codes.size == 0 or codes.min() >= 0):
            return np.zeros(len(col), dtype=bool)
        return np.where(codes < 0, True, ~ok[np.maximum(codes, 0)])
    if col.dtype == object and pd.api.types.infer_dtype(col, skipna=False) == "string":
        # only str objects (no missing value): look for "" among the distinct values
        if not nonempty:
            return np.zeros(len(col), dtype=bool)
        codes, uniq = pd.factorize(col.to_numpy(dtype=object))
        empty = np.array([v == "" for v in uniq], dtype=bool)
        return empty[codes] if empty.any() else np.zeros(len(col), dtype=bool)
    if isinstance(col.dtype, pd.StringDtype):
        bad = col.isna().to_numpy(bool)
        if nonempty:
            bad = bad | (col == "").fillna(False).to_numpy(bool)
        return bad
    return ~col.map(lambda v: isinstance(v, str) and (v != "" or not nonempty)).to_numpy(bool)


def _check_meta(meta: Mapping[str, Any]) -> dict[str, Any]:
    if not isinstance(meta, Mapping):
        raise DatasetError(f"meta must be a mapping, got {type(meta).__name__}")
    try:
        return json.loads(json.dumps(dict(meta), allow_nan=False))
    except (TypeError, ValueError) as exc:
        raise DatasetError(f"meta is not JSON-safe: {exc}") from None


@dataclass(frozen=True)
class Measurement:
    """A validated table plus JSON-safe metadata.

    Parameters
    ----------
    data : pandas.DataFrame
        Rows in the labbrdf schema; validated on construction.
    meta : dict
        JSON-safe metadata (instrument settings, header lines, conventions). For a
        concatenation of several files it holds ``{"parts": [{"source": ..., "meta": ...}]}``.
    """

    data: pd.DataFrame
    meta: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        object.__setattr__(self, "data", validate(self.data))
        object.__setattr__(self, "meta", _check_meta(self.meta))

    def __len__(self) -> int:
        return len(self.data)

    @property
    def quantities(self) -> list[str]:
        """Quantities present, in schema order."""
        present = set(self.data["quantity"].astype(str))
        return [q for q in QUANTITIES if q in present]

    def summary(self) -> dict[str, Any]:
        """JSON-safe one-line description: sample, rows, quantities, ranges."""
        d = self.data
        wl = d["wavelength_nm"]
        th = d["theta_i_deg"].dropna().round(3).unique()
        return {
            "sample": sorted(set(d["sample"])),
            "rows": int(len(d)),
            "quantities": self.quantities,
            "wavelength_nm": [float(wl.min()), float(wl.max())],
            "theta_i_deg": sorted(float(t) for t in th),
        }


#: Longest name [characters] kept in a string column built from one header field: a
#: sample name is a line of a header, and a crafted or corrupt file with a title of
#: megabytes would otherwise put it in every output row (CSV, Parquet, reports).
MAX_NAME_CHARS = 512


def capped_name(name: str) -> str:
    """``name`` itself, or its first characters and a mark saying how long it was.

    The reader's ``meta`` keeps the whole header field; only the table's copy is cut.
    """
    if len(name) <= MAX_NAME_CHARS:
        return name
    mark = f"... [{len(name)} characters, cut]"
    return name[: MAX_NAME_CHARS - len(mark)] + mark


def make_frame(
    *,
    sample: str,
    instrument: str,
    source: str,
    quantity: str | Iterable[str],
    value: Any,
    unit: str | Iterable[str],
    wavelength_nm: Any,
    sigma: Any = np.nan,
    theta_i_deg: Any = np.nan,
    theta_r_deg: Any = np.nan,
    phi_r_deg: Any = np.nan,
    **optional: Any,
) -> pd.DataFrame:
    """Build a schema table from arrays and scalars (broadcast to one length).

    A scalar string becomes an object column of references to that one string (never n
    copies), and a ``sample`` longer than
    :data:`MAX_NAME_CHARS` is cut by :func:`capped_name`: memory stays a small multiple of
    the data whatever a header holds.

    Optional columns (``time_s``, ``channel``, ``x_mm``, ``y_mm``, ``sample_rotation_deg``,
    ``zone``) go in ``optional``.
    The result is not validated; wrap it in :class:`Measurement` to do so.
    """
    unknown = set(optional) - set(OPTIONAL_COLUMNS)
    if unknown:
        raise DatasetError(f"unknown optional column(s) {sorted(unknown)}")
    value = np.atleast_1d(np.asarray(value, dtype=float))
    n = value.shape[0]
    cols: dict[str, Any] = {
        "sample": sample,
        "instrument": instrument,
        "source": source,
        "quantity": quantity,
        "value": value,
        "sigma": sigma,
        "unit": unit,
        "wavelength_nm": wavelength_nm,
        "theta_i_deg": theta_i_deg,
        "theta_r_deg": theta_r_deg,
        "phi_r_deg": phi_r_deg,
        **optional,
    }
    if isinstance(sample, str) and len(sample) > MAX_NAME_CHARS:
        cols["sample"] = capped_name(sample)
    out: dict[str, Any] = {}
    for k, v in cols.items():
        if isinstance(v, str):
            # n references to one str object: a list of n strings would become a string
            # array of n copies under pandas >= 3 (a 5 MB title times the rows)
            fill = np.empty(n, dtype=object)
            fill[:] = v
            out[k] = pd.Series(fill, dtype=object, copy=False)
        elif np.ndim(v) == 0:
            out[k] = [v] * n
        else:
            arr = list(v) if not isinstance(v, np.ndarray) else v
            if len(arr) != n:
                raise DatasetError(f"column {k!r} has {len(arr)} values, expected {n}")
            out[k] = arr
    return pd.DataFrame(out)


def empty_frame() -> pd.DataFrame:
    """An empty table with the schema's columns (for building up, never for returning)."""
    return pd.DataFrame({c: pd.Series(dtype=t) for c, t in COLUMNS.items()})


def concat(measurements: Iterable[Measurement]) -> Measurement:
    """Concatenate several measurements; each part's meta is kept under ``parts``.

    A measurement that is itself a concatenation contributes its parts, so nesting is flat.
    """
    ms = list(measurements)
    if not ms:
        raise DatasetError("nothing to concatenate: no measurements given")
    parts: list[dict[str, Any]] = []
    for m in ms:
        if not isinstance(m, Measurement):
            raise DatasetError(f"expected Measurement, got {type(m).__name__}")
        if "parts" in m.meta and set(m.meta) == {"parts"}:
            parts.extend(m.meta["parts"])
        else:
            sources = sorted(set(m.data["source"]))
            parts.append({"source": sources[0] if len(sources) == 1 else sources, "meta": m.meta})
    frames = [m.data for m in ms]
    data = pd.concat(
        [f.assign(quantity=f["quantity"].astype(str)) for f in frames], ignore_index=True
    )
    return Measurement(data, {"parts": parts})


# --------------------------------------------------------------------------- I/O


#: write to a temporary name beside the target, rename on success (see labbrdf.outputs:
#: umask permissions, OS errors as OutputError, leftovers of killed runs cleaned up)
atomic_output = _outputs.atomic_output


def write_parquet(m: Measurement, path: str | os.PathLike[str]) -> Path:
    """Write a measurement to Parquet (meta in the file's key-value metadata), atomically."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    table = pa.Table.from_pandas(m.data, preserve_index=False)
    md = dict(table.schema.metadata or {})
    md[_META_KEY] = json.dumps(m.meta, allow_nan=False).encode()
    with atomic_output(path) as tmp:
        pq.write_table(table.replace_schema_metadata(md), tmp)
    return Path(path)


def read_parquet(path: str | os.PathLike[str]) -> Measurement:
    """Read a Parquet file written by :func:`write_parquet`."""
    import pyarrow.parquet as pq

    try:
        table = pq.read_table(path)
    except Exception as exc:  # pyarrow raises several types for a bad file
        raise DatasetError(f"{path}: not a readable Parquet file ({exc})") from None
    md = table.schema.metadata or {}
    meta = json.loads(md[_META_KEY]) if _META_KEY in md else {}
    df = table.to_pandas()
    try:
        return Measurement(df, meta)
    except DatasetError as exc:
        raise DatasetError(f"{path}: {exc}") from None


def sidecar_path(path: str | os.PathLike[str]) -> Path:
    """The metadata file that :func:`write_csv` writes beside ``path``: ``<stem>.meta.json``."""
    p = Path(path)
    return p.with_name(p.stem + ".meta.json")


def write_csv(m: Measurement, path: str | os.PathLike[str]) -> Path:
    """Write a measurement to CSV plus its metadata to ``<stem>.meta.json``, atomically.

    The CSV is the plain table (first line the column names, so a spreadsheet shows it as
    is), floats written in their shortest round-tripping form so :func:`read_csv` gives
    back the same numbers. The meta goes to the sidecar JSON (:func:`sidecar_path`). Both
    are written to temporary files and renamed into place only when both are complete.

    Text is written verbatim, without the ``'`` prefix that the CSV tables meant for
    people get against spreadsheet formula injection (:func:`labbrdf.outputs.csv_safe_cell`):
    this file is a data file that labbrdf and pandas read back exactly, and a prefix would
    change sample names such as ``-1 deg tilt`` on every round trip. Do not open it in a
    spreadsheet from an untrusted source; the fit and report tables are safe to open.
    """
    side = sidecar_path(path)
    with atomic_output(path) as tmp, atomic_output(side) as tmp_side:
        with open(tmp_side, "w", encoding="utf-8", newline="\n") as fh:
            json.dump(m.meta, fh, allow_nan=False, indent=1)
            fh.write("\n")
        with open(tmp, "w", encoding="utf-8", newline="") as fh:
            # pandas formats floats through numpy's printing, which an imported package
            # may have switched to its 12-digit legacy mode (colour-science sets
            # legacy="1.13")
            with np.printoptions(legacy=False):
                m.data.to_csv(fh, index=False, lineterminator="\n")
    return Path(path)


#: pandas before 3.0 parses CSV floats with a fast parser that is not correctly rounded
#: (2.1 lost the last digit), so the exact "round_trip" parser is asked for; pandas 3 made
#: the correctly rounded parser the default and deprecated the option
_EXACT_FLOATS: dict[str, Any] = (
    {"float_precision": "round_trip"} if int(pd.__version__.split(".")[0]) < 3 else {}
)


def read_csv(path: str | os.PathLike[str]) -> Measurement:
    """Read a CSV file written by :func:`write_csv` (a plain schema CSV works too).

    The meta comes from the sidecar ``<stem>.meta.json`` when it exists; files written by
    earlier versions carry it in a first line ``# labbrdf-meta: {...}`` instead, which is
    read too (and wins, being part of the file).
    """
    path = Path(path)
    with open(path, encoding="utf-8", newline="") as fh:
        first = fh.readline()
        meta: dict[str, Any] = {}
        if first.startswith(_CSV_META_PREFIX):
            try:
                meta = json.loads(first[len(_CSV_META_PREFIX) :])
            except json.JSONDecodeError as exc:
                raise DatasetError(f"{path}, line 1: bad labbrdf-meta JSON ({exc})") from None
        else:
            fh.seek(0)
            side = sidecar_path(path)
            if side.is_file():
                try:
                    meta = json.loads(side.read_text(encoding="utf-8"))
                except (json.JSONDecodeError, UnicodeDecodeError) as exc:
                    raise DatasetError(f"{side}: not valid JSON ({exc})") from None
        dtypes = {c: str for c in ("sample", "instrument", "source", "unit", "channel")}
        try:
            df = pd.read_csv(
                fh, dtype=dtypes, keep_default_na=False, na_values=[""], **_EXACT_FLOATS
            )
        except (pd.errors.ParserError, pd.errors.EmptyDataError) as exc:
            raise DatasetError(f"{path}: not a labbrdf CSV table ({exc})") from None
    try:
        return Measurement(df, meta)
    except DatasetError as exc:
        raise DatasetError(f"{path}: {exc}") from None


def write(m: Measurement, path: str | os.PathLike[str]) -> Path:
    """Write by extension: ``.parquet`` or ``.csv``."""
    suffix = Path(path).suffix.lower()
    if suffix == ".parquet":
        return write_parquet(m, path)
    if suffix == ".csv":
        return write_csv(m, path)
    raise DatasetError(f"{path}: cannot write {suffix!r}; use .parquet or .csv")


def read(path: str | os.PathLike[str]) -> Measurement:
    """Read a labbrdf dataset file by extension: ``.parquet`` or ``.csv``."""
    suffix = Path(path).suffix.lower()
    if suffix == ".parquet":
        return read_parquet(path)
    if suffix == ".csv":
        return read_csv(path)
    raise DatasetError(f"{path}: not a labbrdf dataset file (.parquet or .csv)")


def wrap_delta(delta_deg: Any) -> np.ndarray:
    """Wrap Delta [deg] into [0, 360) (Nebraska convention range)."""
    d = np.mod(np.asarray(delta_deg, dtype=float), 360.0)
    # np.mod can return 360.0 for tiny negative inputs
    return np.where(d >= 360.0, d - 360.0, d)


def is_finite_number(x: Any) -> bool:
    """True for a finite real number."""
    try:
        return math.isfinite(float(x))
    except (TypeError, ValueError):
        return False
