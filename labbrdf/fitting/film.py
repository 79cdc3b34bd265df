"""The film fit: a layer stack as a model of the one fitting core.

:func:`fit_film` turns psi/Delta (any angles), polarised or unpolarised reflectance and
transmittance rows of one sample (one or several files, fitted jointly) into residual
components with the files' sigmas, and fits the free parameters of a
:class:`~labbrdf.films.FilmModel` with :func:`labbrdf.fitting.fit` (global then local,
seeded): no second fitter. :class:`FilmFit` reports thicknesses and n, k with intervals,
chi2/nu beside Woollam's MSE, correlations and identifiability notes. The film objects
(:mod:`labbrdf.films`) do not import it: the fit is a workflow above them.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike, NDArray
from scipy import special

from ..dataset import Measurement
from ..films import FILM_QUANTITIES, NK_REPORT_NM, FilmError, FilmModel, Stack, load_model
from ..films import incoherent as inc
from ..jsonsafe import jsonable
from ..models import Model, Parameters
from ..nk import dispersion as disp
from ..nk.reading import tabulated_from_file
from ..samples import SampleFile, stated_names
from .core import METHOD, fit
from .data import FitData, FitError
from .result import FitResult
from .uncertainty import CORREL_MAX

__all__ = ["FilmFit", "fit_film", "stated_samples", "woollam_mse"]


class _FilmFitModel(Model):
    """The film as a :class:`~labbrdf.models.base.Model` of the fitting core.

    Each data row carries a channel (psi, Delta, R_s, R_p, R, T_s, T_p, T); ``_evaluate``
    returns the model value of every row. For Delta rows it returns the measured value
    plus the angular difference, so the core's residual ``y - model`` is the wrapped
    difference in (-180, 180] deg whatever the branch.
    """

    name = "film"
    #: the film fit's rows (psi, Delta, R, T channels), as the core's data name them
    quantities = ("film",)
    reference = (
        "coherent transfer matrices (labbrdf.films.matrices) with labbrdf.nk.dispersion materials"
    )

    #: a smooth residual vector: the default local stage runs as trust-region least
    #: squares (:func:`labbrdf.fitting.stages._least_squares_local`), not BOBYQA's rounds
    least_squares_local = True

    _CH = {"psi": 0, "delta": 1, "rs": 2, "rp": 3, "r": 4, "ts": 5, "tp": 6, "t": 7, "dpol": 8}

    def __init__(self, fm: FilmModel, channels: NDArray, y: NDArray) -> None:
        self.fm = fm
        self.channels = np.asarray(channels, int)
        self.y = np.asarray(y, float)
        self._pairs: tuple[NDArray, ...] | None = None
        super().__init__()

    def default_params(self) -> Parameters:
        p = Parameters()
        vals = self.fm.stack.values()
        units = self.fm.stack.units()
        for k, v in vals.items():
            lo, hi = self.fm.free.get(k, (-math.inf, math.inf))
            vary = k in self.fm.free
            start = min(max(v, lo), hi) if vary else v
            lo, hi = (lo, hi) if vary else (-math.inf, math.inf)
            p.add(k, start, lo, hi, vary, units.get(k, "1"))
        return p

    def rows(self, p: Mapping[str, float], ti_deg: NDArray, wl: NDArray) -> NDArray:
        s = self.fm.stack.with_values({k: p[k] for k in self.fm.free})
        th = np.clip(ti_deg, 0.0, 90.0)
        # psi, Delta, R_s, R_p of one (wavelength, angle) share one stack evaluation
        key = self._pairs
        if key is None or not (np.array_equal(key[0], wl) and np.array_equal(key[1], th)):
            pairs, inv = np.unique(np.stack([wl, th]), axis=1, return_inverse=True)
            key = self._pairs = (wl.copy(), th.copy(), pairs[0], pairs[1], inv.ravel())
        u_wl, u_th, inv = key[2], key[3], key[4]
        sums = s.intensity_sums(u_wl, u_th)  # coherent or with incoherent layers
        Rs, Rp = sums.Rs[inv], sums.Rp[inv]
        ch = self.channels
        out = np.full(ch.shape, np.nan)
        psi = np.degrees(np.arctan2(np.sqrt(Rp), np.sqrt(Rs)))
        delta = np.degrees(np.angle(sums.X[inv]))
        d = (delta - self.y + 180.0) % 360.0 - 180.0
        out = np.where(ch == 0, psi, out)
        out = np.where(ch == 1, self.y + d, out)
        out = np.where(ch == 2, Rs, out)
        out = np.where(ch == 3, Rp, out)
        out = np.where(ch == 4, 0.5 * (Rs + Rp), out)
        if np.any(ch >= 5):
            Ts, Tp = sums.Ts[inv], sums.Tp[inv]
            out = np.where(ch == 5, Ts, out)
            out = np.where(ch == 6, Tp, out)
            out = np.where(ch == 7, 0.5 * (Ts + Tp), out)
        if np.any(ch == 8):  # depolarization, 1 - sqrt(N^2 + C^2 + S^2) (films.incoherent)
            out = np.where(ch == 8, inc.ellipsometry(sums)[2][inv], out)
        return out

    def _evaluate(self, p, theta_i, theta_r, phi_r, wavelength):
        if wavelength is None or np.shape(theta_i) != self.channels.shape:
            raise FitError("film model: evaluated on rows other than the fitted data")
        try:
            return self.rows(p, np.degrees(theta_i), np.asarray(wavelength, float))
        except ValueError:  # parameters outside the physical domain (n < 0, C > 2 E0, ...)
            return np.full(self.channels.shape, np.nan)


# --------------------------------------------------------------------------------------
# data
# --------------------------------------------------------------------------------------


def _frame(data: Any) -> pd.DataFrame:
    if isinstance(data, Measurement):
        return data.data
    if isinstance(data, pd.DataFrame):
        return data
    if isinstance(data, (list, tuple)):
        return pd.concat([_frame(d) for d in data], ignore_index=True)
    raise FilmError(
        f"data: expected a Measurement or a dataset DataFrame, got {type(data).__name__}"
    )


def _film_rows(
    data: Any,
    wl_range: tuple[float, float] | None,
    default_sigma: Mapping[str, float] | None,
    depolarization: bool = False,
) -> tuple[pd.DataFrame, NDArray]:
    """The rows a film fit uses and their channel codes (with the depolarization rows)."""
    df = _frame(data)
    wanted = FILM_QUANTITIES + (("depolarization",) if depolarization else ())
    df = df[df["quantity"].astype(str).isin(wanted)].copy()
    if "channel" in df.columns:
        ch = df["channel"].astype(object).where(df["channel"].notna(), "").astype(str)
    else:
        ch = pd.Series("", index=df.index)
    ell = df["quantity"].astype(str).isin(["psi", "delta"])
    bad = ell & ~ch.isin(["", "pp"])
    df, ch, ell = df[~bad], ch[~bad], ell[~bad]  # generalised-ellipsometry cross channels
    if wl_range is not None:
        keep = (df["wavelength_nm"] >= wl_range[0]) & (df["wavelength_nm"] <= wl_range[1])
        df, ch, ell = df[keep], ch[keep], ell[keep]
    if df.empty:
        raise FilmError(
            "data: no psi, delta, reflectance or transmittance rows"
            + (f" in {wl_range[0]:g}-{wl_range[1]:g} nm" if wl_range else "")
        )
    q = df["quantity"].astype(str)
    code = np.full(len(df), -1)
    code[(q == "psi").to_numpy()] = 0
    code[(q == "delta").to_numpy()] = 1
    code[(q == "depolarization").to_numpy()] = 8
    ell = ell | (q == "depolarization")  # needs an angle as psi and Delta do
    for qty, base in (("reflectance", 2), ("transmittance", 5)):
        m = (q == qty).to_numpy()
        c = ch.to_numpy()
        code[m & (c == "s")] = base
        code[m & (c == "p")] = base + 1
        code[m & np.isin(c, ["", "u", "unpolarized", "unpolarised"])] = base + 2
        odd = m & (code == -1)
        if odd.any():
            raise FilmError(
                f"data: {qty} rows with channel {sorted(set(c[odd]))}; expected s, p or none"
            )
    theta = df["theta_i_deg"].to_numpy(float).copy()
    no_angle = ~np.isfinite(theta)
    if np.any(no_angle & ell.to_numpy()):
        raise FilmError("data: psi/delta or depolarization rows without an angle of incidence")
    theta[no_angle] = 0.0  # spectrophotometer R, T without an angle: normal incidence
    df["theta_i_deg"] = theta
    sig = df["sigma"].to_numpy(float).copy()
    missing = ~(np.isfinite(sig) & (sig > 0))
    if missing.any():
        for qty in sorted(set(q[missing])):
            if default_sigma and qty in default_sigma:
                sig[missing & (q == qty).to_numpy()] = float(default_sigma[qty])
            else:
                raise FilmError(
                    f"data: {int((missing & (q == qty).to_numpy()).sum())} {qty} row(s) have no "
                    f"sigma; a film fit weights by the files' sigmas: give default_sigma="
                    f"{{'{qty}': ...}} (CLI --sigma {qty}=VALUE) in the value's units"
                )
    df["sigma"] = sig
    return df.reset_index(drop=True), code


def stated_samples(rows: pd.DataFrame) -> dict[str, tuple[str, ...]]:
    """The sample names each file of ``rows`` states: ``source`` -> names, in row order.

    A name is stated when the file says it, not when its reader took the file's name
    (:func:`labbrdf.samples.stated_names`); files that state none are left out.
    """
    if "sample" not in rows.columns or "source" not in rows.columns:
        return {}
    out: dict[str, tuple[str, ...]] = {}
    for src, g in rows.groupby(rows["source"].astype(str), sort=False):
        names = tuple(dict.fromkeys(g["sample"].astype(str)))
        said = stated_names(SampleFile(Path(str(src)), names))
        if said:
            out[str(src)] = said
    return out


def _check_one_sample(rows: pd.DataFrame) -> None:
    """Refuse rows whose files state different samples (a film fit is of one sample)."""
    said = stated_samples(rows)
    names = list(dict.fromkeys(n for v in said.values() for n in v))
    if len(names) < 2:
        return
    listing = "; ".join(f"{src} states {', '.join(map(repr, v))}" for src, v in said.items())
    raise FilmError(
        f"data: the files state {len(names)} different samples ({listing}); a film fit is "
        "of one sample: fit each sample on its own (select its rows), or, if they are one "
        "sample, say so with one_sample=True (CLI: --same-sample FILE,FILE)"
    )


def _check_coverage(fm: FilmModel, wl: NDArray) -> None:
    mats = [("substrate", fm.stack.substrate), ("ambient", fm.stack.ambient)]
    mats += [(lay.name, lay.material) for lay in fm.stack.layers]
    for name, m in mats:
        if isinstance(m, disp.Tabulated) and not m.covers(wl):
            lo, hi = m.range_nm
            raise FilmError(
                f"{fm.source}: {name} material {m.source} covers {lo:g}-{hi:g} nm but the "
                f"data span {float(wl.min()):g}-{float(wl.max()):g} nm; restrict the fit "
                "with wavelength_nm = [min, max] (CLI --wavelength-range MIN:MAX) or use a "
                "table that covers the data"
            )


# --------------------------------------------------------------------------------------
# the fit
# --------------------------------------------------------------------------------------


def woollam_mse(chisqr: float, n_values: int, n_params: int) -> float:
    """Woollam's mean squared error of a fit.

    ``MSE = sqrt( 1/(2N - M) sum_i [ ((psi_mod - psi_exp)/sigma_psi)^2 +
    ((Delta_mod - Delta_exp)/sigma_Delta)^2 ] )`` for N (psi, Delta) pairs and M fitted
    parameters (J. A. Woollam Co., *Guide to Using WVASE32*, section "Mean Squared Error";
    C. M. Herzinger et al., J. Appl. Phys. 83, 3323 (1998), eq. (1)), i.e.
    ``sqrt(chi2 / nu)`` with the ``2N`` measured values; with reflectance or transmittance
    rows in a joint fit their weighted squares count the same way.

    Notes
    -----
    CompleteEASE's default MSE is computed from N = cos 2psi, C and S = sin 2psi cos/sin
    Delta (times 1000), not from psi and Delta: it is a different number for the same fit.
    """
    nu = n_values - n_params
    return math.sqrt(chisqr / nu) if nu > 0 else math.nan


@dataclass
class FilmFit:
    """A film fit: the core's :class:`~labbrdf.FitResult` and the best-fit stack."""

    result: FitResult
    model: FilmModel
    stack: Stack
    data: pd.DataFrame
    channels: NDArray
    sources: list[str]

    @property
    def mse(self) -> float:
        """Woollam's MSE (:func:`woollam_mse`)."""
        return woollam_mse(self.result.chisqr, self.result.ndata, self.result.nvarys)

    def _nk_at(self, wl: float) -> dict[str, dict[str, Any]]:
        """n, k of each medium at ``wl`` with stderr and 95 % intervals (:mod:`.film_nk`)."""
        from .film_nk import nk_entry

        return nk_entry(self, wl)

    @property
    def substrate_name(self) -> str:
        """The substrate in words: its table's or file's name, or its model."""
        from .film_verdict import material_label

        return material_label(self.stack.substrate)

    @property
    def verdict(self) -> str | None:
        """Words saying that the model is wrong (MSE above ``MSE_WRONG_MODEL``), or None.

        :mod:`labbrdf.fitting.film_verdict`: the parameters are then not meaningful, and
        the words say what to try (another substrate, the bare-substrate file, more layers).
        """
        from .film_verdict import wrong_model_verdict

        return wrong_model_verdict(self.mse, self.substrate_name)

    @property
    def misfit_scale(self) -> float | None:
        """``sqrt(chi2/nu)`` when chi-square rejects the model at the 1 % level, else None.

        The model then misses the data by more than the files' sigmas (a systematic
        misfit: the substrate's table, an unmodelled layer, the instrument's calibration);
        intervals from the sigmas alone are too narrow, and ``*_scaled`` intervals (stderr
        times this factor, lmfit's ``scale_covar``) are reported beside them.
        """
        res = self.result
        if res.nfree <= 0 or not math.isfinite(res.chisqr):
            return None
        if special.chdtrc(res.nfree, res.chisqr) >= 0.01:
            return None
        return math.sqrt(res.redchi)

    def notes(self) -> list[str]:
        """Plain-language notes: misfit, thickness-index trade-offs, bounds."""
        res = self.result
        notes = []
        if self.misfit_scale is not None:
            notes.append(
                f"chi2/nu = {res.redchi:.3g}: the model misses the data by more than the files' "
                "sigmas (p < 0.01); the intervals from the sigmas alone are too narrow; "
                f"*_scaled intervals multiply them by sqrt(chi2/nu) = {self.misfit_scale:.3g}"
            )
        for k in res.var_names:
            q = res.params[k]
            for other, c in (q.correl or {}).items():
                if k < other and abs(c) >= CORREL_MAX:
                    a_th, b_th = k.endswith("thickness_nm"), other.endswith("thickness_nm")
                    if a_th != b_th:
                        notes.append(
                            f"{k} and {other} trade off (correlation {c:+.3f}): the data fix "
                            "their combination (optical thickness) better than each alone; "
                            "typical of thin films (Aspnes' d-n correlation below ~10 nm)"
                        )
                    else:
                        notes.append(f"{k} and {other} are strongly correlated ({c:+.3f})")
        for k, fl in res.flags.items():
            for reason in res.flag_reasons.get(k, []):
                notes.append(f"{k}: {reason}")
            if "at_bound" in fl and not res.flag_reasons.get(k):
                notes.append(f"{k}: at a bound of its box")
        return notes

    def channel_stats(self) -> dict[str, dict[str, float]]:
        """chi2 and count per data channel (psi, delta, R_s, ...)."""
        names = {0: "psi", 1: "delta", 2: "R_s", 3: "R_p", 4: "R", 5: "T_s", 6: "T_p", 7: "T"}
        names[8] = "depolarization"
        r = np.asarray(self.result.residual, float) / self.data["sigma"].to_numpy(float)
        out = {}
        for code, nm in names.items():
            m = self.channels == code
            if m.any():
                out[nm] = {"n": int(m.sum()), "chi2": float(np.sum(r[m] ** 2))}
        return out

    def summary(self, at_nm: Sequence[float] | None = None) -> dict[str, Any]:
        """JSON-safe summary of the fit.

        Layers (thickness, material parameters, n and k at 633 nm with
        stderr and 95 % intervals), chi2, nu, chi2/nu, MSE, the verdict (None, or words
        saying that the model is wrong: :attr:`verdict`), flags, correlations, notes.

        Parameters
        ----------
        at_nm : sequence of float, optional
            Wavelengths [nm] at which ``nk_at`` gives every medium's n, k with stderr and
            95 % intervals (as ``nk_at_633nm``).

        Raises
        ------
        FilmError
            A wavelength of ``at_nm`` outside a table of the stack.
        """
        res = self.result
        nk = self._nk_at(NK_REPORT_NM) if self._covers(NK_REPORT_NM) else {}
        scale = self.misfit_scale
        tq = float(special.stdtrit(max(res.nfree, 1), 0.975))
        at_nm = [float(w) for w in (at_nm or ())]
        for w in at_nm:
            if not self._covers(w):
                raise FilmError(
                    f"n, k at {w:g} nm: outside the wavelengths the stack's tables cover"
                )

        def param(k: str) -> dict[str, Any]:
            q = res.params[k]
            d: dict[str, Any] = {"value": q.value, "vary": q.vary, "units": q.units}
            if q.vary:
                d["stderr"] = q.stderr
                d["ci95"] = list(q.ci95) if q.ci95 is not None else None
                d["ci_method"] = res.ci_methods.get(k, res.ci_method)
                if k in res.ci_reasons:
                    d["ci_reason"] = res.ci_reasons[k]
                if q.stderr is not None:
                    d["ci95_wald"] = [
                        max(q.value - tq * q.stderr, q.min),
                        min(q.value + tq * q.stderr, q.max),
                    ]
                if scale is not None and q.stderr is not None:
                    se = q.stderr * scale
                    d["stderr_scaled"] = se
                    d["ci95_scaled"] = [
                        max(q.value - tq * se, q.min),
                        min(q.value + tq * se, q.max),
                    ]
                d["bounds"] = [q.min, q.max]
                d["flags"] = res.flags.get(k, [])
            return d

        layers = []
        for lay in self.stack.layers:
            keys = [f"{lay.name}.{k}" for k in lay.params]
            layers.append(
                {
                    "name": lay.name,
                    "material": lay.material.to_dict(),
                    "parameters": {k.split(".", 1)[1]: param(k) for k in keys},
                    f"nk_at_{NK_REPORT_NM:g}nm": nk.get(lay.name),
                }
            )
        sub_keys = [k for k in self.stack.values() if k.startswith("substrate.")]
        stack_keys = [k for k in self.stack.values() if k.startswith("stack.")]
        return jsonable(
            {
                "kind": "labbrdf film fit",
                "sources": self.sources,
                "stack": self.stack.to_dict(),
                "layers": layers,
                "substrate": {
                    "name": self.substrate_name,
                    "material": self.stack.substrate.to_dict(),
                    "parameters": {k.split(".", 1)[1]: param(k) for k in sub_keys},
                    f"nk_at_{NK_REPORT_NM:g}nm": nk.get("substrate"),
                },
                "stack_parameters": {k.split(".", 1)[1]: param(k) for k in stack_keys},
                "wavelength_range_nm": [
                    float(self.data["wavelength_nm"].min()),
                    float(self.data["wavelength_nm"].max()),
                ],
                "ndata": res.ndata,
                "nvarys": res.nvarys,
                "nfree": res.nfree,
                "chisqr": res.chisqr,
                "redchi": res.redchi,
                "mse": self.mse,
                "channels": self.channel_stats(),
                "success": res.success,
                "message": res.message,
                "method": res.method,
                "search": [str(st["algorithm"]) for st in res.stages],
                "seed": res.seed,
                "nfev": res.nfev,
                "elapsed_s": res.elapsed_s,
                "ci_method": res.ci_method,
                "flags": res.flags,
                "correlations": {
                    k: res.params[k].correl for k in res.var_names if res.params[k].correl
                },
                "notes": self.notes(),
                "warnings": list(res.warnings),
                "verdict": self.verdict,
                "nk_at": [{"wavelength_nm": w, "media": self._nk_at(w)} for w in at_nm],
            }
        )

    def _covers(self, wl: float) -> bool:
        try:
            self.stack.nk(wl)
        except ValueError:
            return False
        return True

    def save_json(
        self, path: str | os.PathLike[str], at_nm: Sequence[float] | None = None
    ) -> Path:
        """Write :meth:`summary` (``at_nm`` as there) as JSON, atomically.

        A new file or a complete replacement.
        """
        from ..outputs import atomic_output

        p = Path(path)
        text = json.dumps(self.summary(at_nm), indent=2, allow_nan=False) + "\n"
        with atomic_output(p) as tmp:
            Path(tmp).write_text(text)
        return p

    def compare_reflectance(self, reflectance: Any) -> pd.DataFrame:
        """Measured specular reflectance against the best-fit stack's prediction.

        Parameters
        ----------
        reflectance : Measurement, DataFrame or list of them
            Rows with ``quantity == "reflectance"``: channel ``s``/``p`` (R_s, R_p) or none
            (``(R_s + R_p)/2``); no angle means normal incidence.

        Returns
        -------
        pandas.DataFrame
            The columns of :func:`labbrdf.nk.compare_reflectance` (``sample, source,
            wavelength_nm, theta_i_deg, channel, measured, measured_sigma, predicted,
            predicted_sigma, difference, difference_sigma, z``), so a report treats both
            alike. ``predicted_sigma`` propagates the fit's covariance (scaled by
            :attr:`misfit_scale` when chi-square rejects the model) through the stack.
            Rows outside the wavelengths the stack's tables cover are dropped and counted
            in ``attrs["outside_range"]``.

        Raises
        ------
        FilmError
            No reflectance rows, or none the stack covers.
        """
        df = _frame(reflectance)
        rows = df[df["quantity"].astype(str) == "reflectance"]
        if rows.empty:
            raise FilmError("no reflectance rows in the data to compare with")
        wl = rows["wavelength_nm"].to_numpy(float)
        ok = np.array([self._covers(float(w)) for w in np.unique(wl)])
        covered = np.isin(wl, np.unique(wl)[ok])
        outside = int((~covered).sum())
        rows = rows[covered]
        if rows.empty:
            raise FilmError("no reflectance row within the wavelengths the stack covers")
        wl = rows["wavelength_nm"].to_numpy(float)
        theta = np.nan_to_num(rows["theta_i_deg"].to_numpy(float), nan=0.0)
        if "channel" in rows.columns:
            channel = rows["channel"].astype(object).to_numpy()
        else:
            channel = np.full(len(rows), None, dtype=object)
        is_s, is_p = channel == "s", channel == "p"

        def predict(st: Stack) -> NDArray:
            rs, rp = st.reflectance(wl, theta)
            return np.where(is_s, rs, np.where(is_p, rp, 0.5 * (rs + rp)))

        predicted = predict(self.stack)
        res = self.result
        names = list(res.var_names)
        cov = None if res.covar is None else np.asarray(res.covar, float)
        psig = np.full(len(rows), np.nan)
        if cov is not None and cov.shape == (len(names), len(names)) and np.all(np.isfinite(cov)):
            vals = {k: res.params[k].value for k in names}
            G = np.empty((len(rows), len(names)))
            for j, k in enumerate(names):
                q = res.params[k]
                h = 1e-6 * max(abs(q.value), 1e-3)
                up, dn = dict(vals), dict(vals)
                up[k] = min(q.value + h, q.max)
                dn[k] = max(q.value - h, q.min)
                G[:, j] = (
                    predict(self.model.stack.with_values(up))
                    - predict(self.model.stack.with_values(dn))
                ) / (up[k] - dn[k])
            var = np.einsum("ij,jk,ik->i", G, cov, G) * (self.misfit_scale or 1.0) ** 2
            psig = np.sqrt(np.maximum(var, 0.0))
        measured = rows["value"].to_numpy(float)
        msig = rows["sigma"].to_numpy(float)
        diff = measured - predicted
        dsig = np.where(np.isnan(msig), psig, np.hypot(msig, np.nan_to_num(psig)))
        with np.errstate(divide="ignore", invalid="ignore"):
            z = diff / dsig
        out = pd.DataFrame(
            {
                "sample": rows["sample"].astype(object).to_numpy(),
                "source": rows["source"].astype(object).to_numpy(),
                "wavelength_nm": wl,
                "theta_i_deg": rows["theta_i_deg"].to_numpy(float),
                "channel": channel,
                "measured": measured,
                "measured_sigma": msig,
                "predicted": predicted,
                "predicted_sigma": psig,
                "difference": diff,
                "difference_sigma": dsig,
                "z": z,
            }
        )
        out.attrs["outside_range"] = outside
        return out

    def nk_table(self, wavelength_nm: ArrayLike | None = None) -> pd.DataFrame:
        """n, k of every layer and the substrate, with their standard errors.

        On the fitted wavelengths (or the given ones [nm]); the columns of
        :func:`labbrdf.fitting.film_nk.nk_at_table` (``<name>_n``, ``<name>_n_stderr``, ...,
        and ``*_stderr_scaled`` where chi-square rejects the model).
        """
        from .film_nk import nk_at_table

        wl = (
            np.unique(self.data["wavelength_nm"].to_numpy(float))
            if wavelength_nm is None
            else np.asarray(wavelength_nm, float)
        )
        return nk_at_table(self, wl)

    def fit_report(self, at_nm: Sequence[float] | None = None) -> str:
        """Text report: each layer's parameters and n, k, the substrate, the fit, notes.

        What ``labbrdf film`` prints (:func:`labbrdf.fitting.film_display.film_fit_report`
        of :meth:`summary`); ``at_nm``: wavelengths [nm] at which to print every medium's
        n, k with stderr (``labbrdf film --at``). Ends with the verdict where the MSE says
        that the model is wrong.
        """
        from .film_display import film_fit_report

        return film_fit_report(self.summary(at_nm))

    def __str__(self) -> str:
        return self.fit_report()

    def _repr_html_(self) -> str:
        from .film_display import film_fit_html

        return film_fit_html(self.summary())

    def plot(self, ax: Any = None) -> Any:
        """Data with 1-sigma bars and the fit per channel against wavelength, residuals below.

        Parameters
        ----------
        ax : sequence of matplotlib Axes, optional
            Two per channel present (psi, Delta, R, T ...): the data and the residual
            axes; default a new figure, one column per channel.

        Returns
        -------
        matplotlib Figure
        """
        from .film_display import film_fit_plot

        return film_fit_plot(self, ax)


def _fits_depolarization(choice: bool | str, stack: Stack, data: Any) -> bool:
    """Whether the depolarization rows enter the fit (:func:`fit_film`'s rule)."""
    if choice not in ("auto", True, False):
        raise FilmError(f"depolarization: expected 'auto', True or False, got {choice!r}")
    has = bool((_frame(data)["quantity"].astype(str) == "depolarization").any())
    if choice is True and not has:
        raise FilmError(
            "depolarization: the data have no depolarization rows to fit (a WVASE file "
            "carries them as dpolE); expected data with them, or depolarization='auto'"
        )
    return has and (choice is True or (choice == "auto" and stack.depolarizing))


def fit_film(
    stack_or_model: Stack | FilmModel | str | os.PathLike[str],
    data: Any,
    *,
    free: Mapping[str, tuple[float, float]] | None = None,
    wavelength_range_nm: tuple[float, float] | None = None,
    default_sigma: Mapping[str, float] | None = None,
    method: str = METHOD,
    seed: int = 0,
    ci: str = "auto",
    maxeval: int | Sequence[int | None] | None = None,
    one_sample: bool = False,
    on_wald: Callable[[FilmFit], None] | None = None,
    depolarization: bool | str = "auto",
) -> FilmFit:
    """Fit a film stack's thicknesses and dispersion parameters to measured data.

    Parameters
    ----------
    stack_or_model : Stack, FilmModel or path
        A :class:`Stack` (every layer's thickness and parametric material parameters vary,
        :meth:`FilmModel.default`), a :class:`FilmModel`, or a TOML model file
        (:func:`load_model`).
    data : Measurement, DataFrame or list of them
        Rows with quantity psi, delta (ordinary ellipsometry, any angles), reflectance or
        transmittance (channel ``s``, ``p`` or unpolarised; no angle = normal incidence), of
        one sample: several files are fitted jointly.
    free : mapping, optional
        ``"<layer>.<name>" -> (min, max)``: replaces the model's varying parameters.
    wavelength_range_nm : (float, float), optional
        Fit only these wavelengths (overrides the model file's).
    default_sigma : mapping, optional
        quantity -> sigma for rows whose file gives none.
    method, seed, maxeval
        As :func:`labbrdf.fitting.fit` (global then local; seeded).
    ci : {"auto", "wald", "profile"}
        95 % intervals from the covariance (``"wald"``, the fast answer), from the profile
        of chi-square (``"profile"``), or (default) Wald first and the profile only for the
        parameters whose interval it can change: one at a bound, without a standard
        error, correlated above 0.99 with another, or over whose Wald interval chi-square
        is not quadratic (:func:`labbrdf.fitting.intervals.profile_reasons`). The summary
        says per parameter which interval it carries (``ci_method``).
    one_sample : bool
        The caller says that the files are one sample although they state different
        sample names (a relabelled sample, a typo in a header). Without it such data are
        refused: a joint fit of two samples is no sample's film.
    on_wald : callable, optional
        Called with the fit carrying Wald intervals before any profile is computed (a
        command line prints this fast answer first); not called when nothing is profiled.
    depolarization : {"auto", True, False}
        Whether the files' depolarization rows (WVASE ``dpolE``) enter the residual, each
        divided by its own sigma. ``"auto"`` (default): when the model can depolarize
        (:attr:`Stack.depolarizing`: a thickness spread, bandwidth or angle spread
        parameter, an incoherent layer or a finite substrate) and the data have such rows;
        a model that cannot depolarize predicts 0 whatever its parameters, and the channel
        would only add a constant to chi-square. ``True`` requires such rows. Their chi2
        is the ``depolarization`` entry of :meth:`FilmFit.channel_stats`, and they count in
        the MSE as every fitted value does.

    Returns
    -------
    FilmFit

    Raises
    ------
    FilmError
        No usable rows, a row without sigma, a table that does not cover the data, files
        that state different sample names (without ``one_sample``; naming the files and
        their names).
    FitError
        From the core (too few points, unknown method, ...).
    """
    if isinstance(stack_or_model, Stack):
        fm = FilmModel.default(stack_or_model)
    elif isinstance(stack_or_model, FilmModel):
        fm = stack_or_model
    elif isinstance(stack_or_model, (str, os.PathLike)):
        fm = load_model(stack_or_model, tabulated_from_file)
    else:
        raise FilmError(
            f"expected a Stack, a FilmModel or a model file, got {type(stack_or_model).__name__}"
        )
    if free is not None:
        known = fm.stack.values()
        bad = sorted(set(free) - set(known))
        if bad:
            raise FilmError(f"free: unknown parameter(s) {bad}; parameters: {sorted(known)}")
        fm = FilmModel(fm.stack, {k: (float(a), float(b)) for k, (a, b) in free.items()},
                       fm.wavelength_range_nm, fm.source)  # fmt: skip
    wl_range = wavelength_range_nm or fm.wavelength_range_nm
    with_dpol = _fits_depolarization(depolarization, fm.stack, data)
    rows, codes = _film_rows(data, wl_range, default_sigma, with_dpol)
    if not one_sample:
        _check_one_sample(rows)
    wl = rows["wavelength_nm"].to_numpy(float)
    _check_coverage(fm, wl)
    for k, (lo, hi) in fm.free.items():
        if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
            raise FilmError(f"{fm.source}: {k}: bounds [{lo}, {hi}] must be finite with min < max")
    model = _FilmFitModel(fm, codes, rows["value"].to_numpy(float))
    fd = FitData(
        rows["theta_i_deg"].to_numpy(float),
        rows["theta_i_deg"].to_numpy(float),
        rows["value"].to_numpy(float),
        rows["sigma"].to_numpy(float),
        180.0,
        wl,
        "film",
        "mixed",
    )
    sources = sorted(set(rows["source"].astype(str))) if "source" in rows else []

    def film(res: FitResult) -> FilmFit:
        best = fm.stack.with_values({k: res.params[k].value for k in fm.free})
        return FilmFit(res, fm, best, rows, codes, sources)

    first = None if on_wald is None else (lambda res: on_wald(film(res)))
    res = fit(model, fd, method=method, seed=seed, ci=ci, maxeval=maxeval, guess=False,
              weighting="sigma", mask_zeros=False, on_wald=first)  # fmt: skip
    return film(res)
