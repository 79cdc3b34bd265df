"""Section ``spectra``: fitted parameters against wavelength, with the published values."""

from __future__ import annotations

import numpy as np

from .. import figures
from ..builder import Unavailable, slug
from ..context import Context
from ..published import published_params

__all__ = ["spectra_section"]


def spectra_section(ctx: Context, model_name: str = "smooth3") -> None:
    """Fitted parameters against wavelength with 95% intervals (and published values)."""
    recs = ctx.fits.get(model_name) or []
    if not recs:
        raise Unavailable(f"no {model_name} fits")
    if len({r.wavelength_nm for r in recs}) < 2:
        raise Unavailable("fewer than two wavelengths: no spectrum to draw")
    pnames = [p for p in recs[0].params if recs[0].params[p].get("vary", True)]
    units = {p: (recs[0].params[p].get("units") or "1") for p in pnames}
    for s in sorted({r.sample for r in recs}):
        rr = sorted((r for r in recs if r.sample == s), key=lambda r: r.wavelength_nm)
        wl = [r.wavelength_nm for r in rr]
        series = [
            {
                "label": f"{s}: fit (95% interval)",
                "wavelength": wl,
                "values": {p: [r.params[p]["value"] for r in rr] for p in pnames},
                "lo": {
                    p: [r.params[p]["lo"] if r.params[p]["lo"] is not None else np.nan for r in rr]
                    for p in pnames
                },
                "hi": {
                    p: [r.params[p]["hi"] if r.params[p]["hi"] is not None else np.nan for r in rr]
                    for p in pnames
                },
            }
        ]
        pubs = [published_params(ctx.published, s, w) for w in wl]
        if model_name == "smooth3" and any(pubs):
            series.append(
                {
                    "label": "published (Zou 2013)",
                    "style": "published",
                    "wavelength": wl,
                    "values": {
                        p: [pp.get(p, np.nan) if pp.get(p) is not None else np.nan for pp in pubs]
                        for p in pnames
                    },
                }
            )
        ctx.b.figure(
            f"spectra_{model_name}_{slug(s)}",
            f"{model_name} parameters of {s} against wavelength",
            "Modelled: each marker is the parameter fitted at one wavelength, with its 95% "
            "interval; stars: the published values where they exist. Measured: the scans "
            "the fits used (previous figures).",
            figures.spectra_figure(pnames, units, series, title=f"{s}: {model_name}"),
        )
