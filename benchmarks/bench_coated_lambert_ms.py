"""Multiple scattering over a Lambertian base: the white furnace and the counting walk.

The numbers of ``docs/tracer.md`` (multiple scattering over a Lambertian base), with the
model's own walk counts (the tests use fewer):

1. the white furnace (lossless coating n = 1.5 over a white base) at alpha_top 0.05, 0.1,
   0.2, 0.3 and 0, 30, 60, 80 deg, 1 x 2 degree grid: the albedo of the multiple-scattering
   form with its stated standard error, and single scattering's;
2. the form against ``trace(scattering="multiple", estimator="counting")`` on the layered
   model's 3 x 6 grid, every bin pooled into groups of 400 counted rays: z RMS, mean z,
   the pole's and the grazing row's z, the albedo with both errors, and CPU seconds.

Usage: ``python benchmarks/bench_coated_lambert_ms.py [--rays 400000]``.
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

from labbrdf.tracer import Coating, Grid, Substrate, TraceConfig, trace
from labbrdf.tracer.agreement import pool_bins
from labbrdf.tracer.coated_lambert import coated_lambert
from labbrdf.tracer.coated_lambert_ms import coated_lambert_ms, first_surface_ms
from labbrdf.tracer.estimator import first_surface_map

CASES = [  # alpha, albedo, theta_i, coating k, scalar
    (0.3, 0.6, 30.0, 0.0, False),
    (0.3, 1.0, 60.0, 0.0, False),
    (0.2, 0.8, 0.0, 0.0, False),
    (0.3, 0.6, 70.0, 0.002, True),
    (0.05, 0.8, 45.0, 0.0, False),
]


def config(alpha: float, theta_i: float, albedo: float, k: float, **kw) -> TraceConfig:
    return TraceConfig(
        theta_i_deg=theta_i,
        substrate=Substrate.lambertian(albedo),
        coating=Coating(n=1.5, k=k, alpha=alpha, thickness_nm=1000.0),
        scattering="multiple",
        **kw,
    )


def model_map(cfg: TraceConfig, multiple: bool = True) -> tuple[np.ndarray, float]:
    """S0 map of the form on the configuration's grid and its albedo's standard error."""
    coat = cfg.coating
    assert coat is not None
    a = float(cfg.substrate.albedo)
    grid = Grid(cfg.theta_step_deg, cfg.phi_step_deg)
    if not multiple:
        body = coated_lambert(coat.n, coat.alpha, coat.k, coat.thickness_nm, cfg.wavelength_nm)
        return first_surface_map(cfg)[..., 0, 0] + body.bin_map(a, cfg.theta_i_deg, grid), 0.0
    ms = coated_lambert_ms(coat.n, coat.alpha, coat.k, coat.thickness_nm, cfg.wavelength_nm)
    first, se = first_surface_ms(cfg)
    f = first + ms.bin_map(a, cfg.theta_i_deg, grid)
    return f, math.hypot(se, ms.body_stderr(a, cfg.theta_i_deg))


def furnace() -> None:
    print("white furnace (lossless n 1.5 over a white base), 1 x 2 deg grid")
    for alpha in (0.05, 0.1, 0.2, 0.3):
        for t in (0.0, 30.0, 60.0, 80.0):
            cfg = config(alpha, t, 1.0, 0.0, theta_step_deg=1.0, phi_step_deg=2.0)
            om = Grid(1.0, 2.0).cos_solid_angle_sr
            f, se = model_map(cfg)
            single = float((model_map(cfg, False)[0] * om).sum())
            print(
                f"  alpha {alpha:4.2f} {t:4.0f} deg: multiple {float((f * om).sum()):.5f} +- "
                f"{se:.5f}; single {single:.4f}"
            )


def against_counting(rays: int) -> None:
    print(f"against the counting multiple-scattering walk ({rays} rays, 3 x 6 deg)")
    for alpha, albedo, t, k, scalar in CASES:
        cfg = config(alpha, t, albedo, k, rays=rays, seed=11, estimator="counting")
        cfg = cfg.replace(scalar=scalar, theta_step_deg=3.0, phi_step_deg=6.0)
        c0 = time.process_time()
        res = trace(cfg)
        c1 = time.process_time()
        f, f_se = model_map(cfg)
        c2 = time.process_time()
        om = res.grid.cos_solid_angle_sr.ravel()
        g = pool_bins(res.counts, 400)
        ng = int(g.max()) + 1
        omg = np.bincount(g, weights=om, minlength=ng)
        s = np.bincount(g, weights=res.sums[..., 0, 0].ravel(), minlength=ng)
        ss = np.bincount(g, weights=res.sumsq[..., 0, 0].ravel(), minlength=ng)
        n = res.rays
        se = np.sqrt(np.maximum(ss / n - (s / n) ** 2, 0.0) / n) / omg
        z = (np.bincount(g, weights=f.ravel() * om, minlength=ng) / omg - s / (n * omg)) / se
        a = float((f.ravel() * om).sum())
        za = (a - res.albedo()) / math.hypot(f_se, res.albedo_stderr())
        print(
            f"  alpha {alpha} a {albedo} {t:g} deg k {k} {'scalar' if scalar else 'polarized'}:"
            f" {ng} groups, z RMS {np.sqrt(np.mean(z**2)):.3f}, mean {z.mean():+.3f}, pole "
            f"{z[0]:+.2f}, grazing {z[-1]:+.2f}; albedo {a:.5f} +- {f_se:.5f} vs "
            f"{res.albedo():.5f} +- {res.albedo_stderr():.5f} (z {za:+.2f}); CPU counting "
            f"{c1 - c0:.1f} s, form {c2 - c1:.1f} s"
        )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rays", type=int, default=400_000)
    args = ap.parse_args()
    furnace()
    against_counting(args.rays)


if __name__ == "__main__":
    main()
