"""Tracer speed and memory (the lead runs this; numbers measured on a busy machine mislead).

Prints:

1. rays/s, one process, for a rough Al conductor (alpha 0.2, 45 deg; single and multiple
   scattering) and for varnish-coated Al at 60 deg (alpha 0.2, multiple scattering);
2. the paper's run (2e5 rays, coated Al, 60 deg) serially and on 2 worker processes
   (``labbrdf.parallel.imap``), aim < 2 s;
3. a 1e7-ray run on 2 workers with the peak resident memory of the driver and the workers
   (``resource.getrusage``), aim < 1 GB;
4. the per-ray Python loop of ``baseline_loop_tracer.py`` on 2000 rays, scaled, and the
   speed-up of the vectorised tracer (aim >= 200x).

5. the estimators on the paper's case (varnish 1.5 over Al, alpha 0.2 both, 60 deg,
   650 nm, single scattering): counting with 2e5 rays against evaluated, efficiency
   ``E = 1 / (relerr^2 x seconds)``, relerr the RMS relative error of S0 over the lobe bins
   (S0 > 10 % of its maximum) estimated from two seeds, seconds per run including start-up
   (the exit operator built once, then read from the cache, both quoted), one process;
   the DOP standard error over the lobe; a full 91 x 360 map with its peak memory.
6. the Lambertian base against the conductor under the same varnish (alpha 0.2, 60 deg,
   multiple scattering, counting): rays/s and facet events per ray, one process.

Usage: ``python benchmarks/bench_tracer.py [--quick] [--estimators] [--base]``
(``--quick`` uses 1e6 rays for item 3; ``--estimators`` runs item 5 only, ``--base``
item 6 only).
"""

from __future__ import annotations

import functools
import resource
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from baseline_loop_tracer import rays_per_second as loop_rays_per_second  # noqa: E402

from labbrdf import parallel  # noqa: E402
from labbrdf.tracer import Coating, Substrate, TraceConfig, trace  # noqa: E402

ROUGH_SINGLE = TraceConfig(
    theta_i_deg=45.0, substrate=Substrate(alpha=0.2), scattering="single", estimator="counting"
)
ROUGH_MULTI = ROUGH_SINGLE.replace(scattering="multiple")
COATED = TraceConfig(theta_i_deg=60.0, substrate=Substrate(alpha=0.2), coating=Coating(alpha=0.2))


def _best_rate(cfg: TraceConfig, rays: int, repeats: int = 3, **kw) -> tuple[float, float]:
    """Best of ``repeats`` runs: (rays/s, seconds)."""
    best = float("inf")
    for _ in range(repeats):
        t0 = time.perf_counter()
        trace(cfg.replace(rays=rays), **kw)
        best = min(best, time.perf_counter() - t0)
    return rays / best, best


def _rss_mb() -> tuple[float, float]:
    own = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    kids = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024
    return own, kids


PAPER = TraceConfig(
    theta_i_deg=60.0,
    wavelength_nm=650.0,
    substrate=Substrate(n=1.55, k=7.71, alpha=0.2),
    coating=Coating(n=1.5, alpha=0.2),
    scattering="single",
)


def _timed(cfg: TraceConfig):
    t0 = time.perf_counter()
    res = trace(cfg)
    return res, time.perf_counter() - t0


def _relerr(a, b) -> float:
    """RMS relative error of one run's S0 over the lobe, from two independent seeds."""
    import numpy as np

    m = (a.s0() + b.s0()) / 2
    lobe = m > 0.1 * m.max()
    return float(np.sqrt(np.mean(((a.s0() - b.s0())[lobe] / m[lobe]) ** 2 / 2)))


def estimators() -> None:
    """Item 5: counting against evaluated on the paper's case."""
    import os
    import tempfile

    import numpy as np

    os.environ["XDG_CACHE_HOME"] = tempfile.mkdtemp(prefix="bench-cache-")  # a cold cache
    print("5. estimators, the paper's case (single scattering), one process")
    a, ta = _timed(PAPER.replace(rays=200_000, seed=1, estimator="counting"))
    b, tb = _timed(PAPER.replace(rays=200_000, seed=2, estimator="counting"))
    rc, tc = _relerr(a, b), (ta + tb) / 2
    ec = 1 / (rc * rc * tc)
    print(f"   counting  2e5 rays: relerr {rc:.2%}, {tc:.1f} s/run, E = {ec:.3g}")
    for rays in (120_000, 50_000):
        # the first run of the first size starts with an empty cache: it builds the operator
        a, ta = _timed(PAPER.replace(rays=rays, seed=1, estimator="evaluated"))
        b, tb = _timed(PAPER.replace(rays=rays, seed=2, estimator="evaluated"))
        re = _relerr(a, b)
        lobe = a.s0() > 0.1 * a.s0().max()
        dse = a.dop_stderr()[lobe]
        e1, e2 = 1 / (re * re * ta), 1 / (re * re * tb)
        print(
            f"   evaluated {rays:.1e} rays: relerr {re:.2%}; runs {ta:.1f} s and {tb:.1f} s "
            f"(operator {a.info.get('operator_seconds', 0):.1f} s and "
            f"{b.info.get('operator_seconds', 0):.1f} s: built or read from the cache); "
            f"E = {e1:.3g} / {e2:.3g} = {e1 / ec:.0f}x / {e2 / ec:.0f}x counting; "
            f"DOP SE over the lobe: max {np.nanmax(dse):.4f}, median {np.nanmedian(dse):.4f}"
        )
    own0, _ = _rss_mb()
    res, t = _timed(PAPER.replace(rays=120_000, seed=3))
    own1, _ = _rss_mb()
    print(
        f"   full 91 x 360 map, 16 elements + errors, 1.2e5 rays (cached operator): {t:.1f} s; "
        f"peak RSS {max(own0, own1):.0f} MB; operator {res.info.get('operator_mb', 0):.0f} MB"
    )


def base() -> None:
    """Item 6: the Lambertian base's cost against the conductor's, same coating."""
    print("6. Lambertian base (albedo 0.8) vs Al under varnish, 60 deg, multiple, counting")
    for name, cfg in (
        ("coated Al", COATED.replace(estimator="counting")),
        ("coated base", COATED.replace(substrate=Substrate.lambertian(0.8))),
        ("bare Al", ROUGH_MULTI),
        ("bare base", ROUGH_MULTI.replace(substrate=Substrate.lambertian(0.8))),
    ):
        rate, t = _best_rate(cfg, 200_000)
        res = trace(cfg.replace(rays=200_000))
        print(
            f"   {name:12s} {rate:12,.0f} rays/s; {res.events / res.rays:5.2f} events/ray; "
            f"albedo {res.albedo():.4f}"
        )


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if "--estimators" in argv:
        estimators()
        return 0
    if "--base" in argv:
        base()
        return 0
    quick = "--quick" in argv
    pmap = functools.partial(parallel.imap, scheduler="processes", workers=2)

    print("1. single-process throughput")
    rates = {}
    for name, cfg in (
        ("rough Al single", ROUGH_SINGLE),
        ("rough Al multiple", ROUGH_MULTI),
        ("coated Al 60 deg", COATED),
    ):
        rate, _ = _best_rate(cfg, 500_000)
        rates[name] = rate
        print(f"   {name:20s} {rate:12,.0f} rays/s")

    print("2. the paper's run: 2e5 rays, coated Al, 60 deg")
    _, t_serial = _best_rate(COATED, 200_000)
    _, t_par = _best_rate(COATED, 200_000, map=pmap, blocks_per_unit=1)
    print(f"   serial {t_serial:.2f} s; 2 workers {t_par:.2f} s (aim < 2 s)")

    rays = 1_000_000 if quick else 10_000_000
    print(f"3. {rays:.0e} rays, coated Al 60 deg, 2 workers")
    t0 = time.perf_counter()
    res = trace(COATED.replace(rays=rays), map=pmap, blocks_per_unit=4)
    dt = time.perf_counter() - t0
    own, kids = _rss_mb()
    print(
        f"   {dt:.1f} s ({rays / dt:,.0f} rays/s), albedo {res.albedo():.5f}; "
        f"peak RSS driver {own:.0f} MB, largest worker {kids:.0f} MB (aim < 1 GB)"
    )

    print("4. per-ray Python loop (2000 rays, scaled)")
    for name, cfg in (("rough Al single", ROUGH_SINGLE), ("coated Al 60 deg", COATED)):
        loop = loop_rays_per_second(cfg, 2000)
        print(
            f"   {name:20s} loop {loop:10,.0f} rays/s; vectorised {rates[name]:12,.0f} rays/s; "
            f"speed-up {rates[name] / loop:6.0f}x (one core each)"
        )
    estimators()
    base()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
