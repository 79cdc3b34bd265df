"""How a film fit shows itself: its text report, its notebook HTML and its figure.

The functions read a :meth:`labbrdf.FilmFit.summary` (text, HTML) or the fit's rows and
residuals (figure); :class:`labbrdf.FilmFit` delegates its ``fit_report``, ``__str__``,
``_repr_html_`` and ``plot`` to them, as :class:`labbrdf.FitResult` shows itself.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

import numpy as np

from .._plotting import COLOURS, draw_panel
from .film_verdict import material_label

if TYPE_CHECKING:
    from .film import FilmFit

__all__ = [
    "film_fit_html",
    "film_fit_panels",
    "film_fit_plot",
    "film_fit_report",
    "intervals_text",
]

#: the fit's channel codes (:attr:`labbrdf.FilmFit.channels`): name and axis label
CHANNELS = {
    0: ("psi", "psi [deg]"),
    1: ("delta", "Delta [deg]"),
    2: ("R_s", "R_s"),
    3: ("R_p", "R_p"),
    4: ("R", "R"),
    5: ("T_s", "T_s"),
    6: ("T_p", "T_p"),
    7: ("T", "T"),
    8: ("depolarization", "depolarization [1]"),
}


def _nk_entry(part: Mapping[str, Any]) -> tuple[str, Mapping[str, Any] | None]:
    """The wavelength [nm] (as text) and the entry of a summary's ``nk_at_<WL>nm`` key."""
    for key, value in part.items():
        if key.startswith("nk_at_") and key.endswith("nm"):
            return key[len("nk_at_") : -len("nm")], value
    return "", None


def _param_text(p: Mapping[str, Any]) -> str:
    """One parameter of a summary: value, stderr, 95 % interval (scaled), flags."""
    v = p["value"]
    if not p.get("vary"):
        return f"{v:.6g} (fixed)"
    se, ci = p.get("stderr"), p.get("ci95")
    out = f"{v:.6g}"
    if se is not None:
        out += f" +- {se:.2g}"
    if ci:
        how = " profile" if p.get("ci_method") == "profile" else ""
        out += f"  95 %{how} [{ci[0]:.6g}, {ci[1]:.6g}]"
    sc = p.get("ci95_scaled")
    if sc:
        out += f"  scaled [{sc[0]:.6g}, {sc[1]:.6g}]"
    if p.get("flags"):
        out += "  " + ",".join(p["flags"])
    return out


def _nk_text(nk: Mapping[str, Any]) -> str:
    """``n +- se, k +- se`` of one medium (and the scaled stderr where given)."""
    n_se = nk.get("n_stderr")
    k_se = nk.get("k_stderr")
    n_txt = f"{nk['n']:.5f}" + (f" +- {n_se:.2g}" if n_se is not None else "")
    k_txt = f"{nk['k']:.5f}" + (f" +- {k_se:.2g}" if k_se is not None else "")
    out = f"{n_txt}, {k_txt}"
    n_sc, k_sc = nk.get("n_stderr_scaled"), nk.get("k_stderr_scaled")
    if n_sc is not None:
        out += f"  (scaled: +- {n_sc:.2g}" + (f", +- {k_sc:.2g})" if k_sc is not None else ")")
    return out


def _nk_line(wl: str, nk: Mapping[str, Any]) -> str:
    return f"  n, k at {wl} nm: {_nk_text(nk)}"


def _search_text(summary: Mapping[str, Any]) -> str:
    """The stages that ran, in turn (the film's local stage may be least squares)."""
    return " then ".join(summary.get("search") or [summary["method"]])


def _fit_line(summary: Mapping[str, Any]) -> str:
    wl = summary["wavelength_range_nm"]
    return (
        f"fit: {summary['ndata']} values, {wl[0]:g}-{wl[1]:g} nm, {summary['nvarys']} free; "
        f"chi2/nu = {summary['redchi']:.4g}, MSE = {summary['mse']:.4g} (Woollam); "
        f"{summary['nfev']} evaluations, {_search_text(summary)}, seed {summary['seed']}, "
        f"intervals: {intervals_text(summary)}"
    )


def _dpol_lines(summary: Mapping[str, Any]) -> list[str]:
    """The depolarization channel's own chi2, and the MSE of psi and Delta alone, if fitted."""
    ch = summary.get("channels", {})
    dp = ch.get("depolarization")
    if dp is None:
        return []
    per = dp["chi2"] / dp["n"]
    line = f"depolarization channel: {dp['n']} rows, chi2 {dp['chi2']:.4g} (chi2/n {per:.3g})"
    if "psi" in ch and "delta" in ch:
        n = ch["psi"]["n"] + ch["delta"]["n"] - summary["nvarys"]
        if n > 0:
            mse = math.sqrt((ch["psi"]["chi2"] + ch["delta"]["chi2"]) / n)
            line += f"; MSE of psi and Delta alone {mse:.4g}"
    return [line]


def intervals_text(summary: Mapping[str, Any]) -> str:
    """Which 95 % intervals a film fit's summary carries, in words.

    ``Wald``, ``profile``, or (``ci="auto"``) ``Wald; profile for NAME (why), ...``.
    """
    how = summary["ci_method"]
    if how != "auto":
        return "Wald" if how == "wald" else how
    groups = [(lay["name"], lay["parameters"]) for lay in summary["layers"]]
    groups.append(("substrate", summary["substrate"].get("parameters", {})))
    prof = [
        f"{owner}.{k} ({p.get('ci_reason', '?')})"
        for owner, params in groups
        for k, p in params.items()
        if p.get("ci_method") == "profile"
    ]
    return "Wald" + (f"; profile for {', '.join(prof)}" if prof else " (no profile needed)")


def film_fit_report(summary: Mapping[str, Any]) -> str:
    """The text report of a film fit: each layer, the substrate, the fit, notes, warnings.

    Parameters
    ----------
    summary : mapping
        :meth:`labbrdf.FilmFit.summary`.

    Returns
    -------
    str
        One line per parameter (value, stderr, 95 % interval, flags), each layer's n, k at
        the summary's reporting wavelength, then the fit's statistics [nm for ranges].
    """
    lines = []
    for lay in summary["layers"]:
        mat = lay["material"].get("model", "?")
        lines.append(f"layer {lay['name']} ({mat})")
        for k, p in lay["parameters"].items():
            lines.append(f"  {k:<14s} {_param_text(p)}")
        wl, nk = _nk_entry(lay)
        if nk:
            lines.append(_nk_line(wl, nk))
    sub = summary["substrate"]
    lines.append(f"substrate: {sub.get('name') or material_label(sub['material'])}")
    for p_name, p in sub.get("parameters", {}).items():
        lines.append(f"  {p_name:<14s} {_param_text(p)}")
    lines.extend(_at_lines(summary.get("nk_at") or []))
    for k, p in summary.get("stack_parameters", {}).items():  # e.g. thickness_spread
        lines.append(f"stack {k:<14s} {_param_text(p)}")
    lines.append(_fit_line(summary))
    lines.extend(_dpol_lines(summary))
    if not summary["success"]:
        lines.append(f"fit did not converge: {summary['message']}")
    lines.extend(f"note: {n}" for n in summary["notes"])
    lines.extend(f"warning: {w}" for w in summary["warnings"])
    if summary.get("verdict"):
        lines.append(f"VERDICT: {summary['verdict']}")
    return "\n".join(lines)


def _at_lines(entries: list[Mapping[str, Any]]) -> list[str]:
    """n, k of every medium at each asked wavelength, with stderr (scaled where given)."""
    lines = []
    for e in entries:
        lines.append(f"n, k at {e['wavelength_nm']:g} nm (+- standard error):")
        for name, nk in e["media"].items():
            lines.append(f"  {name:<14s} {_nk_text(nk)}")
    return lines


def film_fit_html(summary: Mapping[str, Any]) -> str:
    """The notebook HTML of a film fit: its statistics and one row per parameter.

    Parameters
    ----------
    summary : mapping
        :meth:`labbrdf.FilmFit.summary`.

    Returns
    -------
    str
        An HTML fragment (every text escaped).
    """
    import html

    from ..richrepr import card

    wl = summary["wavelength_range_nm"]
    facts = [
        ("values", summary["ndata"]),
        ("wavelengths [nm]", f"{wl[0]:g}-{wl[1]:g}"),
        ("free parameters", summary["nvarys"]),
        ("chi2/nu", f"{summary['redchi']:.4g}"),
        ("MSE (Woollam)", f"{summary['mse']:.4g}"),
        ("method", f"{_search_text(summary)} (seed {summary['seed']})"),
        ("intervals", intervals_text(summary)),
        ("success", f"{summary['success']} ({summary['message']})"),
    ]
    parts = [*(("layer " + lay["name"], lay) for lay in summary["layers"])]
    parts.append(("substrate", summary["substrate"]))
    facts.insert(0, ("substrate", summary["substrate"].get("name", "?")))
    parts.append(("stack", {"parameters": summary.get("stack_parameters", {})}))
    rows = [
        (where, k, _param_text(p))
        for where, part in parts
        for k, p in part.get("parameters", {}).items()
    ]
    notes = [*summary["notes"], *summary["warnings"]]
    if summary.get("verdict"):
        notes.insert(0, "VERDICT: " + summary["verdict"])
    extra = "<ul>" + "".join(f"<li>{html.escape(n)}</li>" for n in notes) + "</ul>"
    layers = ", ".join(lay["name"] for lay in summary["layers"]) or "no layer"
    return card(
        f"Film fit: {layers} on {summary['substrate'].get('name', 'the substrate')}",
        facts,
        (("part", "parameter", "value +- stderr  [95 % interval]  flags"), rows),
        extra if notes else "",
    )


def film_fit_panels(fit: FilmFit) -> list[dict[str, Any]]:
    """Two panels per channel: data with 1-sigma bars and the fit, then the residuals.

    Parameters
    ----------
    fit : FilmFit

    Returns
    -------
    list of dict
        Panels as ``labbrdf._plotting.draw_panel`` draws them, against wavelength
        [nm]; one colour per angle of incidence (the first seven angles of a channel).
        The fit at a point is the value less the fit's residual there (Delta's residual
        is wrapped into [-180, 180) deg).
    """
    d = fit.data
    x = d["wavelength_nm"].to_numpy(float)
    y = d["value"].to_numpy(float)
    sigma = d["sigma"].to_numpy(float)
    resid = np.asarray(fit.result.residual, float)
    theta = d["theta_i_deg"].to_numpy(float).round(2)
    panels = []
    for code, (name, label) in CHANNELS.items():
        m = np.asarray(fit.channels) == code
        if not m.any():
            continue
        data, res = [], []
        for colour, th in zip(COLOURS, np.unique(theta[m]), strict=False):
            k = m & (theta == th)
            tag = f"theta_i {th:g} deg"
            data.append({"label": tag, "x": x[k], "y": y[k], "yerr": sigma[k],
                         "style": "points", "colour": colour})  # fmt: skip
            data.append({"label": "", "x": x[k], "y": y[k] - resid[k], "style": "line",
                         "colour": colour})  # fmt: skip
            res.append({"label": tag, "x": x[k], "y": resid[k], "band": sigma[k],
                        "style": "points", "colour": colour})  # fmt: skip
        panels.append({"title": f"{name}: measured and fit", "xlabel": "wavelength [nm]",
                       "ylabel": label, "series": data})  # fmt: skip
        panels.append({"title": f"{name} residual (band: 1 sigma)", "xlabel": "wavelength [nm]",
                       "ylabel": f"measured - fit, {label}", "series": res})  # fmt: skip
    return panels


def film_fit_plot(fit: FilmFit, ax: Any = None) -> Any:
    """Draw :func:`film_fit_panels`: one column per channel, residuals below the data.

    Parameters
    ----------
    fit : FilmFit
    ax : sequence of matplotlib Axes, optional
        Two per channel (data, residuals, in the order of :data:`CHANNELS`); default a new
        figure with one column per channel.

    Returns
    -------
    matplotlib Figure

    Raises
    ------
    ValueError
        ``ax`` holds another number of Axes than two per channel.
    """
    panels = film_fit_panels(fit)
    if ax is None:
        import matplotlib.pyplot as plt

        ncols = len(panels) // 2
        _, grid = plt.subplots(
            2,
            ncols,
            squeeze=False,
            figsize=(4.8 * ncols, 5.2),
            gridspec_kw={"height_ratios": [3, 1.2]},
            layout="constrained",
        )
        axes = [a for col in grid.T for a in col]
    else:
        axes = list(np.asarray(ax, dtype=object).ravel())
    if len(axes) != len(panels):
        raise ValueError(
            f"ax: expected {len(panels)} Axes (data and residuals of each channel), "
            f"got {len(axes)}"
        )
    for a, panel in zip(axes, panels, strict=True):
        draw_panel(a, panel)
    return axes[0].figure
