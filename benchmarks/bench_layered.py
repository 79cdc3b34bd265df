"""Cost of fitting the traced layered model, against microfacet + Lambertian on the same data.

Run: ``python benchmarks/bench_layered.py [--repeat 3] [--rays 20000] [--file F.bsdf]
[--incidences 15,45,75] [--replicates R]``

Data: the Radiant IS-SA brown vinyl export of ``../shared/real-exports`` (``--file``),
fitted with the layered model over a diffuse base, or, where it is absent, a synthetic
``.bsdf`` of the layered model itself (Al under varnish, alpha_top 0.15, alpha_sub 0.3,
2 % noise) fitted with the layered model over Al plus a Lambertian floor; the incidences
``--incidences``. Per model, the
median over ``--repeat`` runs of: wall time of the fit, objective evaluations (``nfev``),
traces run (layered with one seed; cache misses), seconds per evaluation, chi2/nu, AIC,
BIC, and with seed replicates each seed's estimate, their spread and the reported error. Then the
parts of one layered evaluation: one trace, the exit operator's build, and an evaluation at
all incidences with a fresh operator.

Aim: 2-3 layered parameters at three incidences in under 10 minutes on 2 cores. Measured
(load average 3.5-8, ``OPENBLAS_NUM_THREADS=1``): the vinyl 137 s (124 evaluations, 378
traces), the synthetic file 194 s (115 evaluations, 351 traces); microfacet + Lambertian
0.1-0.3 s on either. Seed replicates cost R fits: the synthetic file at 45 degrees only
(166 points), 4000 rays, Al + floor (``--file /none --incidences 45 --rays 4000``): one
seed 32 s (112 evaluations, alpha_top 0.267), three seeds (the default) 91 s (331
evaluations): alpha_top 0.267, 0.172, 0.134, s_between 0.069, reported 0.191 +- 0.040
against the truth 0.15 (load average 1.4-1.6). Where the
time goes (cProfile of three evaluations of the vinyl at 15, 45 and 75 deg, diffuse base,
2e4 rays, 3 x 6 grid, load average ~11): 2.6 s per evaluation, of which the three walks
1.4 s (53 %), one exit-operator build per new alpha_top 1.0 s (37 %; the memory cache
keeps two, so every new alpha_top value builds one), the first-surface maps and the
operator's application the rest. A fit of ~124 evaluations is therefore ~2/3 walks and
~1/3 operator builds: reusing operators across alpha_top (interpolating their spectra) and
reusing the walks across the base albedo (the diffuse base multiplies a ray's weight by
the albedo at each base event, so cells kept per number of base events make the map a
polynomial in the albedo) are the two largest savings; neither is done yet. Not a
timed test: numbers depend on the machine and its load (report ``uptime`` with them), and
on OpenBLAS's thread count (``OPENBLAS_NUM_THREADS=1`` is 2.5x faster on a loaded machine).
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

from labbrdf import adapters, fit, models
from labbrdf.bsdf_geometry import scatter_to_angles
from labbrdf.writers.zemax import write_bsdf

ROOT = Path(__file__).resolve().parents[1]
REAL = ROOT.parent / "shared/real-exports/zemax-bsdf/test_13_planesymmetric_brdf_zemax.bsdf"
AL = {"n": 1.55, "k": 7.71}


def synthetic(path: Path, incidences: list[float], rays: int) -> Path:
    """A .bsdf of the layered model (seed 12345, independent of the fit's seed 0)."""
    gen = models.get("layered", seed=12345, rays=rays, **AL)
    ti = np.asarray(incidences, float)
    rad = np.array([0, 5, 10, 15, 20, 30, 40, 50, 60, 70, 80.0])
    az = np.arange(0.0, 181.0, 10.0)
    tr, pr, up = scatter_to_angles(ti[:, None, None], rad[None, None, :], az[None, :, None])
    tib = np.broadcast_to(ti[:, None, None], tr.shape)
    f = gen.evaluate(
        np.radians(tib[up]),
        np.radians(tr[up]),
        np.radians(pr[up]),
        params={"alpha_top": 0.15, "alpha_sub": 0.3},
    )
    vals = np.zeros(tr.shape)
    vals[up] = f * (1 + 0.02 * np.random.default_rng(7).standard_normal(f.size))
    return write_bsdf(
        path,
        theta_i_deg=ti,
        radial_deg=rad,
        azimuth_deg=az,
        values=vals[None, None],
        symmetry="PlaneSymmetrical",
        overwrite=True,
    )


def run(label: str, make: Any, df: Any, repeat: int, replicates: int | None = None) -> dict:
    """Median wall time, nfev and fit statistics of ``repeat`` fits of ``make()``.

    ``replicates``: seed replicates of a stochastic model (None: the model's default);
    their traces run in fresh model instances and are not counted.
    """
    walls, cpus, nfevs, traces = [], [], [], []
    res = None
    for _ in range(repeat):
        model = make()
        t0, c0 = time.perf_counter(), time.process_time()
        R = replicates if model.stochastic else None
        res = fit(model, df, weighting="relative", replicates=R)
        walls.append(time.perf_counter() - t0)
        cpus.append(time.process_time() - c0)
        nfevs.append(res.nfev)
        traces.append(getattr(model, "traces", 0))
    assert res is not None
    wall = statistics.median(walls)
    nfev = statistics.median(nfevs)
    print(
        f"{label:<34} {wall:8.1f} s (CPU {statistics.median(cpus):6.1f} s)  nfev {nfev:5.0f}"
        f"  traces {statistics.median(traces):5.0f}"
        f"  {1e3 * wall / nfev:7.1f} ms/eval  chi2/nu {res.redchi:.4g}  AIC {res.aic:.5g}"
        f"  BIC {res.bic:.5g}  success {res.success}"
    )
    print("    " + ", ".join(f"{k}={p.value:.4g}" for k, p in res.params.items()))
    for k, sb in (res.seed_spread or {}).items():
        vals = ", ".join(f"{r[k]:.4f}" for r in res.replicates or [])
        se = res.params[k].stderr or float("nan")
        print(f"    {k}: seeds {vals}; s_between {sb:.4f}; reported stderr {se:.4f}")
    return {"wall": wall, "nfev": nfev, "result": res}


def parts(df: Any, rays: int) -> None:
    """Median seconds of one trace, one operator build and one three-incidence evaluation."""
    from labbrdf.tracer import Coating, Substrate, TraceConfig, trace
    from labbrdf.tracer.operator import memory_cache

    cfg = TraceConfig(
        rays=rays,
        theta_i_deg=45.0,
        substrate=Substrate(alpha=0.3),
        coating=Coating(alpha=0.2, thickness_nm=1000.0),
        scattering="single",
        estimator="evaluated",
        theta_step_deg=3.0,
        phi_step_deg=6.0,
    )
    one, ops = [], []
    for i in range(3):
        with memory_cache():
            r = trace(cfg.replace(coating=Coating(alpha=0.2 + 1e-3 * i, thickness_nm=1000.0)))
        one.append(r.seconds)
        ops.append(r.info["operator_seconds"])
    print(
        f"one trace (2e4-ray scale: {rays} rays, 3 x 6 deg): {statistics.median(one):.2f} s, "
        f"operator build {statistics.median(ops):.2f} s"
    )
    ti = np.radians(df["theta_i_deg"].to_numpy(float))
    tr = np.radians(df["theta_r_deg"].to_numpy(float))
    pr = np.radians(df["phi_r_deg"].to_numpy(float))
    ev = []
    for i in range(3):
        m = models.get("layered", rays=rays, **AL)
        t0 = time.perf_counter()
        m.evaluate(ti, tr, pr, params={"alpha_top": 0.2 + 1e-3 * i})
        ev.append(time.perf_counter() - t0)
    n_inc = df["theta_i_deg"].nunique()
    print(f"one evaluation at {n_inc} incidences: {statistics.median(ev):.2f} s")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--rays", type=int, default=20_000)
    ap.add_argument("--file", type=Path, default=REAL)
    ap.add_argument("--incidences", default="15,45,75")
    ap.add_argument(
        "--replicates", type=int, default=None, help="seed replicates (default: the model's)"
    )
    args = ap.parse_args()
    inc = [float(x) for x in args.incidences.split(",")]
    with tempfile.TemporaryDirectory() as tmp:
        path = args.file if args.file.exists() else synthetic(Path(tmp) / "s.bsdf", inc, args.rays)
        df = adapters.read(path).data
        df = df[df["theta_i_deg"].isin(inc) & (df["value"] != 0)]
        print(f"{path.name}: {len(df)} points at {inc} deg")
        parts(df, args.rays)
        run(
            "microfacet n=1.5 + kd",
            lambda: models.get("microfacet", n=1.5, k=0.0, diffuse=True),
            df,
            args.repeat,
        )
        if path == args.file:  # the vinyl: a clear layer over a diffuse body
            run(
                f"layered, diffuse base ({args.rays} rays)",
                lambda: models.get("layered", rays=args.rays, base="diffuse"),
                df,
                args.repeat,
                args.replicates,
            )
        else:
            run(
                f"layered over Al + floor ({args.rays} rays)",
                lambda: models.get("layered", rays=args.rays, floor=True, **AL),
                df,
                args.repeat,
                args.replicates,
            )


if __name__ == "__main__":
    main()
