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

Usage: ``python benchmarks/bench_tracer.py [--quick]`` (``--quick`` uses 1e6 rays for item 3).
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

ROUGH_SINGLE = TraceConfig(theta_i_deg=45.0, substrate=Substrate(alpha=0.2), scattering="single")
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


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
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
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
