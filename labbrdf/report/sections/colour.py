"""Section ``colour``: the sample colour from spectrophotometer reflectance.

CIE 1931 2 deg observer, illuminant D65, sRGB, computed with colour-science.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from .. import figures
from ..builder import Unavailable, slug
from ..context import Context

__all__ = ["CMFS_NAME", "colour_section"]

#: the observer's colour-matching functions, by colour-science's name
CMFS_NAME = "CIE 1931 2 Degree Standard Observer"


def _spectrophotometer_rows(ctx: Context, d: pd.DataFrame) -> pd.DataFrame:
    """Reflectance rows usable for a colour: near-normal, of unpolarised light.

    Single-polarisation ellipsometer reflectance (R_s or R_p of one file) is not the
    sample's reflectance for unpolarised light: never a colour from it (a note and a skip
    per such file).
    """
    spec = d[d["quantity"].isin(["hemispherical_reflectance", "reflectance"])]
    polarised = {
        Path(str(f.get("path", ""))).name: str(f["meta"]["reflectance_kind"])
        for f in ctx.files
        if (f.get("meta") or {}).get("reflectance_kind")
    }
    if "channel" in spec.columns:
        ch = spec["channel"].astype(object)
        for src in spec.loc[ch.isin(["s", "p"]), "source"].unique():
            polarised.setdefault(str(src), "single-polarisation reflectance (channel s or p)")
    left_out = sorted(set(spec["source"].astype(str)) & set(polarised))
    for src in left_out:
        ctx.b.note(
            "no colour",
            f"{src}: {polarised[src]}; a colour needs the reflectance of the sample for "
            "unpolarised light (a spectrophotometer), so these rows are not used",
        )
        ctx.b.skip(
            f"colour.{slug(src)}",
            f"sample colour of {src}",
            f"{polarised[src]}: not a colour source",
        )
    spec = spec[~spec["source"].astype(str).isin(left_out)]
    return spec[spec["theta_i_deg"].isna() | (spec["theta_i_deg"] < 10)] if len(spec) else spec


def _sample_colour(
    ctx: Context,
    sample: Any,
    src: Any,
    g: pd.DataFrame,
    grid: np.ndarray,
    cmfs: Any,
    ill: Any,
) -> dict[str, Any]:
    """Colour of one (sample, file) spectrum: its swatch, text and figure, and its table row.

    ``cmfs`` and ``ill``: the observer and the illuminant, aligned to ``grid`` [nm].
    """
    import colour

    b = ctx.b
    g = g.groupby("wavelength_nm", as_index=False)["value"].mean()
    wl = g["wavelength_nm"].to_numpy(float)
    v = g["value"].to_numpy(float)
    # linear interpolation between the measured points, end values held outside them
    # (np.interp), evaluated on the uniform 1 nm grid
    used = colour.SpectralDistribution(np.interp(grid, wl, v), grid, name=str(sample))
    xyz = colour.sd_to_XYZ(used, cmfs, ill)
    rgb = np.asarray(colour.XYZ_to_sRGB(xyz / 100.0), float)
    rgb_c = np.clip(rgb, 0.0, 1.0)
    hexc = "#" + "".join(f"{int(round(255 * x)):02x}" for x in rgb_c)
    inside = (wl >= 360) & (wl <= 780)
    note = (
        f"{inside.sum()} measured point(s) in 360-780 nm ({wl.min():g}-{wl.max():g} nm "
        "measured); linear interpolation between them, constant extrapolation (end "
        "values held) outside"
    )
    few = inside.sum() < 10 or wl.min() > 400 or wl.max() < 700
    b.swatch(f"colour_{slug(str(sample))}_{slug(str(src))}", hexc)
    b.text(
        f"{sample} ({src}): sRGB {hexc}. {note}."
        + (
            " Too few points or too narrow a range for a trustworthy colour: the "
            "swatch is indicative only."
            if few
            else ""
        )
    )
    b.figure(
        f"colour_spectrum_{slug(str(sample))}_{slug(str(src))}",
        f"Reflectance spectrum of {sample} used for its colour ({src})",
        "Measured: the spectrophotometer reflectance points [%]. Modelled: none; the line "
        "is the spectrum handed to colour-science after linear interpolation and constant "
        "extrapolation to 360-780 nm.",
        figures.spectrum_figure(
            wl, v, np.asarray(used.wavelengths), np.asarray(used.values), title=f"{sample}"
        ),
    )
    return {
        "sample": str(sample),
        "source": str(src),
        "points": int(len(wl)),
        "wl_min": float(wl.min()),
        "wl_max": float(wl.max()),
        "X": float(xyz[0]),
        "Y": float(xyz[1]),
        "Z": float(xyz[2]),
        "R": float(rgb[0]),
        "G": float(rgb[1]),
        "B": float(rgb[2]),
        "hex": hexc,
        "in_gamut": bool(np.all((rgb >= 0) & (rgb <= 1))),
        "method": note,
        "reliable": not few,
    }


def colour_section(ctx: Context) -> None:
    """Sample colour from the spectrophotometer reflectance (CIE 1931 2 deg, D65, sRGB)."""
    import colour  # imported here: slow, and it changes numpy's print options

    d = ctx.data
    if d is None:
        raise Unavailable("no data ingested")
    spec = _spectrophotometer_rows(ctx, d)
    if not len(spec):
        raise Unavailable(
            "no spectrophotometer reflectance (hemispherical_reflectance or "
            "near-normal reflectance) ingested"
        )
    b = ctx.b
    shape = colour.SpectralShape(360, 780, 1)
    grid = np.asarray(shape.wavelengths, float)
    # observer and illuminant on the computation grid up front, so colour-science has
    # nothing to re-align (and no warnings to print)
    cmfs = colour.MSDS_CMFS[CMFS_NAME].copy().align(shape)
    ill = colour.SDS_ILLUMINANTS["D65"].copy().align(shape)
    white = colour.sd_to_XYZ(colour.SpectralDistribution(np.ones_like(grid), grid), cmfs, ill)
    rows = [
        _sample_colour(ctx, sample, src, g, grid, cmfs, ill)
        for (sample, src), g in spec.groupby(["sample", "source"], sort=True)
    ]
    b.table(
        "colour",
        "Sample colour (CIE 1931 2\u00b0 observer, D65, sRGB)",
        [
            ("sample", "sample", ""),
            ("source", "file", ""),
            ("points", "points", "d"),
            ("wl_min", "\u03bb min [nm]", "g"),
            ("wl_max", "\u03bb max [nm]", "g"),
            ("X", "X", ".4g"),
            ("Y", "Y", ".4g"),
            ("Z", "Z", ".4g"),
            ("R", "sR", ".3f"),
            ("G", "sG", ".3f"),
            ("B", "sB", ".3f"),
            ("hex", "sRGB hex", ""),
            ("in_gamut", "in sRGB gamut", ""),
            ("reliable", "enough spectral data", ""),
            ("method", "interpolation / extrapolation", ""),
        ],
        rows,
        caption="colour.sd_to_XYZ with the CIE 1931 2 degree observer and illuminant D65 "
        "(Y = 100 for a perfect reflector), colour.XYZ_to_sRGB of XYZ/100; sR, sG, sB are "
        "the encoded sRGB values before clipping to [0, 1] for the swatch.",
    )
    b.check(
        "colour.white",
        "a perfect reflector (R = 1) maps to Y = 100 in the colour pipeline",
        abs(float(white[1]) - 100.0) < 1e-6,
        against="CIE colorimetry normalisation (k = 100 / sum(S ybar))",
        value=float(white[1]),
        tolerance=1e-6,
        justification="float64 round-off of the normalisation sum",
    )
