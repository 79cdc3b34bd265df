"""The published tables of Zou, Bai, Wu (2013) that the reports compare fits with.

Zou X., Bai L., Wu Z., "Mirror reflectance spectrum modeling of smooth samples", Acta
Optica Sinica 33(6), 0612008 (2013), doi:10.3788/AOS201333.0612008: Tables 1-2 (smooth3
k1, k2, k3 and the fit RMSE per wavelength of the OSR and the mirror) and Table 3 (the
hemispherical reflectance integrated from the fits against the spectrophotometer). The
files are ``zou2013_table{1,2,3}.csv`` of the fixtures' ``published/`` folder, with their
citation headers as ``#`` comments.

:func:`read_published` gives the tables as a dict (``params``: Tables 1-2 stacked with a
``sample`` column; ``table3``), which a report keeps in ``Context.published``;
:func:`published_params` and :func:`paper_values` look rows up in that dict.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import numpy as np
import pandas as pd

from .builder import num

__all__ = ["paper_values", "published_params", "read_published"]

#: the published tables of one report: ``params`` (Tables 1-2) and ``table3``
Tables = Mapping[str, pd.DataFrame]


def _rename(df: pd.DataFrame) -> pd.DataFrame:
    ren = {}
    for c in df.columns:
        lc = str(c).strip().lower()
        for key in ("k1", "k2", "k3", "rmse", "sample"):
            if lc.startswith(key):
                ren[c] = key
        if lc.startswith("wavelength") or lc in ("lambda_nm", "wl_nm"):
            ren[c] = "wavelength_nm"
        if lc.startswith("integration"):
            ren[c] = "integration_pct"
        if lc.startswith("measured") or lc.startswith("hemispherical"):
            ren[c] = "measured_pct"
        if lc.startswith("error") or lc.startswith("relative"):
            ren[c] = "error_pct"
    return df.rename(columns=ren)


def read_published(folder: Path) -> tuple[dict[str, pd.DataFrame], list[str]]:
    """Read the published Tables 1-3 of ``folder``; returns the tables and the files read.

    A missing file is left out (its table is absent from the dict). Tables 1-2 without a
    ``sample`` column are the OSR's and the mirror's.
    """
    tables: dict[str, pd.DataFrame] = {}
    read = []
    frames = []
    for n, default_sample in ((1, "OSR"), (2, "mirror")):
        p = folder / f"zou2013_table{n}.csv"
        if p.is_file():
            t = _rename(pd.read_csv(p, comment="#", skipinitialspace=True))
            if "sample" not in t.columns:
                t["sample"] = default_sample
            t["sample"] = t["sample"].astype(str)
            frames.append(t)
            read.append(p.name)
    if frames:
        tables["params"] = pd.concat(frames, ignore_index=True)
    p = folder / "zou2013_table3.csv"
    if p.is_file():
        tables["table3"] = _rename(pd.read_csv(p, comment="#", skipinitialspace=True))
        read.append(p.name)
    return tables, read


def _row(tables: Tables, sample: str, wl: float) -> pd.Series | None:
    t = tables.get("params")
    if t is None:
        return None
    m = t[(t["sample"].str.lower() == sample.lower()) & np.isclose(t["wavelength_nm"], wl)]
    return m.iloc[0] if len(m) else None


def published_params(tables: Tables, sample: str, wl: float) -> dict[str, float | None]:
    """Published smooth3 k1, k2, k3 and RMSE (Tables 1-2) of a sample and wavelength [nm].

    Empty when the tables or the row are missing; a blank cell is None.
    """
    r = _row(tables, sample, wl)
    if r is None:
        return {}
    return {k: num(r.get(k)) for k in ("k1", "k2", "k3", "rmse")}


def paper_values(tables: Tables, sample: str, wl: float) -> dict[str, float] | None:
    """The paper's smooth3 parameters (k1, k2, k3) of a sample and wavelength [nm], or None."""
    r = _row(tables, sample, wl)
    if r is None:
        return None
    return {"k1": float(r["k1"]), "k2": float(r["k2"]), "k3": float(r["k3"])}
