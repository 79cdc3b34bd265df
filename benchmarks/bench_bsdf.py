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
from labbrdf.adapters.zemax_bsdf import write_bsdf


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


if __name__ == "__main__":
    main()
