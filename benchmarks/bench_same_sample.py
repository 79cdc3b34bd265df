"""``--same-sample`` splitting: time against the number of commas in the value.

Run: ``python benchmarks/bench_same_sample.py [--max-commas 16000] [--repeat 3]``

In a temporary folder with three inputs whose names hold 0, 1 and 2 commas (``a.dat``,
``b,c.di``, ``d,e,f.csv``), times the median of ``--repeat`` runs of
:func:`labbrdf.samples.split_same_sample` on a value that lists them round-robin, with
1,000 to ``--max-commas`` commas (doubling), and on a value of as many pieces that match no
input (the fall-back split at every comma). Prints seconds and microseconds per comma: a
linear split keeps the second column flat as the value grows (the former split tried every
piece, quadratically many, each joined and resolved: 2,000 commas took over two minutes).
Not a timed test: numbers depend on the machine and its load; the test suite counts the
pieces resolved instead (``tests/test_samples.py``).
"""

from __future__ import annotations

import argparse
import os
import statistics
import tempfile
import time

from labbrdf.samples import split_same_sample

INPUTS = ["a.dat", "b,c.di", "d,e,f.csv"]


def _median_s(text: str, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        split_same_sample(text, INPUTS)
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--max-commas", type=int, default=16_000)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    old = os.getcwd()
    with tempfile.TemporaryDirectory() as tmp:
        os.chdir(tmp)
        try:
            for name in INPUTS:
                with open(name, "w") as f:
                    f.write("x")
            print(f"{'commas':>8} {'matching [s]':>13} {'us/comma':>9} {'unknown [s]':>12}")
            n = 1_000
            while n <= args.max_commas:
                pieces = []
                while sum(p.count(",") + 1 for p in pieces) <= n:
                    pieces.append(INPUTS[len(pieces) % 3])
                text = ",".join(pieces)
                t = _median_s(text, args.repeat)
                unknown = ",".join(f"x{i}" for i in range(n + 1))
                u = _median_s(unknown, args.repeat)
                c = text.count(",")
                print(f"{c:>8} {t:>13.4f} {1e6 * t / c:>9.2f} {u:>12.4f}")
                n *= 2
        finally:
            os.chdir(old)


if __name__ == "__main__":
    main()
