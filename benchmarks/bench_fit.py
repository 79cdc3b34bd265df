"""Speed and quality of labbrdf.fit: time per fit and chi-square reached.

Run: ``python benchmarks/bench_fit.py [--repeat N] [--skip-batch] [--workers 2]
[--seeds 16] [--only-convergence]``

First a convergence table: per model and fixture group (OSR and mirror x 360/500/550/
860 nm, synthetic with the fixtures' noise, ``fixtures/specular/*.csv``), the default fit
over seeds 0-15: success, the spread of the reached chi-square across seeds, evaluations
including the final polish, CPU time per fit. Then, per model, the median over the
fixture groups of the wall time per fit and the chi-square reached by

* ``default``: ``labbrdf.fit(model, data)`` (GN_CRS2_LM+LN_BOBYQA, profiled amplitudes,
  data-driven start, default budgets);
* ``crs3000``: nlopt GN_CRS2_LM with 3000 evaluations, then LN_BOBYQA, every parameter
  searched (no profiling, no guess);
* ``de``: ``scipy.optimize.differential_evolution`` (polish on, seed 0) on the same
  chi-square and bounds;

and the worst ratio chi2(default) / chi2(de) (aim: <= 1, never worse). Then it times
``fit_many`` on one synthetic sample with 761 wavelengths (240-1000 nm) on a process pool.

Aims: <= 10 ms per smooth3 fit, <= 100 ms per five_param fit, 761 wavelengths
in < 5 s on 2 cores. Not a timed test: numbers depend on the machine and its load.
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

import numpy as np
import pandas as pd
from scipy import optimize

from labbrdf.fitting import FitData, Objective, fit, fit_many
from labbrdf.models import MODELS, get

ROOT = Path(__file__).resolve().parents[1]

#: Zou 2013 Tables 1-2 (k1, k2 [rad], k3 [rad]); used when the fixture files are absent
ZOU2013 = {
    "OSR": {
        360: (0.7443, -0.01156, 0.4161),
        500: (0.9740, -0.01506, 0.4177),
        550: (1.0150, -0.01660, 0.4176),
        860: (1.0310, -0.01968, 0.4155),
    },
    "mirror": {
        360: (0.4972, 0.1379, 0.3704),
        500: (0.5580, 0.1659, 0.3693),
        550: (0.5494, 0.1682, 0.3693),
        860: (0.3909, 0.1594, 0.3710),
    },
}


def synthetic(k: tuple[float, float, float], rng: np.random.Generator) -> FitData:
    """Fixture geometry and noise model (fixtures/README.md) from smooth3 parameters."""
    ti = np.repeat([30.0, 45.0, 60.0], 21)
    tr = ti + np.tile(np.round(np.arange(-2.0, 2.0001, 0.2), 10), 3)
    y = get("smooth3").evaluate(
        np.radians(ti), np.radians(tr), params=dict(zip(("k1", "k2", "k3"), k, strict=True))
    )
    sigma = np.hypot(0.005 * y, 1e-4)
    return FitData(ti, tr, y + sigma * rng.standard_normal(y.size), sigma)


def fixture_groups() -> list[tuple[str, FitData]]:
    groups = []
    files = [
        ROOT / "labbrdf" / "data" / "fixtures" / "specular" / f"{s}_specular.csv"
        for s in ("osr", "mirror")
    ]
    if all(f.is_file() for f in files):
        for f in files:
            df = pd.read_csv(f, comment="#")
            for wl, g in df.groupby("wavelength_nm"):
                groups.append(
                    (
                        f"{f.stem.split('_')[0]} {wl:g} nm",
                        FitData(
                            g["theta_i_deg"],
                            g["theta_r_deg"],
                            g["value"],
                            g["sigma"],
                            g["phi_r_deg"],
                        ),
                    )
                )
        return groups
    rng = np.random.default_rng(20130612)
    for s, tab in ZOU2013.items():
        for wl, k in tab.items():
            groups.append((f"{s} {wl} nm (generated)", synthetic(k, rng)))
    return groups


def de_fit(model_name: str, fd: FitData) -> tuple[float, float]:
    """differential_evolution (polish on) on the weighted chi-square; (chi2, seconds).

    Every varying parameter is searched (no profiling), on the same [0, 1] box as nlopt
    (log scale for ``log`` parameters such as k3 and kb), so the comparison is of the
    optimisers, not of the parametrisations.
    """
    model = get(model_name)
    obj = Objective(model, fd, model.params, 1.0 / np.asarray(fd.sigma) ** 2)
    lo, hi = obj.bounds()
    t0 = time.perf_counter()
    with np.errstate(all="ignore"):
        res = optimize.differential_evolution(
            lambda x: obj(x), list(zip(lo, hi, strict=True)), seed=0, polish=True
        )
        _, chi2 = obj.solve(obj.from_vector(res.x))
    return float(chi2), time.perf_counter() - t0


def timed(f, repeat: int) -> tuple[object, float]:
    best = math.inf
    out = None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = f()
        best = min(best, time.perf_counter() - t0)
    return out, best


def bench_model(model_name: str, groups: list[tuple[str, FitData]], repeat: int) -> None:
    print(f"\n== {model_name}: {len(groups)} fixture groups, best of {repeat} per fit ==")
    print(
        f"{'group':<22}{'default ms':>11}{'chi2':>12}{'crs3000 ms':>12}{'chi2':>12}"
        f"{'DE ms':>10}{'chi2':>12}"
    )
    rows = []
    for label, fd in groups:
        r0, t0 = timed(lambda fd=fd: fit(model_name, fd), repeat)
        r1, t1 = timed(
            lambda fd=fd: fit(model_name, fd, maxeval=(3000, None), profile=False, guess=False), 1
        )
        c2, t2 = de_fit(model_name, fd)
        rows.append((t0, r0.chisqr, t1, r1.chisqr, t2, c2, r0.success))
        print(
            f"{label:<22}{t0 * 1e3:11.2f}{r0.chisqr:12.6g}{t1 * 1e3:12.1f}{r1.chisqr:12.6g}"
            f"{t2 * 1e3:10.0f}{c2:12.6g}"
        )
    a = np.array([r[:6] for r in rows], float)
    med = np.median(a, axis=0)
    print(
        f"{'median':<22}{med[0] * 1e3:11.2f}{med[1]:12.6g}{med[2] * 1e3:12.1f}"
        f"{med[3]:12.6g}{med[4] * 1e3:10.0f}{med[5]:12.6g}"
    )
    print(
        "worst chi2(default)/chi2(DE) - 1 = "
        f"{np.max(a[:, 1] / a[:, 5]) - 1:+.1e}; worst chi2(default)/chi2(crs3000) - 1 = "
        f"{np.max(a[:, 1] / a[:, 3]) - 1:+.1e} (|x| < 1e-8: same optimum to the local "
        f"tolerances); all successful: {all(r[6] for r in rows)}"
    )


def bench_batch(workers: int) -> None:
    """fit_many over 761 wavelengths of one sample (parameters drift with wavelength)."""
    rng = np.random.default_rng(1)
    wls = np.arange(240.0, 1001.0)
    frames = []
    for wl in wls:
        s = (wl - 240.0) / 760.0
        k = (0.7 + 0.3 * s, -0.01 - 0.01 * s, 0.415 + 0.002 * s)
        fd = synthetic(k, rng)
        frames.append(
            pd.DataFrame(
                {
                    "sample": "OSR",
                    "instrument": "synthetic",
                    "source": "bench",
                    "quantity": "brdf",
                    "value": fd.value,
                    "sigma": fd.sigma,
                    "unit": "sr-1",
                    "wavelength_nm": wl,
                    "theta_i_deg": fd.theta_i_deg,
                    "theta_r_deg": fd.theta_r_deg,
                    "phi_r_deg": 180.0,
                }
            )
        )
    df = pd.concat(frames, ignore_index=True)
    print(
        f"\n== fit_many: smooth3, {wls.size} wavelengths, {len(df)} rows, processes x {workers} =="
    )
    t0 = time.perf_counter()
    table = fit_many(df, "smooth3", scheduler="processes", workers=workers, progress=False)
    dt = time.perf_counter() - t0
    print(
        f"wall {dt:.2f} s (aim < 5 s on 2 cores), {1e3 * dt / wls.size:.2f} ms per "
        f"wavelength, success {int(table['success'].sum())}/{len(table)}, median fit "
        f"{1e3 * table['elapsed_s'].median():.2f} ms"
    )
    t0 = time.perf_counter()
    fit_many(df, "smooth3", scheduler="serial", progress=False)
    print(f"serial: {time.perf_counter() - t0:.2f} s")


#: models of the convergence table (registry name, options)
CONVERGENCE_MODELS = [
    ("smooth3", {}),
    ("five_param", {}),
    ("five_param", {"shadowing": "mb"}),
    ("microfacet", {"n": 1.5, "k": 0.0, "diffuse": True}),
]


def bench_convergence(groups: list[tuple[str, FitData]], seeds: int) -> None:
    """Per model and group over seeds 0..seeds-1: success, spread of chi2, cost.

    nlopt's random sequence differs between releases and machines (and the BLAS kernel moves
    the last bits of chi-square, hence the path), so the seeds stand in for them: a fit
    that reaches its minimum only for the seed it was tuned on is fragile. ``spread`` is the
    largest relative chi-square difference to the best seed (aim: < 1e-6); ``polish`` the
    median number of evaluations of the final polish; ``cpu ms`` the median CPU time per
    fit (process time: less sensitive to a loaded machine than the wall time).
    """
    print(f"\nDefault fit over seeds 0..{seeds - 1} (per model and group)")
    print(
        f"{'model':<18}{'group':<16}{'success':>9}{'spread':>10}{'nfev med':>10}"
        f"{'nfev max':>10}{'polish':>8}{'cpu ms':>8}"
    )
    n_ok = n_all = 0
    worst = 0.0
    for name, options in CONVERGENCE_MODELS:
        model = get(name, **options)
        label_m = name + "".join(f" {v}" for k, v in options.items() if k == "shadowing")
        all_nfev, all_ms = [], []
        for label, fd in groups:
            nfev, ms, pol, chi2, ok = [], [], [], [], 0
            for seed in range(seeds):
                t0 = time.process_time()
                r = fit(model, fd, seed=seed)
                ms.append(1e3 * (time.process_time() - t0))
                nfev.append(r.nfev)
                pol.append(sum(s["nfev"] for s in r.stages if s["algorithm"].startswith("polish")))
                chi2.append(r.chisqr)
                ok += bool(r.success)
            spread = (max(chi2) - min(chi2)) / min(chi2)
            worst = max(worst, spread)
            n_ok, n_all = n_ok + ok, n_all + seeds
            all_nfev += nfev
            all_ms += ms
            print(
                f"{label_m:<18}{label:<16}{ok:>5}/{seeds:<3}{spread:>10.1e}"
                f"{np.median(nfev):>10.0f}{max(nfev):>10d}{np.median(pol):>8.0f}"
                f"{np.median(ms):>8.1f}"
            )
        print(
            f"{label_m:<18}{'all groups':<16}{'':>9}{'':>10}{np.median(all_nfev):>10.0f}"
            f"{max(all_nfev):>10d}{'':>8}{np.median(all_ms):>8.1f}"
        )
    print(f"all: {n_ok}/{n_all} successful; worst chi2 spread over seeds {worst:.1e}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5, help="timing repeats per fit (best of)")
    ap.add_argument("--workers", type=int, default=2, help="process-pool workers for fit_many")
    ap.add_argument("--skip-batch", action="store_true", help="skip the 761-wavelength batch")
    ap.add_argument("--seeds", type=int, default=16, help="seeds for the convergence table")
    ap.add_argument(
        "--only-convergence", action="store_true", help="print only the convergence table"
    )
    args = ap.parse_args()
    groups = fixture_groups()
    bench_convergence(groups, args.seeds)
    if args.only_convergence:
        return
    bench_model("smooth3", groups, args.repeat)
    if "five_param" in MODELS:
        bench_model("five_param", groups, max(1, args.repeat // 2))
    if not args.skip_batch:
        bench_batch(args.workers)


if __name__ == "__main__":
    main()
