"""The brown vinyl fitted with and without a scattering coating (``layered``, ``medium=True``).

Run: ``python benchmarks/bench_layered_medium.py [--rays 10000] [--replicates 1]
[--incidences 15,45,75] [--file F.bsdf] [--max-theta-r 90] [--check N]``

Data: the Radiant IS-SA brown vinyl export of ``../shared/real-exports`` (three
incidences, relative weights, as ``bench_layered.py``). Models: the layered model over a
diffuse base with a clear coating (the renewal closed form: ``alpha_top``, ``albedo``
searched) and with a Henyey-Greenstein medium in the coating (``alpha_top``, ``albedo``,
``medium_tau``, ``medium_ssa``, ``medium_g`` searched; traced with the evaluated
estimator, ``--rays`` rays per trace, ``--replicates`` seeds). Per model: chi2/nu, AIC,
the fitted parameters with their errors, the median relative residual ``(model - data) /
data`` at 75 deg incidence over all its points and over the forward lobe (azimuth within
30 deg of the specular plane's forward side, theta_r >= 45 deg), evaluations, CPU seconds.
``--check N``: the fitted medium's evaluated map against the counting walk (N rays, every
bin) at each incidence.

Not a timed test: the traced fit takes minutes (about 1 s of CPU per evaluation at 2e4
rays and three incidences); numbers depend on the machine and its load (report ``uptime``
with them). Set ``OPENBLAS_NUM_THREADS=1`` on a loaded machine.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path
from typing import Any

import numpy as np

from labbrdf import adapters, fit, models

ROOT = Path(__file__).resolve().parents[1]
REAL = ROOT.parent / "shared/real-exports/zemax-bsdf/test_13_planesymmetric_brdf_zemax.bsdf"


def residuals(model: Any, res: Any, df: Any) -> tuple[float, float, int]:
    """Median (model - data) / data at 75 deg: all points, the forward lobe, its size."""
    d = df[np.isclose(df["theta_i_deg"], 75.0)]
    ti, tr, pr = (
        np.radians(d[c].to_numpy(float)) for c in ("theta_i_deg", "theta_r_deg", "phi_r_deg")
    )
    f = model.evaluate(ti, tr, pr, params={k: p.value for k, p in res.params.items()})
    rel = f / d["value"].to_numpy(float) - 1.0
    dphi = np.abs(np.mod(d["phi_r_deg"].to_numpy(float), 360.0) - 180.0)
    lobe = (dphi <= 30.0) & (d["theta_r_deg"].to_numpy(float) >= 45.0)
    return float(np.median(rel)), float(np.median(rel[lobe])), int(lobe.sum())


def check(values: dict[str, float], incidences: list[float], rays: int) -> None:
    """The model's evaluated trace at ``values`` against the counting walk, every bin.

    Each incidence: the layered model's configuration (diffuse base, the medium of
    ``values``, 3 x 6 degree bins, scalar M00) traced ``rays`` rays with either estimator
    (seeds 0 and 99); M00 over every bin pooled into groups of 400 counted rays.
    """
    from labbrdf.tracer import Coating, Medium, Substrate, TraceConfig, trace
    from labbrdf.tracer.agreement import agreement

    med = Medium(values["medium_tau"], values["medium_ssa"], values["medium_g"])
    for t in incidences:
        cfg = TraceConfig(
            rays=rays,
            theta_i_deg=t,
            wavelength_nm=555.0,
            substrate=Substrate.lambertian(values["albedo"]),
            coating=Coating(n=1.5, alpha=values["alpha_top"], thickness_nm=1000.0, medium=med),
            scattering="single",
            theta_step_deg=3.0,
            phi_step_deg=6.0,
        )
        ev = trace(cfg.replace(estimator="evaluated"))
        co = trace(cfg.replace(estimator="counting", seed=99))
        ag = agreement(ev, co, elements="m00")
        print(f"  {t:g} deg: evaluated vs counting ({rays} rays): {ag}")


def run(label: str, model: Any, df: Any, replicates: int | None) -> dict[str, float]:
    """Fit, time and print one model."""
    t0, c0 = time.perf_counter(), time.process_time()
    res = fit(model, df, weighting="relative", replicates=replicates if model.stochastic else None)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    all75, lobe75, n_lobe = residuals(model, res, df)
    print(
        f"{label}: chi2/nu {res.redchi:.4g}  AIC {res.aic:.5g}  BIC {res.bic:.5g}  nfev "
        f"{res.nfev}  CPU {cpu:.1f} s (wall {wall:.1f} s)  success {res.success}"
    )
    for k, p in res.params.items():
        if p.vary:
            se = p.stderr if p.stderr is not None else float("nan")
            print(f"    {k} = {p.value:.4g} +- {se:.2g}")
    print(
        f"    median (model - data) / data at 75 deg: all {100 * all75:+.1f} %, forward lobe "
        f"({n_lobe} points) {100 * lobe75:+.1f} %"
    )
    for k, sb in (res.seed_spread or {}).items():
        seeds = ", ".join(f"{r[k]:.4g}" for r in res.replicates or [])
        print(f"    {k}: seeds {seeds}; seed spread {sb:.4g}")
    return {k: p.value for k, p in res.params.items()}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rays", type=int, default=10_000)
    ap.add_argument("--replicates", type=int, default=1)
    ap.add_argument("--file", type=Path, default=REAL)
    ap.add_argument("--incidences", default="15,45,75")
    ap.add_argument("--max-theta-r", type=float, default=90.0, help="drop points beyond [deg]")
    ap.add_argument("--check", type=int, default=0, help="rays of the counting check (0: none)")
    args = ap.parse_args()
    if not args.file.exists():
        raise SystemExit(f"{args.file}: not found (the shared real exports)")
    inc = [float(x) for x in args.incidences.split(",")]
    df = adapters.read(args.file).data
    df = df[df["theta_i_deg"].isin(inc) & (df["value"] != 0)]
    df = df[df["theta_r_deg"] <= args.max_theta_r]
    print(f"{args.file.name}: {len(df)} points at {inc} deg, {args.rays} rays per trace")
    run("layered, diffuse base, clear coating", models.get("layered", base="diffuse"), df, None)
    values = run(
        f"layered, diffuse base, HG medium ({args.replicates} seed(s))",
        models.get("layered", base="diffuse", medium=True, rays=args.rays),
        df,
        args.replicates,
    )
    if args.check:
        check(values, inc, args.check)


if __name__ == "__main__":
    main()
