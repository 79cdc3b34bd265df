"""Ingest speed: ``labbrdf.read`` on a large WVASE Psi/Delta file against ``pandas.read_csv``.

Run: ``python benchmarks/bench_ingest.py [--mb 50] [--repeat 5] [--keep DIR]``

Writes a synthetic WVASE32 ASCII file of about ``--mb`` MB (the 4-line header of
``w2_10102006.dat``, then untagged ``x AOI Psi Delta sPsi sDelta`` rows, CRLF, 676
wavelengths x as many angles as needed; seeded) into a temporary directory, then times, in
this process, the median of ``--repeat`` runs of

* ``labbrdf.read(path)``: dispatch, decoding, parsing, unit conversion, the long table
  (2 rows per line) and its validation;
* ``pandas.read_csv(path, sep="\\t", header=None, skiprows=4)``: the bare numeric block;
* ``labbrdf.adapters._numblock.parse_block`` alone (the parser inside the reader, on the
  file's bytes in place as the reader calls it);
* ``labbrdf.dataset.validate`` alone (on the long table as the reader builds it, string
  columns categorical);

and prints lines/s, MB/s and the ratio labbrdf/pandas. The runs are interleaved (one of each
per round), so a change of machine load hits all of them alike. Aim: labbrdf at
least half pandas' speed (ratio >= 0.5). Not a timed test: numbers depend on the machine and
its load (and on the state of the allocator: pandas alone varies by up to 2x between runs).
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pandas as pd

import labbrdf
from labbrdf.adapters._frame import build_frame
from labbrdf.adapters._numblock import head_lines, parse_block
from labbrdf.dataset import validate

HEADER = (
    "10102006 Ta Metal 02\r\n"
    "VASEmethod[EllipsometerType=4, Isotropic, FixedPol=45.00, ZoneAve=1, Revs=40, "
    "WVASE=3.616, HardVer=17.034, Tue Oct 10 10:24:56 2006]\r\n"
    "Original[bench.dat]\r\n"
    "nm\r\n"
)


def write_file(path: Path, megabytes: float, seed: int = 0) -> int:
    """Write the synthetic file; return its number of data lines."""
    rng = np.random.default_rng(seed)
    line_bytes = 62  # about, with 6 fields written as below
    n = int(megabytes * 1e6 / line_bytes)
    wl = np.linspace(245.73252, 1697.766406, 676)
    x = np.resize(wl, n)
    aoi = 45.0 + 0.5 * (np.arange(n) // 676 % 60) - 3.66e-4
    cols = [
        x,
        aoi,
        rng.uniform(10, 40, n),
        rng.uniform(-180, 180, n),
        rng.uniform(0.005, 0.1, n),
        rng.uniform(0.005, 0.3, n),
    ]
    table = pd.DataFrame(dict(enumerate(cols)))
    with open(path, "w", newline="") as fh:
        fh.write(HEADER)
        table.to_csv(
            fh, sep="\t", header=False, index=False, lineterminator="\r\n", float_format="%.6f"
        )
    return n


def median_times(fns: dict[str, Callable[[], object]], repeat: int) -> dict[str, float]:
    """Median wall time [s] of each function, run in interleaved rounds."""
    times: dict[str, list[float]] = {name: [] for name in fns}
    for _ in range(repeat):
        for name, fn in fns.items():
            t0 = time.perf_counter()
            fn()
            times[name].append(time.perf_counter() - t0)
    return {name: statistics.median(t) for name, t in times.items()}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mb", type=float, default=50.0, help="file size [MB] (default 50)")
    ap.add_argument("--repeat", type=int, default=5, help="runs per timing (median)")
    ap.add_argument("--keep", type=Path, default=None, help="write the file here and keep it")
    args = ap.parse_args(argv)

    with tempfile.TemporaryDirectory() as tmp:
        folder = args.keep or Path(tmp)
        folder.mkdir(parents=True, exist_ok=True)
        path = folder / "bench_wvase.dat"
        n = write_file(path, args.mb)
        size_mb = path.stat().st_size / 1e6
        print(f"file: {path} ({size_mb:.1f} MB, {n} data lines)")

        m = labbrdf.read(path)  # warm-up, and a check of what is timed
        assert len(m) == 2 * n, (len(m), n)
        raw = path.read_bytes()
        _, offset = head_lines(raw.decode("ascii"), 4)
        d = m.data  # the long table as the reader hands it to validate: categorical text
        table = build_frame(
            sample=d["sample"].iloc[0],
            instrument=d["instrument"].iloc[0],
            source=d["source"].iloc[0],
            quantity=pd.Categorical(d["quantity"]),
            value=d["value"],
            sigma=d["sigma"],
            unit=pd.Categorical(d["unit"]),
            wavelength_nm=d["wavelength_nm"],
            theta_i_deg=d["theta_i_deg"],
            theta_r_deg=d["theta_r_deg"],
            phi_r_deg=d["phi_r_deg"],
        )
        t = median_times(
            {
                "labbrdf.read": lambda: labbrdf.read(path),
                "pandas.read_csv (block)": lambda: pd.read_csv(
                    path, sep="\t", header=None, skiprows=4
                ),
                "_numblock.parse_block": lambda: parse_block(
                    path, None, 5, 8, tagged=True, data=raw, data_start=offset
                ),
                "dataset.validate": lambda: validate(table),
            },
            args.repeat,
        )

    print(f"{'':28s} {'time [s]':>9s} {'lines/s':>12s} {'MB/s':>8s}")
    for name, ti in t.items():
        print(f"{name:28s} {ti:9.3f} {n / ti:12.0f} {size_mb / ti:8.1f}")
    t_lab = t["labbrdf.read"]
    ratio = t["pandas.read_csv (block)"] / t_lab
    print(f"speed ratio labbrdf/pandas: {ratio:.2f} (aim >= 0.5)")
    print(f"labbrdf.read rows/s (long table, 2 rows per line): {2 * n / t_lab:.0f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
