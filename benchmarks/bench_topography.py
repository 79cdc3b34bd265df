"""Speed of the roughness statistics and of the tracer with a tabulated distribution.

Prints:

1. :func:`labbrdf.roughness.topography.roughness_statistics` of a 1024 x 1024 Gaussian map
   (median of 5 runs), with the default 5 x 5 jackknife tiles and without uncertainties, and
   the peak of NumPy's allocations (tracemalloc) in multiples of the float64 heights;
2. tracer throughput (rays/s, one process, best of 3) for rough Al (alpha 0.2, 45 deg,
   single and multiple scattering) with GGX and with the GGX table
   (``TabulatedNDF.ggx(0.2)``) and with a table measured from a generated surface, in the
   same run, and the ratio table / GGX.

Usage: ``python benchmarks/bench_topography.py [--quick]``
"""

from __future__ import annotations

import statistics
import sys
import time
import tracemalloc

from labbrdf.microfacet import TabulatedNDF
from labbrdf.roughness.synthetic import gaussian_surface
from labbrdf.roughness.topography import roughness_statistics
from labbrdf.tracer import Substrate, TraceConfig, trace


def _median_seconds(func, repeats: int) -> float:
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        func()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def _best_rate(cfg: TraceConfig, repeats: int = 3) -> float:
    best = float("inf")
    for _ in range(repeats):
        t0 = time.perf_counter()
        trace(cfg)
        best = min(best, time.perf_counter() - t0)
    return cfg.rays / best


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    quick = "--quick" in argv
    n = 512 if quick else 1024
    s = gaussian_surface(n, n * 1e-6, 1e-7, 8e-6, rng=0)
    print(f"1. roughness statistics of a {n} x {n} map (median of 5)")
    for blocks in (5, 0):
        t = _median_seconds(lambda b=blocks: roughness_statistics(s.z, 1e-6, blocks=b), 5)
        print(f"   blocks={blocks}: {t:.2f} s")
    for blocks in (0, 2):
        tracemalloc.start()
        roughness_statistics(s.z, 1e-6, blocks=blocks)
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
        print(f"   blocks={blocks}: peak allocations {peak / s.z.nbytes:.1f} x the heights")

    rays = 50_000 if quick else 200_000
    t0 = time.perf_counter()
    ggx_table = TabulatedNDF.ggx(0.2)
    t_build = time.perf_counter() - t0
    t0 = time.perf_counter()
    measured = Substrate.from_surface(gaussian_surface(512, 512e-6, 1e-6, 7e-6, rng=1))
    t_meas = time.perf_counter() - t0
    print(
        f"2. tracer, {rays} rays, one process (table build {t_build:.2f} s GGX 256^2, "
        f"{t_meas:.2f} s measured 64^2)"
    )
    for scat in ("single", "multiple"):
        base = TraceConfig(
            rays=rays, seed=1, theta_i_deg=45.0, scattering=scat, substrate=Substrate(alpha=0.2)
        )
        r0 = _best_rate(base)
        r1 = _best_rate(base.replace(substrate=Substrate(alpha=0.2, ndf=ggx_table)))
        r2 = _best_rate(base.replace(substrate=measured))
        print(
            f"   {scat:8s}: GGX {r0:9.0f} rays/s | GGX table {r1:9.0f} rays/s "
            f"(ratio {r1 / r0:.2f}) | measured table {r2:9.0f} rays/s (ratio {r2 / r0:.2f})"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
