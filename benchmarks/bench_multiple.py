"""What multiple scattering costs: the counting walk and the evaluated estimator.

The paper's case (varnish n = 1.5 over Al 1.55+7.71i, alpha 0.2 both, 60 deg, 650 nm,
1-degree grid), one process:

1. multiple scattering, counting: the RMS relative error of S0 per 1-degree lobe bin
   (S0 > 10 % of its maximum) from two seeds, seconds per run, and the rays and seconds
   it would need for 1 % (the error falls like ``1 / sqrt(rays)``);
1b. multiple scattering, evaluated (the walk's single events in closed form, every later
   vertex through its operator; ``docs/tracer.md``): the same numbers, with the
   operators' build (a cold cache), loaded from the disk cache, and kept in memory;
2. single scattering, evaluated, in the same run (the estimator a converged
   multiple-scattering estimator has to match);
3. what single scattering leaves out: the albedo of both models, and the lobe's RMS
   relative difference;
4. the white furnace (a lossless coating over a white Lambertian base, 45 deg) at coating
   alpha 0.05 / 0.1 / 0.2: multiple scattering (counting) against single (evaluated) and
   multiple (evaluated);
5. (``--fit``) the ``layered`` model over Al with ``scattering="multiple"`` fitted to
   synthetic data from itself at another seed and 10 times the rays (incidences 30 / 60
   deg, 2 % noise,
   ``alpha_top`` 0.15, ``alpha_sub`` 0.3): the estimates against the truth in units of
   their stated errors, seconds and evaluations.

Seconds are CPU seconds of this process (``time.process_time``): on a shared machine the
wall clock mostly measures the other processes. Item 1b also prints the wall clock: the
next operator is built in a worker thread while the current one's products run.

Item 1b measured (``--only-evaluated``, ``OPENBLAS_NUM_THREADS=1``, 2 cores with a test
suite on one, load 1.1): 1 % per lobe bin in 8.2 s wall / 9.8 s CPU with the four
operators built, 5.0 / 6.0 s from the disk cache, 4.5 / 4.5 s in memory (before the
level sums on the spectrum, the direct copies and the build one ahead: 14.5 / 7.8 / 5.4 s
wall, back to back; at load 2.5: 10.3 / 6.0 / 4.6 s wall against 14.5 / 7.6 / 5.7).

Usage: ``python benchmarks/bench_multiple.py [--rays N] [--evaluated-rays M]
[--only-evaluated] [--fit RAYS]`` (default 2e5 rays per counting run, 1.2e5 per evaluated run).
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from bench_tracer import _relerr  # noqa: E402

from labbrdf.tracer import Coating, Substrate, TraceConfig, trace  # noqa: E402
from labbrdf.tracer.operator import memory_cache  # noqa: E402

PAPER = TraceConfig(
    wavelength_nm=650.0,
    theta_i_deg=60.0,
    substrate=Substrate(n=1.55, k=7.71, alpha=0.2),
    coating=Coating(n=1.5, alpha=0.2),
)


def _pair(cfg: TraceConfig) -> tuple:
    """Two seeds of ``cfg``: (run 1, run 2, mean seconds per run)."""
    t0 = time.process_time()
    a = trace(cfg.replace(seed=1))
    t1 = time.process_time()
    b = trace(cfg.replace(seed=2))
    t2 = time.process_time()
    return a, b, (t2 - t0) / 2, (t1 - t0, t2 - t1)


def costs(rays: int) -> tuple:
    """Items 1 and 2."""
    print("1. multiple scattering, counting, the paper's case, 1-degree grid")
    a, b, sec, _ = _pair(PAPER.replace(rays=rays, scattering="multiple", estimator="counting"))
    rc = _relerr(a, b)
    need = rays * (rc / 0.01) ** 2
    print(
        f"   {rays:.1e} rays: relerr per lobe bin {rc:.2%}, {sec:.1f} s/run; "
        f"1 % needs {need:.2e} rays, {sec * need / rays:.0f} s"
    )
    print("2. single scattering, evaluated, same case")
    ev_rays = max(rays // 2, 1000)
    c, d, _, (t_first, t_second) = _pair(
        PAPER.replace(rays=ev_rays, scattering="single", estimator="evaluated")
    )
    re = _relerr(c, d)
    need_e = ev_rays * (re / 0.01) ** 2
    print(
        f"   {ev_rays:.1e} rays: relerr per lobe bin {re:.2%}; runs {t_first:.1f} s "
        f"(operator {c.info.get('operator_seconds', 0):.1f} s) and {t_second:.1f} s "
        f"(operator {d.info.get('operator_seconds', 0):.1f} s); 1 % needs {need_e:.2e} rays, "
        f"{t_second * need_e / ev_rays:.1f} s with the operator at hand"
    )
    ratio = (sec * need / rays) / (t_second * need_e / ev_rays)
    print(f"   seconds to 1 %: multiple (counting) / single (evaluated) = {ratio:.0f}")
    return a, b, c, d


def evaluated_multiple(rays: int, counting: tuple | None) -> None:
    """Item 1b (``counting``: item 1's two runs, for the albedo and the lobe)."""
    os.environ["XDG_CACHE_HOME"] = tempfile.mkdtemp(prefix="bench-cache-")  # a cold cache
    print("1b. multiple scattering, evaluated, same case")
    cfg = PAPER.replace(rays=rays, scattering="multiple", estimator="evaluated")
    t0 = time.process_time()
    w0 = time.perf_counter()
    a = trace(cfg.replace(seed=1))  # builds the four operators (and stores them)
    cold, cold_wall = time.process_time() - t0, time.perf_counter() - w0
    t0 = time.process_time()
    w0 = time.perf_counter()
    b = trace(cfg.replace(seed=2))  # loads them from the disk cache
    disk, disk_wall = time.process_time() - t0, time.perf_counter() - w0
    with memory_cache():
        trace(cfg.replace(rays=1000, seed=3))  # into memory
        t0 = time.process_time()
        w0 = time.perf_counter()
        trace(cfg.replace(seed=4))
        mem, mem_wall = time.process_time() - t0, time.perf_counter() - w0
    re = _relerr(a, b)
    need = rays * (re / 0.01) ** 2
    print(
        f"   {rays:.1e} rays: relerr per lobe bin {re:.2%}; 1 % needs {need:.2e} rays; "
        f"operators {a.info.get('operator_mb', 0):.0f} MB"
    )
    for name, cpu, wall in (
        ("operators built", cold, cold_wall),
        ("operators from disk", disk, disk_wall),
        ("operators in memory", mem, mem_wall),
    ):
        print(
            f"   {name:20s}: {cpu:5.1f} s CPU ({wall:5.1f} s wall) per run, "
            f"1 % in {cpu * need / rays:5.1f} s CPU ({wall * need / rays:5.1f} s wall)"
        )
    print(f"   albedo {a.albedo():.4f} / {b.albedo():.4f} +- {a.albedo_stderr():.4f}")
    if counting is not None:
        # the lobe chosen on the evaluated map: chosen on the noisy counted one, it would
        # pick the counted bins that fluctuated up
        ms = (counting[0].s0() + counting[1].s0()) / 2
        ev = (a.s0() + b.s0()) / 2
        lobe = ev > 0.1 * ev.max()
        w = a.grid.cos_solid_angle_sr[lobe]
        rel = float((ev[lobe] * w).sum() / (ms[lobe] * w).sum() - 1.0)
        print(
            f"   counting albedo {(counting[0].albedo() + counting[1].albedo()) / 2:.4f}; "
            f"the lobe's power, evaluated / counting - 1: {rel:+.2%}"
        )


def fit_conductor(rays: int) -> None:
    """Item 5."""
    from labbrdf import adapters, fit, models
    from labbrdf.bsdf_geometry import scatter_to_angles
    from labbrdf.writers.zemax import write_bsdf

    print("5. layered over Al, multiple scattering, fitted to itself (another seed)")
    al = {"n": 1.55, "k": 7.71, "scattering": "multiple", "grid": "3x6", "rays": rays}
    truth = {"alpha_top": 0.15, "alpha_sub": 0.3}
    # the data from 10 times the rays: its Monte Carlo error is common to every seed
    # replicate of the fit, so it must stay below the replicates' own
    gen = models.get("layered", seed=12345, **{**al, "rays": 10 * rays})
    ti = np.array([30.0, 60.0])
    rad = np.array([0, 5, 10, 15, 20, 30, 40, 50, 60, 70, 80.0])
    az = np.arange(0.0, 181.0, 15.0)
    tr, pr, up = scatter_to_angles(ti[:, None, None], rad[None, None, :], az[None, :, None])
    tib = np.broadcast_to(ti[:, None, None], tr.shape)
    f = gen.evaluate(np.radians(tib[up]), np.radians(tr[up]), np.radians(pr[up]), params=truth)
    vals = np.zeros(tr.shape)
    vals[up] = f * (1 + 0.02 * np.random.default_rng(7).standard_normal(f.size))
    with tempfile.TemporaryDirectory() as tmp:
        path = write_bsdf(
            Path(tmp) / "s.bsdf",
            theta_i_deg=ti,
            radial_deg=rad,
            azimuth_deg=az,
            values=vals[None, None],
            symmetry="PlaneSymmetrical",
            overwrite=True,
        )
        df = adapters.read(path).data
    df = df[df["value"] != 0]
    model = models.get("layered", seed=0, **al)
    t0, w0 = time.process_time(), time.perf_counter()
    res = fit(model, df, weighting="relative")
    cpu, wall = time.process_time() - t0, time.perf_counter() - w0
    print(
        f"   {len(df)} points; {wall:.0f} s wall ({cpu:.0f} s CPU), {res.nfev} evaluations "
        f"(+ the seed replicates), {wall / max(res.nfev, 1):.2f} s per evaluation; "
        f"chi2/nu {res.redchi:.3g}"
    )
    for k, v in truth.items():
        p = res.params[k]
        se = p.stderr or float("nan")
        print(f"   {k}: {p.value:.4f} +- {se:.4f} (truth {v}, z {(p.value - v) / se:+.2f})")


def missing(a, b, c, d) -> None:  # noqa: ANN001
    """Item 3."""
    ms = (a.s0() + b.s0()) / 2
    ss = (c.s0() + d.s0()) / 2
    lobe = ms > 0.1 * ms.max()
    rel = float(np.sqrt(np.mean(((ss - ms)[lobe] / ms[lobe]) ** 2)))
    print("3. what single scattering leaves out (same case)")
    print(
        f"   albedo multiple {(a.albedo() + b.albedo()) / 2:.4f} +- {a.albedo_stderr():.4f}, "
        f"single {(c.albedo() + d.albedo()) / 2:.4f}; lobe RMS relative difference {rel:.1%}"
    )


def furnace(rays: int) -> None:
    """Item 4."""
    print("4. white furnace (lossless coating n 1.5 over a white Lambertian base, 45 deg)")
    for alpha in (0.05, 0.1, 0.2):
        cfg = TraceConfig(
            theta_i_deg=45.0,
            substrate=Substrate.lambertian(1.0),
            coating=Coating(n=1.5, alpha=alpha),
            theta_step_deg=3.0,
            phi_step_deg=6.0,
            tau=0.0,
            max_bounces=1000,
        )
        t0 = time.process_time()
        m = trace(cfg.replace(rays=rays // 4, scattering="multiple", estimator="counting"))
        t1 = time.process_time()
        s = trace(cfg.replace(rays=rays // 20, scattering="single", estimator="evaluated"))
        t2 = time.process_time()
        e = trace(cfg.replace(rays=rays // 20, scattering="multiple", estimator="evaluated"))
        t3 = time.process_time()
        print(
            f"   alpha {alpha:4.2f}: multiple {m.albedo():.4f} +- {m.albedo_stderr():.4f} "
            f"({t1 - t0:.1f} s), single {s.albedo():.4f} +- {s.albedo_stderr():.4f} "
            f"({t2 - t1:.1f} s), multiple evaluated {e.albedo():.4f} +- "
            f"{e.albedo_stderr():.4f} ({t3 - t2:.1f} s)"
        )


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rays", type=int, default=200_000)
    ap.add_argument("--evaluated-rays", type=int, default=120_000)
    ap.add_argument("--only-evaluated", action="store_true")
    ap.add_argument("--fit", type=int, default=0, help="item 5 only, with this many rays")
    args = ap.parse_args(argv)
    if args.fit:
        fit_conductor(args.fit)
        return 0
    if args.only_evaluated:
        evaluated_multiple(args.evaluated_rays, None)
        return 0
    runs = costs(args.rays)
    evaluated_multiple(args.evaluated_rays, runs[:2])
    missing(*runs)
    furnace(args.rays)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
