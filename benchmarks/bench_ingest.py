"""Ingest speed: ``labbrdf.read`` on a large WVASE Psi/Delta file against ``pandas.read_csv``.

Run: ``python benchmarks/bench_ingest.py [--mb 50] [--repeat 5] [--keep DIR]``

Writes a synthetic WVASE32 ASCII file of about ``--mb`` MB (the 4-line header of
``w2_10102006.dat``, then untagged ``x AOI Psi Delta sPsi sDelta`` rows, CRLF, 676
wavelengths x as many angles as needed; seeded) into a temporary directory, then times, in
this process, the median of ``--repeat`` runs of

* ``labbrdf.read(path)``: dispatch, decoding, parsing, unit conversion, the long table
  (2 rows per line) and its validation;
* ``pandas.read_csv(path, sep="\\t", header=None, skiprows=4)``: the bare numeric block;
* ``labbrdf.adapters._numblock.parse_block`` alone (the parser inside the reader);

and prints lines/s, MB/s and the ratio labbrdf/pandas. Aim (issue 3): labbrdf at least half
pandas' speed (ratio >= 0.5). Not a timed test: numbers depend on the machine and its load.
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd

import labbrdf
from labbrdf.adapters._numblock import parse_block, split_head

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


def median_time(fn, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


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
        t_lab = median_time(lambda: labbrdf.read(path), args.repeat)
        t_pd = median_time(
            lambda: pd.read_csv(path, sep="\t", header=None, skiprows=4), args.repeat
        )
        text = path.read_text()
        _, body = split_head(text, 4)
        t_parse = median_time(lambda: parse_block(path, body, 5, 8, tagged=True), args.repeat)

    print(f"{'':28s} {'time [s]':>9s} {'lines/s':>12s} {'MB/s':>8s}")
    for name, t in (
        ("labbrdf.read", t_lab),
        ("pandas.read_csv (block)", t_pd),
        ("_numblock.parse_block", t_parse),
    ):
        print(f"{name:28s} {t:9.3f} {n / t:12.0f} {size_mb / t:8.1f}")
    ratio = t_pd / t_lab
    print(f"speed ratio labbrdf/pandas: {ratio:.2f} (aim >= 0.5)")
    print(f"labbrdf.read rows/s (long table, 2 rows per line): {2 * n / t_lab:.0f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
