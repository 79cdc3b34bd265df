"""Read speed of the Zemax ``.bsdf`` adapter against ``numpy.loadtxt`` on the same numbers.

Run: ``python benchmarks/bench_bsdf.py [--repeat 5]``

Writes (seeded) an Asymmetrical file of 4 angles of incidence x 361 azimuths x 181 radial
angles (261 364 values) into a temporary directory with ``write_bsdf``, then times, in this
process, the median of ``--repeat`` interleaved runs of

* ``labbrdf.read(path)``: decoding, header, strict parsing of every block, the exact
  geometry conversion, the long table and its validation;
* ``numpy.loadtxt`` on the numeric rows only (the ``TIS`` and header lines removed
  beforehand, outside the timing).

Aim: labbrdf within 2x of loadtxt. Not a timed test: numbers depend on the machine.

Then (``--fit-repeat``, default 3) the fit of a measured-BRDF report: a seeded Asymmetrical
file of a microfacet surface (n = 1.5, k = 0, diffuse; alpha 0.2, kd 0.1, 2 % log-normal
noise) on 3 angles of incidence x 72 azimuths x 161 radial angles (about 30 000 points above
the horizon) is read and fitted with ``labbrdf.fitting.fit`` as the report and the CLI do
for files without sigma (``weighting="relative"``, ``mask_zeros=True``); printed: points,
median seconds, nfev.
"""

from __future__ import annotations

import argparse
import io
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np

import labbrdf
from labbrdf.adapters.zemax_bsdf import read_table
from labbrdf.writers.zemax import write_bsdf


def make_file(folder: Path) -> Path:
    rng = np.random.default_rng(0)
    ti = np.array([0.0, 20.0, 40.0, 60.0])
    az = np.linspace(0.0, 360.0, 361)[:-1]
    az = np.append(az, 359.5)  # 361 distinct azimuths in [0, 360)
    rad = np.linspace(0.0, 90.0, 181)
    values = rng.lognormal(-2.0, 1.0, size=(1, 1, ti.size, az.size, rad.size))
    return write_bsdf(
        folder / "bench.bsdf",
        theta_i_deg=ti,
        radial_deg=rad,
        azimuth_deg=az,
        values=values,
        symmetry="Asymmetrical",
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--fit-repeat", type=int, default=3)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        path = make_file(Path(tmp))
        lines = path.read_text().splitlines()
        body = lines[lines.index("DataBegin") + 1 :]
        numeric = "\n".join(ln for ln in body if ln[:1].isdigit())
        t_read: list[float] = []
        t_np: list[float] = []
        for _ in range(args.repeat):
            t0 = time.perf_counter()
            m = labbrdf.read(path)
            t_read.append(time.perf_counter() - t0)
            t0 = time.perf_counter()
            arr = np.loadtxt(io.StringIO(numeric))
            t_np.append(time.perf_counter() - t0)
        a, b = statistics.median(t_read), statistics.median(t_np)
        print(f"file: {path.stat().st_size / 1e6:.1f} MB, {arr.size} values, {len(m)} rows kept")
        print(f"labbrdf.read   median {a * 1e3:8.1f} ms")
        print(f"numpy.loadtxt  median {b * 1e3:8.1f} ms")
        print(f"ratio read/loadtxt    {a / b:8.2f}")
        bench_fit(Path(tmp), args.fit_repeat)


def make_microfacet_file(folder: Path) -> Path:
    """A noisy Asymmetrical .bsdf of a microfacet surface (about 30 000 points)."""
    from labbrdf import models
    from labbrdf.writers.zemax import model_to_bsdf

    m = models.get("microfacet", n=1.5, k=0.0, diffuse=True)
    clean = model_to_bsdf(
        m,
        {"alpha": 0.2, "scale": 1.0, "kd": 0.1},
        folder / "micro_clean.bsdf",
        theta_i_deg=[20.0, 40.0, 60.0],
        radial_deg=np.linspace(0.0, 85.0, 161),
        azimuth_deg=np.arange(0.0, 360.0, 5.0),
        symmetry="Asymmetrical",
    )
    t = read_table(clean)
    rng = np.random.default_rng(0)
    return write_bsdf(
        folder / "micro.bsdf",
        theta_i_deg=t.theta_i_deg,
        radial_deg=t.radial_deg,
        azimuth_deg=t.azimuth_deg,
        values=t.values * np.exp(0.02 * rng.standard_normal(t.values.shape)),
        symmetry="Asymmetrical",
    )


def bench_fit(folder: Path, repeat: int) -> None:
    """Median time of fitting microfacet to the file of :func:`make_microfacet_file`."""
    from labbrdf.fitting import fit

    data = labbrdf.read(make_microfacet_file(folder)).data
    times: list[float] = []
    res = None
    for _ in range(repeat):
        t0 = time.perf_counter()
        res = fit(
            labbrdf.models.get("microfacet", n=1.5, k=0.0, diffuse=True),
            data,
            weighting="relative",
            mask_zeros=True,
        )
        times.append(time.perf_counter() - t0)
    assert res is not None
    s = res.summary()
    alpha, kd = s["params"]["alpha"]["value"], s["params"]["kd"]["value"]
    print(
        f"fit microfacet: {len(data)} points, median {statistics.median(times):.2f} s "
        f"of {repeat}, nfev {s['nfev']}, alpha {alpha:.4f} (0.2), kd {kd:.4f} (0.1)"
    )


if __name__ == "__main__":
    main()
