"""Cost of fitting the traced layered model, against microfacet + Lambertian on the same data.

Run: ``python benchmarks/bench_layered.py [--repeat 3] [--rays 20000] [--file F.bsdf]
[--incidences 15,45,75] [--replicates R] [--scattering single|multiple|both] [--check N]
[--workers W] [--no-parts]``

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

Aim: 2-3 layered parameters at three incidences in seconds on 2 cores. Before (traced
diffuse base, three seed replicates, ``OPENBLAS_NUM_THREADS=1``, load average 10-16): the
vinyl 1113 s wall, ~170 s CPU, 354 evaluations over the three seeds, alpha_top 0.3453 +-
0.0092, albedo 0.2443 +- 0.0068, chi2/nu 0.1345; one evaluation 0.48 s of CPU (cProfile:
the walks 53 %, one exit-operator build per new alpha_top 37 %, the first-surface maps the
rest). Now a diffuse base is evaluated in closed form (``labbrdf.tracer.coated_lambert``,
``docs/tracer.md``): one deterministic fit, 12.8-13.7 s CPU (40-100 s wall at load 10-15), 133
evaluations, alpha_top 0.3442, albedo 0.2411, chi2/nu 0.1336. ``--check`` compares the
closed form at the fitted parameters with the counting walk at each incidence (every bin
pooled into groups of 400 counted rays; z RMS ~1 and the albedo within its error when they
agree). The synthetic file's conductor base is still traced. Not a timed test: numbers
depend on the machine and its load (report ``uptime`` with them), and on OpenBLAS's
thread count (``OPENBLAS_NUM_THREADS=1`` is 2.5x faster on a loaded machine).

``--scattering multiple`` fits the vinyl with multiple scattering on the coating's top
(``labbrdf.tracer.coated_lambert_ms``; ``both``: single, then multiple), and ``--check``
then compares with the counting multiple-scattering walk. Measured (load average 7-10,
2 cores; ``--scattering both --check 200000 --no-parts``): single alpha_top 0.3442,
albedo 0.2411, chi2/nu 0.1336, AIC -925.8, 13.2 s CPU; multiple 0.3561, 0.2038, 0.1459,
-885.5, 297 s CPU (``docs/tracer.md``, multiple scattering over a Lambertian base).
That was one seed; the walks of each new alpha_top were nearly all of it. Now
(``labbrdf.tracer.coated_lambert_table``) the walks are tabulated in alpha_top once per
coating and seed and splined, and the fit of ``scattering=multiple`` takes three seed
replicates by default (their spread in its error): each run here first times the tables
(cold, into an empty cache folder, then read back), then the fit cold (a fresh cache
folder: every replicate builds its tables) and cached (the same folder again), with
``--workers`` processes for the replicates (default 2; 1: serial). Wall and CPU seconds
include the worker processes. Numbers: ``docs/tracer.md``.
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

from labbrdf import adapters, fit, models, parallel
from labbrdf.bsdf_geometry import scatter_to_angles
from labbrdf.fitting import fit_replicates
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


def _cpu() -> float:
    """CPU seconds of this process and its finished children [s]."""
    me, kids = (resource.getrusage(w) for w in (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN))
    return me.ru_utime + me.ru_stime + kids.ru_utime + kids.ru_stime


def _fit(model: Any, df: Any, replicates: int | None, workers: int) -> Any:
    """One fit; seed replicates of a stochastic model on ``workers`` processes."""
    R = replicates if model.stochastic else None
    R = model.default_replicates if R is None and model.stochastic else R
    if R is not None and R > 1 and workers > 1:
        ex = parallel.Executor("processes", workers=workers)
        return fit_replicates(model, df, R, executor=ex, weighting="relative")
    return fit(model, df, weighting="relative", replicates=R)


def run(
    label: str, make: Any, df: Any, repeat: int, replicates: int | None = None, workers: int = 1
) -> dict:
    """Median wall time, nfev and fit statistics of ``repeat`` fits of ``make()``.

    ``replicates``: seed replicates of a stochastic model (None: the model's default);
    their traces run in fresh model instances and are not counted; on ``workers``
    processes.
    """
    walls, cpus, nfevs, traces = [], [], [], []
    res = None
    for _ in range(repeat):
        model = make()
        t0, c0 = time.perf_counter(), _cpu()
        res = _fit(model, df, replicates, workers)
        walls.append(time.perf_counter() - t0)
        cpus.append(_cpu() - c0)
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


def tables(incidences: list[float], grid: tuple[float, float]) -> None:
    """Seconds to build the multiple-scattering tables of one seed, cold and from disk."""
    from labbrdf.tracer import coated_lambert_table as tb

    tb.clear_memory()
    c0 = time.process_time()
    tb.ms_table(1.5, 0.0, 1000.0, 550.0)
    c1 = time.process_time()
    for t in incidences:
        tb.higher_orders_table(1.5, t, grid)
    c2 = time.process_time()
    tb.clear_memory()
    tb.ms_table(1.5, 0.0, 1000.0, 550.0)
    for t in incidences:
        tb.higher_orders_table(1.5, t, grid)
    c3 = time.process_time()
    tb.clear_memory()
    print(
        f"tables of one seed ({tb.alpha_nodes().size} alpha nodes, walks {tb.NODE_RAYS}): "
        f"T and R {c1 - c0:.1f} s CPU, higher orders at {len(incidences)} incidences "
        f"{c2 - c1:.1f} s; from the disk cache {c3 - c2:.3f} s"
    )


def multiple(df: Any, args: Any, inc: list[float]) -> dict:
    """The multiple-scattering fit: tables, then the fit cold and cached (fresh folder)."""
    from labbrdf.tracer import coated_lambert_table as tb

    old = os.environ.get("XDG_CACHE_HOME")
    with tempfile.TemporaryDirectory() as tmp:
        os.environ["XDG_CACHE_HOME"] = tmp
        try:
            probe = models.get("layered", base="diffuse", scattering="multiple")
            probe._set_grid(df["theta_i_deg"].to_numpy(float))  # the fit's grid
            assert probe.grid_deg is not None
            tables(inc, probe.grid_deg)
            out: dict = {}
            for state in ("cold", "cached"):
                if state == "cold":
                    for f in Path(tmp).rglob("exit-*.op"):
                        f.unlink()
                tb.clear_memory()
                out = run(
                    f"layered, diffuse base, multiple ({state})",
                    lambda: models.get("layered", base="diffuse", scattering="multiple"),
                    df,
                    args.repeat,
                    args.replicates,
                    args.workers,
                )
        finally:
            if old is None:
                os.environ.pop("XDG_CACHE_HOME", None)
            else:
                os.environ["XDG_CACHE_HOME"] = old
    return out


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


def check(res: Any, incidences: list[float], rays: int, scattering: str = "single") -> None:
    """The closed-form diffuse base at the fitted parameters against the counting walk.

    Multiple scattering: the tabulated form the fit used (seed 0's tables).
    """
    from labbrdf.tracer import Coating, Grid, Substrate, TraceConfig, trace
    from labbrdf.tracer.agreement import pool_bins
    from labbrdf.tracer.coated_lambert import coated_lambert, first_surface_s0
    from labbrdf.tracer.coated_lambert_table import tabulated_first_surface, tabulated_ms
    from labbrdf.tracer.estimator import first_surface_map

    a, alb = res.params["alpha_top"].value, res.params["albedo"].value
    for t in incidences:
        cfg = TraceConfig(
            rays=rays,
            theta_i_deg=t,
            substrate=Substrate.lambertian(alb),
            coating=Coating(n=1.5, alpha=a, thickness_nm=1000.0),
            scattering=scattering,
            estimator="counting",
            scalar=True,
            theta_step_deg=3.0,
            phi_step_deg=6.0,
            seed=99,
        )
        ct = trace(cfg)
        if scattering == "multiple":
            grid = (cfg.theta_step_deg, cfg.phi_step_deg)
            single = first_surface_s0(1.5, a, t, Grid(*grid))
            f = tabulated_first_surface(single, 1.5, a, t, Grid(*grid))
            body = tabulated_ms(1.5, a, 0.0, 1000.0, cfg.wavelength_nm)
        else:
            f = first_surface_map(cfg)[..., 0, 0]
            body = coated_lambert(1.5, a, 0.0, 1000.0, cfg.wavelength_nm)
        f = f + body.bin_map(alb, t, ct.grid)
        om = ct.grid.cos_solid_angle_sr.ravel()
        g = pool_bins(ct.counts, 400)
        ng = int(g.max()) + 1
        omg = np.bincount(g, weights=om, minlength=ng)
        s = np.bincount(g, weights=ct.sums[..., 0, 0].ravel(), minlength=ng)
        ss = np.bincount(g, weights=ct.sumsq[..., 0, 0].ravel(), minlength=ng)
        se = np.sqrt(np.maximum(ss / rays - (s / rays) ** 2, 0.0) / rays) / omg
        z = (np.bincount(g, weights=f.ravel() * om, minlength=ng) / omg - s / (rays * omg)) / se
        alb_c = float((f.ravel() * om).sum())
        print(
            f"  {t:g} deg: {scattering}: model vs counting ({rays} rays), {ng} groups: z RMS "
            f"{np.sqrt(np.mean(z**2)):.2f}, max |z| {np.abs(z).max():.1f}; albedo "
            f"{alb_c:.5f} vs {ct.albedo():.5f} +- {ct.albedo_stderr():.5f}"
        )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--rays", type=int, default=20_000)
    ap.add_argument("--file", type=Path, default=REAL)
    ap.add_argument("--incidences", default="15,45,75")
    ap.add_argument(
        "--replicates", type=int, default=None, help="seed replicates (default: the model's)"
    )
    ap.add_argument("--check", type=int, default=0, help="rays of the counting check (0: none)")
    ap.add_argument("--scattering", choices=("single", "multiple", "both"), default="single")
    ap.add_argument("--no-parts", action="store_true", help="skip the traced conductor parts")
    ap.add_argument("--workers", type=int, default=2, help="processes for seed replicates")
    args = ap.parse_args()
    inc = [float(x) for x in args.incidences.split(",")]
    with tempfile.TemporaryDirectory() as tmp:
        path = args.file if args.file.exists() else synthetic(Path(tmp) / "s.bsdf", inc, args.rays)
        df = adapters.read(path).data
        df = df[df["theta_i_deg"].isin(inc) & (df["value"] != 0)]
        print(f"{path.name}: {len(df)} points at {inc} deg")
        if not args.no_parts:
            parts(df, args.rays)
        run(
            "microfacet n=1.5 + kd",
            lambda: models.get("microfacet", n=1.5, k=0.0, diffuse=True),
            df,
            args.repeat,
        )
        if path == args.file:  # the vinyl: a clear layer over a diffuse body
            kinds = ("single", "multiple") if args.scattering == "both" else (args.scattering,)
            for sc in kinds:
                if sc == "multiple":
                    out = multiple(df, args, inc)
                else:
                    out = run(
                        "layered, diffuse base, single",
                        lambda: models.get("layered", base="diffuse"),
                        df,
                        args.repeat,
                        args.replicates,
                    )
                if args.check:
                    check(out["result"], inc, args.check, sc)
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
