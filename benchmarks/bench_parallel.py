"""Scale-out of labbrdf.parallel: speed-up from 1 to 2 workers, per-task overhead, memory.

Run: ``python benchmarks/bench_parallel.py [--rays 10000000] [--repeat 3] [--skip-dask]``

Prints (medians of ``--repeat`` runs, the serial baselines measured in the same process):

1. ``fit_many`` of smooth3 on one synthetic sample, 761 wavelengths (240-1000 nm, the
   fixtures' geometry: theta_i 30/45/60 deg, theta_r within +-2 deg in 0.2-deg steps, the
   fixtures' noise model), serially and on ``processes`` and ``local`` (dask LocalCluster)
   with 1 and 2 workers; speed-up 1 -> 2 workers (aim >= 1.7x on 2 cores);
2. the same for a tracer run of ``--rays`` rays (default 1e7; Al, alpha 0.2, 45 deg,
   multiple scattering);
3. the per-task overhead: 200 trivial tasks on each scheduler (seconds per task), and the
   start-up cost per call: a new process pool per call (what ``parallel.run`` does) against
   a reused pool, a cold LocalCluster against the reused one (``parallel`` keeps it);
4. peak resident memory of this process and of the worker processes.

Every parallel result is checked against the serial one (bit for bit, timing columns
aside) and the line says ``identical``. Not a timed test: numbers depend on the machine
and its load (measure on a quiet machine).
"""

from __future__ import annotations

import argparse
import functools
import resource
import statistics
import time
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor
from typing import Any

import numpy as np
import pandas as pd

from labbrdf import parallel
from labbrdf.fitting import fit_many
from labbrdf.models import get as get_model
from labbrdf.tracer import Substrate, TraceConfig, trace

#: the trace of item 2: rough Al at 45 deg (rays set by --rays)
TRACE = TraceConfig(theta_i_deg=45.0, substrate=Substrate(alpha=0.2), seed=0)


def batch_frame(seed: int = 1) -> pd.DataFrame:
    """One sample, 761 wavelengths 240-1000 nm, smooth3 parameters drifting with wavelength.

    Fixture geometry (fixtures/README.md): theta_i 30/45/60 deg, theta_r = theta_i +- 2 deg
    in 0.2-deg steps; noise sigma = hypot(0.5 % of the value, 1e-4 sr^-1).
    """
    rng = np.random.default_rng(seed)
    model = get_model("smooth3")
    ti = np.repeat([30.0, 45.0, 60.0], 21)
    tr = ti + np.tile(np.round(np.arange(-2.0, 2.0001, 0.2), 10), 3)
    frames = []
    for wl in np.arange(240.0, 1001.0):
        s = (wl - 240.0) / 760.0
        k = {"k1": 0.7 + 0.3 * s, "k2": -0.01 - 0.01 * s, "k3": 0.415 + 0.002 * s}
        y = model.evaluate(np.radians(ti), np.radians(tr), params=k)
        sigma = np.hypot(0.005 * y, 1e-4)
        frames.append(
            pd.DataFrame(
                {
                    "sample": "OSR",
                    "instrument": "synthetic",
                    "source": "bench_parallel",
                    "quantity": "brdf",
                    "value": y + sigma * rng.standard_normal(y.size),
                    "sigma": sigma,
                    "unit": "sr-1",
                    "wavelength_nm": wl,
                    "theta_i_deg": ti,
                    "theta_r_deg": tr,
                    "phi_r_deg": 180.0,
                }
            )
        )
    return pd.concat(frames, ignore_index=True)


def median_time(f: Callable[[], Any], repeat: int) -> tuple[Any, float]:
    """(last result, median wall time [s]) of ``repeat`` calls."""
    times = []
    out = None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = f()
        times.append(time.perf_counter() - t0)
    return out, statistics.median(times)


def peak_rss_mb() -> float:
    """Peak resident memory of the calling process [MB].

    ``VmHWM`` of /proc/self/status where there is one: unlike ``ru_maxrss`` it belongs to
    the process's own memory map, so a spawned worker does not report its parent's peak
    (Linux carries ``ru_maxrss`` across fork and exec).
    """
    try:
        with open("/proc/self/status") as fh:
            for line in fh:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1]) / 1024.0
    except OSError:
        pass
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


_WORKER_PEAK_MB: list[float] = []


def note_dask_workers() -> None:
    """Record the peak RSS of the running LocalCluster's workers (before it is replaced)."""
    client = parallel.cluster._LOCAL.get("client")
    if client is not None:
        _WORKER_PEAK_MB.extend(client.run(peak_rss_mb).values())


def start_local(workers: int) -> float:
    """Start (or reuse) the LocalCluster for ``workers``; seconds taken."""
    note_dask_workers()
    t0 = time.perf_counter()
    parallel.run(abs, [0], scheduler="local", workers=workers)
    return time.perf_counter() - t0


def same_table(a: pd.DataFrame, b: pd.DataFrame) -> bool:
    try:
        pd.testing.assert_frame_equal(
            a.drop(columns="elapsed_s"), b.drop(columns="elapsed_s"), check_exact=True
        )
    except AssertionError:
        return False
    return True


def same_trace(a: Any, b: Any) -> bool:
    return bool(
        np.array_equal(a.sums, b.sums)
        and np.array_equal(a.sumsq, b.sumsq)
        and np.array_equal(a.counts, b.counts)
        and a.ledger == b.ledger
    )


def scaling(
    title: str,
    run: Callable[[str, int | None], Any],
    same: Callable[[Any, Any], bool],
    schedulers: list[str],
    repeat: int,
) -> None:
    """Serial baseline, then each scheduler with 1 and 2 workers; speed-ups."""
    print(f"\n== {title} (median of {repeat}) ==")
    ref, t_serial = median_time(lambda: run("serial", None), repeat)
    print(f"{'scheduler':<10}{'workers':>8}{'median s':>10}{'vs serial':>11}{'1->2':>8}  check")
    print(f"{'serial':<10}{1:>8}{t_serial:10.2f}{1.0:10.2f}x{'':>8}  reference")
    for sched in schedulers:
        t1 = None
        for w in (1, 2):
            if sched == "local":
                start_local(w)  # the cluster start-up is item 3, not part of this time
            out, t = median_time(lambda s=sched, w=w: run(s, w), repeat)
            t1 = t if w == 1 else t1
            up = f"{t1 / t:7.2f}x" if w == 2 else ""
            ok = "identical" if same(ref, out) else "DIFFERENT FROM SERIAL"
            print(f"{sched:<10}{w:>8}{t:10.2f}{t_serial / t:10.2f}x{up:>8}  {ok}")
    print("aim: 1->2 workers >= 1.7x on a quiet 2-core machine")


def bench_fit(schedulers: list[str], repeat: int) -> None:
    df = batch_frame()

    def run(sched: str, workers: int | None) -> pd.DataFrame:
        return fit_many(df, "smooth3", scheduler=sched, workers=workers, progress=False)

    scaling(
        f"fit_many smooth3: 1 sample x 761 wavelengths, {len(df)} rows",
        run,
        same_table,
        schedulers,
        repeat,
    )


def bench_trace(schedulers: list[str], repeat: int, rays: int, blocks_per_unit: int) -> None:
    cfg = TRACE.replace(rays=rays)

    def run(sched: str, workers: int | None) -> Any:
        if sched == "serial":
            return trace(cfg)
        pmap = functools.partial(parallel.imap, scheduler=sched, workers=workers)
        return trace(cfg, map=pmap, blocks_per_unit=blocks_per_unit)

    scaling(
        f"trace: {rays:.3g} rays, Al alpha 0.2, 45 deg, {cfg.n_blocks} blocks, "
        f"{blocks_per_unit} per task",
        run,
        same_trace,
        schedulers,
        repeat,
    )


def bench_overhead(schedulers: list[str], repeat: int, n_tasks: int = 200) -> None:
    print(f"\n== per-task overhead: {n_tasks} trivial tasks, 2 workers (median of {repeat}) ==")
    items = list(range(n_tasks))
    rows = []
    _, t = median_time(lambda: parallel.run(abs, items, scheduler="serial"), repeat)
    rows.append(("serial", t))
    _, t = median_time(lambda: parallel.run(abs, items, scheduler="processes", workers=2), repeat)
    rows.append(("processes (new pool per call)", t))
    with ProcessPoolExecutor(max_workers=2) as ex:
        list(ex.map(abs, items))
        _, t = median_time(lambda: list(ex.map(abs, items)), repeat)
    rows.append(("reused ProcessPoolExecutor.map", t))
    if "local" in schedulers:
        start_local(2)
        _, t = median_time(lambda: parallel.run(abs, items, scheduler="local", workers=2), repeat)
        rows.append(("local (dask, cluster reused)", t))
    for name, t in rows:
        print(f"{name:<32}{t:9.3f} s  {1e3 * t / n_tasks:8.3f} ms per task")

    print(f"\n== start-up per call (median of {repeat}) ==")
    _, t_new = median_time(
        lambda: parallel.run(abs, [0, 1], scheduler="processes", workers=2), repeat
    )
    print(f"{'processes: new pool, 2 tasks':<32}{t_new:9.3f} s")
    if "local" in schedulers:
        note_dask_workers()
        cold = []
        for _ in range(repeat):
            parallel.shutdown()
            t0 = time.perf_counter()
            parallel.run(abs, [0, 1], scheduler="local", workers=2)
            cold.append(time.perf_counter() - t0)
            note_dask_workers()
        _, warm = median_time(lambda: parallel.run(abs, [0, 1], scheduler="local", workers=2), 3)
        print(f"{'local: cold LocalCluster, 2 tasks':<32}{statistics.median(cold):9.3f} s")
        print(f"{'local: reused cluster, 2 tasks':<32}{warm:9.3f} s")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rays", type=int, default=10_000_000, help="rays of the trace run")
    ap.add_argument("--repeat", type=int, default=3, help="runs per timing (median)")
    ap.add_argument("--blocks-per-unit", type=int, default=1, help="tracer blocks per task")
    ap.add_argument("--skip-dask", action="store_true", help="process pool only")
    ap.add_argument("--skip-fit", action="store_true")
    ap.add_argument("--skip-trace", action="store_true")
    args = ap.parse_args()
    schedulers = ["processes"] if args.skip_dask else ["processes", "local"]
    if not args.skip_dask:
        try:
            import dask.distributed  # noqa: F401
        except ImportError:
            print("dask.distributed not installed: process pool only")
            schedulers = ["processes"]
    if not args.skip_fit:
        bench_fit(schedulers, args.repeat)
    if not args.skip_trace:
        bench_trace(schedulers, args.repeat, args.rays, args.blocks_per_unit)
    bench_overhead(schedulers, args.repeat)
    note_dask_workers()
    parallel.shutdown()
    children = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024.0
    print("\n== peak resident memory ==")
    print(f"{'this process':<34}{peak_rss_mb():8.0f} MB")
    if _WORKER_PEAK_MB:
        print(f"{'largest dask worker (VmHWM)':<34}{max(_WORKER_PEAK_MB):8.0f} MB")
    print(
        f"{'largest reaped child (ru_maxrss)':<34}{children:8.0f} MB  (pool workers; an "
        "upper bound: Linux carries the parent's peak into a forked child)"
    )


if __name__ == "__main__":
    main()
