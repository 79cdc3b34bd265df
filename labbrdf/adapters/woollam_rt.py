"""The geometry of the reflectance rows of a WVASE32 ``RTmethod`` export.

Where the angle field of ``uR``/``pR``/``sR`` rows cannot be their angle of incidence (the
reasoning and the real file behind it are in :mod:`labbrdf.adapters.woollam`), the rows'
angles become NaN and the field is kept in the metadata (:func:`rt_geometry`).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pandas as pd

from .woollam_rows import REFL

__all__ = ["rt_geometry"]


#: Below this angle of incidence a reflection ellipsometer cannot record a specular
#: reflectance: source and detector arms would overlap (WVASE's own convention for angle 0
#: is normal incidence in transmission).
_MIN_REFLECTION_AOI_DEG = 10.0
#: A reflectance that stays within this relative spread (median over wavelengths) while the
#: angle column spans at least :data:`_FLAT_SPAN_DEG` cannot be a function of the angle of
#: incidence: Fresnel's Rp changes by more over such a span (Si at 1000 nm: 0.32 at 0 deg,
#: 0.17 at 50 deg; even aluminium changes by several percent between 0 and 50 deg).
_FLAT_RTOL = 0.01
_FLAT_SPAN_DEG = 30.0
_REFL_KIND = {"p": "single-polarisation (p)", "s": "single-polarisation (s)", "u": "unpolarised"}


def _angle_column_not_aoi(wl: np.ndarray, ang: np.ndarray, val: np.ndarray) -> str | None:
    """Why the angle column of reflectance rows cannot be their angle of incidence, or None."""
    reasons = []
    if ang.min() < _MIN_REFLECTION_AOI_DEG:
        reasons.append(
            f"it reaches {ang.min():g} deg, where a reflection ellipsometer cannot measure a "
            "specular reflectance"
        )
    u = np.unique(ang)
    if u.size >= 2 and u[-1] - u[0] >= _FLAT_SPAN_DEG:
        table = (
            pd.DataFrame({"wl": wl, "a": ang, "v": val})
            .pivot_table(index="wl", columns="a", values="v", aggfunc="mean")
            .dropna()
        )
        if len(table):
            spread = (table.max(axis=1) - table.min(axis=1)) / table.abs().mean(axis=1)
            med = float(np.median(spread))
            if med < _FLAT_RTOL:
                reasons.append(
                    f"the reflectance at one wavelength changes by {100 * med:.2g} % (median) "
                    f"over {u[0]:g}-{u[-1]:g} deg, where Fresnel reflectance would change by "
                    "far more"
                )
    return "; ".join(reasons) or None


def rt_geometry(
    wl: np.ndarray,
    aoi: np.ndarray,
    value: np.ndarray,
    tcodes: np.ndarray,
    code: dict[str, int],
    utags: list[str],
    theta: np.ndarray,
    phi: np.ndarray,
    meta: dict[str, Any],
) -> None:
    """Geometry and kind of the reflectance rows of an ``RTmethod`` file (in place).

    Where the angle column cannot be the angle of incidence (see :func:`read_woollam`),
    ``theta`` and ``phi`` become NaN for those rows and the column goes to
    ``meta["angle_column"]``. ``meta["reflectance_kind"]`` says which polarisation.
    """
    tags = [t for t in sorted(utags) if t in REFL]
    if not tags:
        return
    meta["reflectance_kind"] = (
        "; ".join(_REFL_KIND[REFL[t]] for t in tags) + " ellipsometer reflectance"
    )
    flagged = np.zeros(aoi.size, dtype=bool)
    reasons = []
    for t in tags:
        rows = tcodes == code[t]
        ok = rows & np.isfinite(value)
        why = _angle_column_not_aoi(wl[ok], aoi[ok], value[ok]) if ok.any() else None
        if why is not None:
            flagged |= rows
            reasons.append(f"{t}: {why}")
    if not flagged.any():
        return
    theta[flagged] = np.nan
    phi[flagged] = np.nan
    a = aoi[flagged]
    vals, counts = np.unique(a, return_counts=True)
    meta["angle_column"] = {
        "values_deg": [float(x) for x in vals],
        "rows_per_value": [int(c) for c in counts],
        "is_angle_of_incidence": False,
        "reason": "; ".join(reasons),
        "meaning": "a per-block setting (written in the AOI field) that did not change the "
        "measured reflectance, e.g. a sample rotation about its normal; the file does not "
        "say which, so the angle of incidence is unknown (NaN) and the rows are kept in "
        "file order, one block per value",
    }
