"""Speed baseline: the tracer's algorithm as a plain per-ray Python loop.

Same physics as :mod:`labbrdf.tracer.walk` (visible-normal GGX sampling, Heitz 2016 height
walk or single scattering with separable Smith masking, LB Fresnel Mueller matrices as
row updates, frame rotations, Beer-Lambert, threshold termination, the same bins), but one
ray at a time with Python floats and ``cmath``: what a straightforward implementation
costs. It is a benchmark, not library code; :func:`main` checks that its albedo agrees with
the vectorised tracer within the Monte Carlo error, so both do the same thing.

Run: ``python benchmarks/baseline_loop_tracer.py [rays]``.
"""

from __future__ import annotations

import cmath
import math
import random
import sys
import time

from labbrdf.tracer import Coating, Substrate, TraceConfig, trace


def _fresnel(n1: complex, n2: complex, ci: float):
    """LB amplitudes (optics module docstring), scalar."""
    kz1 = n1 * ci
    kz2 = cmath.sqrt(n2 * n2 - n1 * n1 + kz1 * kz1)
    if kz2.real + kz2.imag < 0:
        kz2 = -kz2
    ds, dp = kz1 + kz2, n2 * n2 * kz1 + n1 * n1 * kz2
    rs, rp = (kz1 - kz2) / ds, (n2 * n2 * kz1 - n1 * n1 * kz2) / dp
    ts, tp = 2 * kz1 / ds, 2 * n1 * n2 * kz1 / dp
    return rs, rp, ts, tp, kz2 / n2


def _abcs(a: complex, b: complex, f: float = 1.0):
    x = a * b.conjugate()
    aa, bb = abs(a) ** 2, abs(b) ** 2
    return 0.5 * f * (aa + bb), 0.5 * f * (aa - bb), f * x.real, f * x.imag


def _g1_lambda(wz: float, alpha: float) -> float:
    z2 = max(wz * wz, 1e-300)
    lam = 0.5 * (-1 + math.sqrt(1 + alpha * alpha * max(1 - z2, 0) / z2))
    return lam if wz >= 0 else -1 - lam


def _vndf(wx, wy, wz, alpha, u1, u2):
    vx, vy, vz = alpha * wx, alpha * wy, wz
    n = math.sqrt(vx * vx + vy * vy + vz * vz)
    vx, vy, vz = vx / n, vy / n, vz / n
    phi = 2 * math.pi * u1
    z = (1 - u2) * (1 + vz) - vz
    st = math.sqrt(min(max(1 - z * z, 0.0), 1.0))
    hx, hy, hz = alpha * (st * math.cos(phi) + vx), alpha * (st * math.sin(phi) + vy), z + vz
    hz = max(hz, 1e-300)
    n = math.sqrt(hx * hx + hy * hy + hz * hz)
    return hx / n, hy / n, hz / n


def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _rotate(M, k, s_old, s_new):
    p = _cross(k, s_old)
    ca, sa = _dot(s_old, s_new), _dot(p, s_new)
    c2, s2 = ca * ca - sa * sa, 2 * ca * sa
    r1, r2 = M[1], M[2]
    M[1] = [c2 * x + s2 * y for x, y in zip(r1, r2, strict=True)]
    M[2] = [c2 * y - s2 * x for x, y in zip(r1, r2, strict=True)]


def _fres(M, a, b, c, s):
    r0, r1, r2, r3 = M
    M[0] = [a * x + b * y for x, y in zip(r0, r1, strict=True)]
    M[1] = [b * x + a * y for x, y in zip(r0, r1, strict=True)]
    M[2] = [c * x + s * y for x, y in zip(r2, r3, strict=True)]
    M[3] = [c * y - s * x for x, y in zip(r2, r3, strict=True)]


def trace_loop(cfg: TraceConfig, seed: int = 0) -> dict:
    """Trace ``cfg.rays`` rays one by one; returns albedo, ledger and the bin sums."""
    rnd = random.Random(seed)
    sub, coat = cfg.substrate, cfg.coating
    layered = coat is not None
    nc = coat.n if layered else 1.0
    a_top = coat.alpha if layered else 0.0
    nsub = complex(sub.n, sub.k)
    n_th = int(round(90 / cfg.theta_step_deg)) + 1
    n_ph = int(round(360 / cfg.phi_step_deg))
    bins = [[0.0] * 16 for _ in range(n_th * n_ph)]
    exited = absorbed = terminated = 0.0
    th = math.radians(cfg.theta_i_deg)
    for _ in range(cfg.rays):
        k = (-math.sin(th), 0.0, -math.cos(th))
        s = (0.0, 1.0, 0.0)
        M = [[1.0 if i == j else 0.0 for j in range(4)] for i in range(4)]
        top, below, h, fresh, bounces = layered, False, math.inf, True, 0
        while True:
            alpha = a_top if top else sub.alpha
            kz = -k[2] if below else k[2]
            if cfg.scattering == "single":
                leave = not fresh
                if leave:
                    if kz <= 0:
                        terminated += M[0][0]
                        break
                    g = 1 / (1 + _g1_lambda(kz, alpha))
                    terminated += M[0][0] * (1 - g)
                    M = [[g * x for x in row] for row in M]
            else:
                lam = _g1_lambda(kz, alpha)
                c1 = min(max((h + 1) / 2, 0.0), 1.0)
                u = rnd.random()
                g1 = c1**lam if kz > 0 else 0.0
                leave = kz > 0 and u >= 1 - g1
                if not leave:
                    ratio = (1 - u) ** (1 / lam) if lam != 0 else 1.0
                    h = min(max(2 * (c1 / ratio) - 1, -1.0), 1.0)
            if leave:
                if (top and not below) or (not top and not layered):
                    exited += M[0][0]
                    theta = math.degrees(math.acos(min(k[2], 1.0)))
                    phi = math.atan2(k[1], k[0]) if (k[0] or k[1]) else math.pi
                    _rotate(M, k, s, (-math.sin(phi), math.cos(phi), 0.0))
                    i = min(int(theta / cfg.theta_step_deg + 0.5), n_th - 1)
                    j = int((math.degrees(phi) % 360) / cfg.phi_step_deg + 0.5) % n_ph
                    b = bins[i * n_ph + j]
                    for e in range(16):
                        b[e] += M[e // 4][e % 4]
                    break
                if layered and coat.k > 0 and coat.thickness_nm > 0:
                    att = math.exp(
                        -4 * math.pi * coat.k * coat.thickness_nm / (cfg.wavelength_nm * abs(k[2]))
                    )
                    absorbed += M[0][0] * (1 - att)
                    M = [[att * x for x in row] for row in M]
                # down out of the top interface -> substrate; up out of it -> top, from below
                top, below, h, fresh = not top, top is False, math.inf, True
                continue
            if bounces >= cfg.max_bounces:
                terminated += M[0][0]
                break
            u1, u2, u3 = rnd.random(), rnd.random(), rnd.random()
            w = (-k[0], -k[1], k[2] if below else -k[2])
            m = _vndf(*w, alpha, u1, u2)
            if below:
                m = (m[0], m[1], -m[2])
            ci = min(max(-_dot(k, m), 0.0), 1.0)
            c = _cross(k, m)
            nrm = math.sqrt(_dot(c, c))
            s_loc = tuple(x / nrm for x in c) if nrm > 1e-12 else s
            _rotate(M, k, s, s_loc)
            m00 = M[0][0]
            kr = tuple(k[i] + 2 * ci * m[i] for i in range(3))
            if not top:
                rs, rp, *_ = _fresnel(nc if layered else 1.0, nsub, ci)
                _fres(M, *((1.0, 0.0, -1.0, 0.0) if sub.mirror else _abcs(rs, rp)))
                knew, trans = kr, False
            else:
                n1, n2 = (nc, 1.0) if below else (1.0, nc)
                rs, rp, ts, tp, ct = _fresnel(n1, n2, ci)
                ref = _abcs(rs, rp)
                f = (n2 * ct).real / (n1 * ci) if ci > 0 else 0.0
                tra = _abcs(ts, tp, f)
                pr = (ref[0] * M[0][0] + ref[1] * M[1][0]) / M[0][0] if M[0][0] > 0 else ref[0]
                pr = min(max(pr, 0.0), 1.0)
                trans = u3 >= pr
                if trans:
                    _fres(M, *(x / (1 - pr) for x in tra))
                    eta, ctr = n1 / n2, ct.real
                    knew = tuple(eta * k[i] + (eta * ci - ctr) * m[i] for i in range(3))
                else:
                    _fres(M, *(x / pr for x in ref))
                    knew = kr
            n = math.sqrt(_dot(knew, knew))
            k, s = tuple(x / n for x in knew), s_loc
            absorbed += m00 - M[0][0]
            bounces += 1
            fresh = False
            if trans:
                below, h = not below, -h
            if M[0][0] < cfg.tau:
                terminated += M[0][0]
                break
    n = cfg.rays
    return {
        "albedo": exited / n,
        "exited": exited / n,
        "absorbed": absorbed / n,
        "terminated": terminated / n,
        "bins": bins,
    }


CASES = {
    "rough Al 45 deg, single": TraceConfig(theta_i_deg=45.0, scattering="single"),
    "coated Al 60 deg, multiple": TraceConfig(
        theta_i_deg=60.0, coating=Coating(alpha=0.2), substrate=Substrate(alpha=0.2)
    ),
}


def rays_per_second(cfg: TraceConfig, rays: int = 2000) -> float:
    """Throughput of the loop on ``rays`` rays [rays/s]."""
    t0 = time.perf_counter()
    trace_loop(cfg.replace(rays=rays))
    return rays / (time.perf_counter() - t0)


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    rays = int(argv[0]) if argv else 2000
    for name, cfg in CASES.items():
        t0 = time.perf_counter()
        loop = trace_loop(cfg.replace(rays=rays), seed=1)
        dt = time.perf_counter() - t0
        vec = trace(cfg.replace(rays=100_000, block_rays=5000))
        se = (vec.albedo_stderr() ** 2 + 1.0 / rays) ** 0.5  # loop error <~ 1/sqrt(rays)
        agree = abs(loop["albedo"] - vec.albedo()) < 4 * se
        print(
            f"{name}: loop {rays / dt:,.0f} rays/s; albedo loop {loop['albedo']:.4f} vs "
            f"vectorised {vec.albedo():.4f} (agree within 4 sigma: {agree})"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
