"""Start-up of the ``labbrdf`` command against ``python -c 'import numpy'``.

Run: ``python benchmarks/bench_startup.py [--repeat 11] [--commands fit,film,...]``

Times, in fresh interpreters started by this process, the median over ``--repeat`` rounds
of the wall time, the CPU time (user + system, from ``os.wait4``) and the peak memory
(max RSS) of

* ``python -c pass`` (the interpreter alone),
* ``python -c 'import numpy'`` (the reference),
* ``python -m labbrdf.cli --version`` and ``--help``,
* ``python -m labbrdf.cli CMD --help`` for every command,

and prints each median with its ratio to ``import numpy``, and the number of modules each
imports (``-X importtime``, one extra run). The rounds are interleaved (one of each per
round), so a change of machine load hits all of them alike. Aim: ``--version`` and
``--help`` within 3x ``import numpy``. Not a timed test: numbers depend on the machine and
its load.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import time

from labbrdf.cli._parser import COMMANDS


def run_once(argv: list[str]) -> tuple[float, float, float]:
    """Wall time [s], CPU time [s] and max RSS [MB] of one run of ``argv``."""
    t0 = time.perf_counter()
    proc = subprocess.Popen(argv, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - t0
    proc.returncode = os.waitstatus_to_exitcode(status)
    if proc.returncode != 0:
        raise SystemExit(f"{' '.join(argv)}: exit code {proc.returncode}")
    return wall, usage.ru_utime + usage.ru_stime, usage.ru_maxrss / 1024


def module_count(argv: list[str]) -> int:
    """The number of modules ``argv`` (a ``python ...`` command) imports."""
    err = subprocess.run(
        [argv[0], "-X", "importtime", *argv[1:]], capture_output=True, text=True, check=True
    ).stderr
    return sum(line.startswith("import time:") for line in err.splitlines()) - 1


def cases(commands: list[str]) -> dict[str, list[str]]:
    """Label -> command line."""
    py = sys.executable
    cli = [py, "-m", "labbrdf.cli"]
    out = {
        "python -c pass": [py, "-c", "pass"],
        "import numpy": [py, "-c", "import numpy"],
        "labbrdf --version": [*cli, "--version"],
        "labbrdf --help": [*cli, "--help"],
    }
    for name in commands:
        out[f"labbrdf {name} --help"] = [*cli, name, "--help"]
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeat", type=int, default=11)
    ap.add_argument("--commands", default=",".join(COMMANDS), help="comma-separated")
    a = ap.parse_args()
    runs = cases([c for c in a.commands.split(",") if c])
    samples: dict[str, list[tuple[float, float, float]]] = {k: [] for k in runs}
    for _ in range(a.repeat):
        for label, argv in runs.items():
            samples[label].append(run_once(argv))
    med = {k: [statistics.median(col) for col in zip(*v, strict=True)] for k, v in samples.items()}
    ref_wall, ref_cpu, _ = med["import numpy"]
    print(f"load average {os.getloadavg()[0]:.2f}; medians of {a.repeat} interleaved runs")
    head = ("wall s", "x numpy", "CPU s", "x numpy")
    print(f"{'':28} " + " ".join(f"{h:>7}" for h in head) + f" {'MB':>6} {'mods':>5}")
    for label, (wall, cpu, rss) in med.items():
        n = module_count(runs[label])
        print(
            f"{label:28} {wall:7.3f} {wall / ref_wall:7.2f} {cpu:7.3f} {cpu / ref_cpu:7.2f} "
            f"{rss:6.0f} {n:5d}"
        )


if __name__ == "__main__":
    main()
