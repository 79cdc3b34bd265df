"""Fit input: the rows of a dataset table (or plain arrays) that a model is fitted to.

Angles stay in degrees here, as at every labbrdf boundary; :class:`~labbrdf.fitting.Objective`
converts them to radians for the model.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike, NDArray

from ..dataset import Measurement
from ..errors import LabbrdfError

__all__ = [
    "FITTABLE_QUANTITIES",
    "FitData",
    "FitError",
    "as_fit_data",
    "clean_fit_data",
    "select_rows",
    "several_groups_message",
]


class FitError(LabbrdfError, ValueError):
    """Bad fit input (data, method, parameter names) or a fit that cannot be set up."""


#: dataset quantities a model can be fitted to (each model says which it describes:
#: :attr:`labbrdf.models.Model.quantities`; BTDF data need a transmission form)
FITTABLE_QUANTITIES = ("brdf", "specular_intensity", "btdf")


@dataclass(frozen=True)
class FitData:
    """Plain arrays to fit: one value per point, angles in degrees.

    Parameters
    ----------
    theta_i_deg, theta_r_deg : array_like
        Incidence and detector polar angles [deg].
    value : array_like
        Measured values (BRDF [sr^-1] or specular intensity).
    sigma : array_like, optional
        1-sigma uncertainties in the units of ``value``; NaN or None where unknown.
    phi_r_deg : array_like
        Detector azimuth of the outward direction [deg]; 180 is the specular half-plane.
    wavelength_nm : array_like, optional
        Vacuum wavelength [nm], passed to wavelength-dependent models.
    quantity, unit : str
        What ``value`` is (dataset vocabulary), for reports.
    """

    theta_i_deg: ArrayLike
    theta_r_deg: ArrayLike
    value: ArrayLike
    sigma: ArrayLike | None = None
    phi_r_deg: ArrayLike = 180.0
    wavelength_nm: ArrayLike | None = None
    quantity: str = "brdf"
    unit: str = "sr-1"

    def __post_init__(self) -> None:
        value = np.atleast_1d(np.asarray(self.value, dtype=float))
        if value.ndim != 1:
            raise FitError(f"FitData: 'value' must be 1-D, got shape {value.shape}")
        n = value.shape[0]
        if n == 0:
            raise FitError("FitData: no data points")

        def col(name: str, v: Any) -> NDArray[np.float64] | None:
            if v is None:
                return None
            a = np.asarray(v, dtype=float)
            if a.ndim == 0:
                return np.full(n, float(a))
            if a.shape != (n,):
                raise FitError(f"FitData: {name!r} has shape {a.shape}, expected ({n},)")
            return a.copy()

        object.__setattr__(self, "value", value.copy())
        for name in ("theta_i_deg", "theta_r_deg", "phi_r_deg"):
            if getattr(self, name) is None:
                raise FitError(f"FitData: {name!r} is required (angles in degrees)")
            object.__setattr__(self, name, col(name, getattr(self, name)))
        sigma = col("sigma", self.sigma)
        object.__setattr__(self, "sigma", np.full(n, np.nan) if sigma is None else sigma)
        object.__setattr__(self, "wavelength_nm", col("wavelength_nm", self.wavelength_nm))

    def __len__(self) -> int:
        return int(np.shape(self.value)[0])

    def take(self, mask: NDArray[np.bool_]) -> FitData:
        """The points where ``mask`` is True."""
        wl = None if self.wavelength_nm is None else np.asarray(self.wavelength_nm)[mask]
        return FitData(
            np.asarray(self.theta_i_deg)[mask],
            np.asarray(self.theta_r_deg)[mask],
            np.asarray(self.value)[mask],
            np.asarray(self.sigma)[mask],
            np.asarray(self.phi_r_deg)[mask],
            wl,
            self.quantity,
            self.unit,
        )

    @classmethod
    def from_frame(
        cls,
        df: pd.DataFrame | Measurement,
        *,
        quantity: str | None = None,
        unit: str | None = None,
    ) -> FitData:
        """Select the fittable rows of a dataset-schema table.

        Rows whose quantity is in :data:`FITTABLE_QUANTITIES` are used; a table that mixes
        several of them, or several units, is refused unless ``quantity`` / ``unit`` say
        which to use. Several samples or wavelengths are refused too (use :func:`fit_many`).
        """
        d, qty, unt = select_rows(df, quantity, unit)
        for key in ("sample", "wavelength_nm"):
            if key in d.columns and d[key].nunique(dropna=False) > 1:
                raise FitError(several_groups_message(key, d[key].nunique(dropna=False)))
        return cls.from_arrays(d, np.arange(len(d)), qty, unt)

    @classmethod
    def from_arrays(
        cls, d: pd.DataFrame | dict[str, NDArray], idx: NDArray, quantity: str, unit: str
    ) -> FitData:
        """The rows ``idx`` of the columns of ``d`` (checked schema rows; internal API).

        Used by :meth:`from_frame` and by :func:`~labbrdf.fitting.fit_many`, which selects
        the rows of every group once and builds each group's FitData from them.
        """

        def col(name: str) -> NDArray:
            return np.asarray(d[name], dtype=float)[idx]

        def optional(name: str) -> NDArray | None:
            return col(name) if name in d else None

        return cls(
            col("theta_i_deg"),
            col("theta_r_deg"),
            col("value"),
            optional("sigma"),
            col("phi_r_deg"),
            optional("wavelength_nm"),
            quantity,
            unit,
        )


def several_groups_message(key: str, count: int) -> str:
    """The error message for data that hold ``count`` groups of ``key`` (internal API)."""
    return (
        f"data hold {count} different {key!r} values; fit one group at a time, e.g. "
        "fit_many(data, model, by=['sample', 'wavelength_nm'])"
    )


def select_rows(df: Any, quantity: str | None, unit: str | None) -> tuple[pd.DataFrame, str, str]:
    """The fittable rows of a schema table, checked for one quantity and one unit."""
    if isinstance(df, Measurement):
        df = df.data
    if not isinstance(df, pd.DataFrame):
        raise FitError(
            f"data: expected a Measurement, DataFrame or FitData, got {type(df).__name__}"
        )
    need = ["quantity", "unit", "value", "theta_i_deg", "theta_r_deg", "phi_r_deg"]
    missing = [c for c in need if c not in df.columns]
    if missing:
        raise FitError(f"data: missing column(s) {missing} of the dataset schema")
    q = df["quantity"].astype(str)
    if quantity is not None:
        if quantity not in FITTABLE_QUANTITIES:
            raise FitError(
                f"quantity={quantity!r} cannot be fitted by a reflectance "
                f"model; use one of {list(FITTABLE_QUANTITIES)}"
            )
        sel = q == quantity
    else:
        sel = q.isin(FITTABLE_QUANTITIES)
    if unit is not None:
        sel &= df["unit"].astype(str) == unit
    d = df[sel.to_numpy()]
    if len(d) == 0:
        present = sorted(set(q))
        wanted = [quantity] if quantity else list(FITTABLE_QUANTITIES)
        raise FitError(
            f"data: no rows with quantity in {wanted}"
            f"{f' and unit {unit!r}' if unit else ''}; the table has {present}"
        )
    combos = sorted(set(zip(d["quantity"].astype(str), d["unit"].astype(str), strict=True)))
    if len(combos) > 1:
        raise FitError(
            f"data mix quantities/units {combos}; say which to fit with quantity=... and unit=..."
        )
    return d, combos[0][0], combos[0][1]


def as_fit_data(data: Any, quantity: str | None, unit: str | None) -> FitData:
    """``data`` as :class:`FitData` (a FitData is returned as is; internal API)."""
    if isinstance(data, FitData):
        return data
    return FitData.from_frame(data, quantity=quantity, unit=unit)


def clean_fit_data(data: FitData, nan_policy: str) -> tuple[FitData, int]:
    """Apply the NaN policy; return the clean data and the number of dropped points."""
    if nan_policy not in ("raise", "omit"):
        raise FitError(f"nan_policy must be 'raise' or 'omit', got {nan_policy!r}")
    cols = [data.theta_i_deg, data.theta_r_deg, data.value, data.phi_r_deg]
    if data.wavelength_nm is not None:
        cols.append(data.wavelength_nm)
    bad = ~np.all(np.isfinite(np.vstack(cols)), axis=0)
    sig = np.asarray(data.sigma)
    bad |= np.isinf(sig)
    if bad.any():
        if nan_policy == "raise":
            idx = np.flatnonzero(bad)
            raise FitError(
                f"data: {idx.size} point(s) with NaN or infinite values (positions "
                f"{idx[:8].tolist()}); clean them or pass nan_policy='omit' to drop them"
            )
        data = data.take(~bad)
    return data, int(bad.sum())
