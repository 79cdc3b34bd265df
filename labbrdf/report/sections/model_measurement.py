"""Section ``model_measurement`` (validation report): model against measurement.

The user report's model-against-measurement sections (``smoothness``: Rayleigh, Fraunhofer,
Davies, Bennett-Porteus; ``prediction``: the tracer's specular DOP and BRDF with no fitted
parameter) run here on the bundled set ``fixtures/predict_measure/``: one SYNTHETIC sample
(a Gaussian height map, its psi/Delta, its specular reflectance spectrum and a ``.bsdf``
traced from it, made consistent by ``make_fixtures.py``). The same section functions draw
it; this module adds checks that can fail:

* every Rayleigh-parameter number of the smoothness tables equals an evaluation written out
  here from the formulas (Davies 1954; the Rayleigh and Fraunhofer thresholds; Bennett and
  Porteus 1961), and every verdict follows from sigma +- 2 u(sigma) and its threshold;
* the measured specular reflectance divided by the Fresnel prediction equals ``exp(-g)``
  (the set was written that way: this checks the chain readers -> pairing -> n, k
  inversion -> band-limited sigma, not new physics);
* the prediction section's own checks: the specular DOP agrees with the ellipsometer's, the
  predicted BRDF agrees with the ``.bsdf`` within its Monte Carlo error;
* a control: the same height map and ``.bsdf`` with the psi/Delta of a wrong index
  (``control_wrong_index_psi_delta.dat``) must be flagged as disagreeing.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from ... import adapters
from ...prediction import predict_brdf, roughness_alpha
from ..builder import Builder, Unavailable, slug
from ..context import Context
from ..inputs import ingest_height_maps, ingest_read
from ..pairing import sample_groups
from ..tracing import rays_of, tracer_map

__all__ = [
    "CONTROL_FILE",
    "SET_DIR",
    "SET_FILES",
    "bulk_nk",
    "formula_deviations",
    "model_measurement_section",
]

#: the set's folder under the fixtures, its files (one sample) and the wrong-index control
SET_DIR = "predict_measure"
SET_FILES = (
    "p1_heights.sdf",
    "p1_psi_delta.dat",
    "p1_specular.Sample.Raw.asc",
    "p1_brdf_600nm.bsdf",
)
CONTROL_FILE = "control_wrong_index_psi_delta.dat"

#: the independent evaluation differs from the section's by float rounding only
FORMULA_RTOL = 1e-9
#: measured / Fresnel against exp(-g): %R is written with 6 significant digits (5e-6
#: relative), psi/Delta with 10 (n, k to ~1e-9); 2e-5 leaves a factor 4 on the rounding
SET_RTOL = 2e-5
#: coverage factor of the verdicts (labbrdf.roughness.smoothness.COVERAGE_FACTOR, restated)
K_VERDICT = 2.0


def bulk_nk(ctx: Context) -> None:
    """Combined bulk n, k of every psi/Delta file into ``ctx.nk_combined``.

    What the user report's section ``nk`` keeps for the section ``smoothness`` (its
    measured/Fresnel ratio), without drawing the section ``nk``.
    """
    from ... import nk as nkmod

    for f in ctx.frames:
        if not (f["quantity"].astype(str) == "psi").any():
            continue
        pts = nkmod.nk_table(nkmod.ordinary_psi_delta(f), on_ill_conditioned="ignore")
        ctx.nk_combined[str(f["source"].iloc[0])] = nkmod.combined_table(pts)


def _rel(a: Any, b: float) -> float:
    a = float(a)
    return abs(a - b) / max(abs(b), 1e-300)


def formula_deviations(rows: list[dict[str, Any]]) -> tuple[float, list[str]]:
    """How far a smoothness table is from the formulas: worst deviation, wrong verdicts.

    Written out here, independently of :mod:`labbrdf.roughness.smoothness`: ``g = (4 pi sigma cos
    theta / lambda)^2`` (Davies 1954), ``u(g) = 2 g u(sigma) / sigma``, the Rayleigh
    threshold ``lambda / (8 cos theta)``, the Fraunhofer threshold ``lambda / (32 cos
    theta)``, the specular factor ``exp(-g)``; a verdict is "smooth" when ``sigma + 2u`` is
    below the threshold, "rough" when ``sigma - 2u`` is at or above it, else "undecided".

    Parameters
    ----------
    rows : list of dict
        Rows of a ``smoothness_*`` table (``results["tables"][...]["rows"]``).

    Returns
    -------
    (float, list of str)
        Largest relative deviation over every number of every judged row, and a text per
        wrong verdict.
    """
    worst, wrong = 0.0, []
    for r in rows:
        if r.get("g") is None:
            continue
        lam, th, s = float(r["wavelength_nm"]), math.radians(float(r["theta_i"])), r["sigma_nm"]
        c = math.cos(th)
        g = (4.0 * math.pi * float(s) * c / lam) ** 2
        u = float(r["u_sigma_nm"]) if r.get("u_sigma_nm") is not None else 0.0
        thr = {"rayleigh": lam / (8.0 * c), "fraunhofer": lam / (32.0 * c)}
        worst = max(
            worst,
            _rel(r["g"], g),
            _rel(r["loss"], math.exp(-g)),
            _rel(r["thr_rayleigh"], thr["rayleigh"]),
            _rel(r["thr_fraunhofer"], thr["fraunhofer"]),
        )
        if r.get("u_g") is not None:
            worst = max(worst, _rel(r["u_g"], 2.0 * g * u / float(s)))
        for crit, t in thr.items():
            lo, hi = float(s) - K_VERDICT * u, float(s) + K_VERDICT * u
            want = "smooth" if hi < t else ("rough" if lo >= t else "undecided")
            if r[crit] != want:
                wrong.append(f"{crit} at {lam:g} nm, {r['theta_i']:g} deg: {r[crit]} != {want}")
    return worst, wrong


def model_measurement_section(
    ctx: Context,
    smoothness: Callable[[Context], object],
    prediction: Callable[[Context], object],
) -> None:
    """Smoothness and prediction on the bundled set, with checks and a wrong-index control.

    Parameters
    ----------
    ctx : Context
    smoothness, prediction : callable
        The user report's sections ``smoothness`` and ``prediction``, run here on the set
        (the workflow passes them: a section does not import another).
    """
    if ctx.fixtures is None:
        raise Unavailable("no fixture folder given")
    d = ctx.fixtures / SET_DIR
    paths = [d / n for n in SET_FILES]
    missing = [p.name for p in [*paths, d / CONTROL_FILE] if not p.is_file()]
    if missing:
        raise Unavailable(f"the bundled set {d} lacks {', '.join(missing)}")
    b = ctx.b
    b.text(
        "The user report's model-against-measurement sections, run on one bundled SYNTHETIC "
        f"sample ({SET_DIR}/, fixtures/README.md): a Gaussian height map (sigma 0.1 um, "
        "correlation length 1.4 um), psi/Delta of a bare substrate n + ik = 1.2 + 7.26i, its "
        "near-normal specular reflectance spectrum (Fresnel times the Davies factor exp(-g) "
        "of the map), and a .bsdf traced from the map's GGX alpha and that index. The files "
        "agree with each other by construction, so every comparison below must agree, and "
        "the wrong-index control must not."
    )
    sub = Context(
        b,
        quick=ctx.quick,
        executor=ctx.executor,
        seed=ctx.seed,
        scale=ctx.scale,
        fixtures=d,
        shared=ctx.shared,
    )
    inputs = adapters.read_inputs(paths).files
    ingest_height_maps(sub, inputs)
    ingest_read(
        sub,
        [f for f in inputs if f.kind == "optical"],
        root=d,
        check_id="model_measurement.read",
        table_id="model_measurement_files",
    )
    sample_groups(
        sub,
        paths,
        [paths],
        given_as="one sample of the bundled set (height maps and .bsdf files state no name)",
    )
    bulk_nk(sub)
    b.heading("Roughness against wavelength", anchor="model_measurement_smoothness")
    smoothness(sub)
    _smoothness_checks(b, sub)
    b.heading("Predict, then measure", anchor="model_measurement_prediction")
    prediction(sub)
    b.heading("Control: the psi/Delta of a wrong index", anchor="model_measurement_control")
    _control(sub, d)


def _smoothness_checks(b: Builder, ctx: Context) -> None:
    tables = b.results["tables"]
    main = [t for t in tables if t.startswith("smoothness_") and "_tis_" not in t]
    tis = [t for t in tables if t.startswith("smoothness_tis_")]
    rows = [r for t in main for r in tables[t]["rows"]]
    judged = [r for r in rows if r.get("g") is not None]
    worst, wrong = formula_deviations(rows)
    b.check(
        "model_measurement.rayleigh_formula",
        "the smoothness table's g, u(g), thresholds and exp(-g) equal the formulas "
        "evaluated independently",
        bool(judged) and worst <= FORMULA_RTOL,
        against="g = (4 pi sigma cos theta / lambda)^2 (Davies 1954), lambda / (8 cos theta), "
        "lambda / (32 cos theta), exp(-g), written out in the check",
        value=worst,
        tolerance=FORMULA_RTOL,
        justification=f"largest relative deviation over {len(judged)} judged rows; the same "
        "formula in double precision differs by rounding only",
        reason="" if judged else "no judged row in the smoothness table",
    )
    b.check(
        "model_measurement.rayleigh_verdicts",
        "every Rayleigh and Fraunhofer verdict follows from sigma +- 2 u(sigma)",
        bool(judged) and not wrong,
        against="smooth if sigma + 2u < threshold, rough if sigma - 2u >= threshold",
        value=len(wrong),
        tolerance=0,
        justification=f"{2 * len(judged)} verdicts, {sorted({r['rayleigh'] for r in judged})} "
        "by Rayleigh",
        reason="; ".join(wrong)[:2000],
    )
    with_ratio = [r for r in judged if r.get("ratio") is not None]
    dev = max((_rel(r["ratio"], math.exp(-float(r["g"]))) for r in with_ratio), default=math.inf)
    b.check(
        "model_measurement.specular_loss",
        "measured / Fresnel reflectance equals the Davies factor exp(-g) on the consistent set",
        len(with_ratio) == len(judged) and dev <= SET_RTOL,
        against="p1_specular.Sample.Raw.asc divided by the Fresnel R of the psi/Delta n, k",
        value=dev,
        tolerance=SET_RTOL,
        justification=f"{len(with_ratio)} of {len(judged)} judged rows have a ratio; the file "
        "holds R_F exp(-g) to 6 digits, so this checks the readers, the pairing, the n, k "
        "inversion and the band-limited sigma end to end",
    )
    worst_t, n_t = 0.0, 0
    for m in ctx.map_roughness.values():
        for g_ in ctx.samples:
            t = f"smoothness_tis_{slug(f'{g_.name}_{m.name}')}"
            rows_t = tables[t]["rows"] if t in tis else []
            for r in rows_t:
                if r.get("tis_r0") is None:
                    continue
                lam, th = float(r["wavelength_nm"]), math.radians(float(r["theta_i"]))
                sigma, _ = m.sigma_for(lam / (1.0 + math.sin(th)))
                g = (4.0 * math.pi * sigma * math.cos(th) / lam) ** 2
                worst_t = max(
                    worst_t, _rel(r["tis_r0"], -math.expm1(-g)), _rel(r["tis_r0_small"], g)
                )
                n_t += 1
    b.check(
        "model_measurement.bennett_porteus",
        "the TIS table's Bennett-Porteus TIS / R_0 = 1 - exp(-g) ~ g equal the formula",
        n_t > 0 and worst_t <= FORMULA_RTOL,
        against="Bennett & Porteus (1961), g written out in the check from the map's sigma "
        "over lambda / (1 + sin theta_i) and up",
        value=worst_t,
        tolerance=FORMULA_RTOL,
        justification=f"{n_t} row(s) of the .bsdf's TIS lines",
    )


def _control(ctx: Context, d: Path) -> None:
    b = ctx.b
    bsdf = d / SET_FILES[3]
    control = adapters.read(d / CONTROL_FILE).data
    hms = [h for h in ctx.height_maps if Path(h.path).name == SET_FILES[0]]
    if not hms:
        raise Unavailable(f"{SET_FILES[0]} was not read as a height map")
    fit = roughness_alpha(hms[0])
    p = predict_brdf(bsdf, control, fit, rays=rays_of(ctx), seed=ctx.seed, map=tracer_map(ctx))
    b.text(
        f"The same height map and {bsdf.name}, but n + ik = {p.n:.4g} + {p.k:.4g}i from "
        f"{CONTROL_FILE} (written for 1.5 + 3i, a poorer metal). {p.verdict()}"
    )
    reg = p.regions()
    b.table(
        "model_measurement_control",
        "Wrong-index control: predicted / measured scatter per region",
        [
            ("theta_i_deg", "AOI [deg]", ".4g"),
            ("region", "region", ""),
            ("points", "points", "d"),
            ("ratio", "predicted / measured", ".4f"),
            ("ratio_stderr", "SE", ".2g"),
            ("consistent", "within 3 SE", ""),
        ],
        reg.to_dict("records"),
        caption="The region integrals of labbrdf.prediction.BrdfPrediction.regions, as in "
        "the prediction table above; here they must NOT agree.",
    )
    worst = float(np.nanmax(np.abs(reg["ratio"].to_numpy(float) - 1.0)))
    b.check(
        "model_measurement.control_flagged",
        "the prediction from a wrong index is flagged as disagreeing with the .bsdf",
        not bool(reg["consistent"].all()),
        against=f"{bsdf.name} with n, k from {CONTROL_FILE}",
        value=worst,
        tolerance="some region |ratio - 1| > 3 SE + 1e-5",
        justification="the control's Fresnel reflectance at 45 deg is about a third below "
        "the sample's, far beyond the Monte Carlo error",
    )
