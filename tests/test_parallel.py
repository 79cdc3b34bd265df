"""The executor layer (labbrdf.parallel): same results on every scheduler, truthful
progress, loud failures; and scale-out of its users (batch fits, tracer, CLI, validate).

The second part (scale-out on dask.distributed): real batch fits and real tracer runs go
through a 2-worker ``LocalCluster`` (``local``), a cluster started here and reached by its
``tcp://`` address, and the CLI; each is compared bit for bit with the serial run. Worker
deaths are injected by :class:`KillOnce`, a picklable wrapper that makes the worker process
running one chosen task exit, a given number of times (counted in a marker file under
``tmp_path``, so the count survives the dead process). dask's retries must then give the
serial numbers, and exhausted retries a :class:`ParallelError` with nothing returned.
"""

from __future__ import annotations

import asyncio
import builtins
import functools
import importlib
import io
import json
import math
import os
import re
import shutil
import subprocess
import sys
import textwrap
import time
from concurrent.futures import Future
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pytest

import labbrdf.fitting.batch
from labbrdf import parallel
from labbrdf.cli import main
from labbrdf.dataset import Measurement, make_frame, write
from labbrdf.fitting import fit_many
from labbrdf.models import get as get_model
from labbrdf.parallel import ParallelError, Progress
from labbrdf.tracer import Substrate, TraceConfig, trace


def crash_once(arg):
    """Kill the worker process the first time (marker file absent), then succeed."""
    marker, value = arg
    if not os.path.exists(marker):
        with open(marker, "w") as fh:
            fh.write("died")
        os._exit(3)
    return value * 2


def always_crash(_):
    os._exit(3)


def fail(x):
    if x == 3:
        raise ValueError("task 3 is bad")
    return x


def test_same_results_serial_and_processes():
    items = [0.5 * i for i in range(20)]
    expected = [math.sqrt(x) for x in items]
    assert parallel.run(math.sqrt, items, scheduler="serial") == expected
    assert parallel.run(math.sqrt, items, scheduler="processes", workers=2) == expected


def test_imap_yields_in_item_order_with_small_window():
    out = list(parallel.imap(math.sqrt, range(9), scheduler="processes", workers=2, window=2))
    assert out == [math.sqrt(i) for i in range(9)]


def test_task_exception_propagates():
    with pytest.raises(ValueError, match="task 3 is bad"):
        parallel.run(fail, range(6), scheduler="processes", workers=2)


def test_dead_pool_worker_fails_loudly():
    with pytest.raises(ParallelError, match="no partial result"):
        parallel.run(always_crash, range(4), scheduler="processes", workers=2)


def test_unknown_scheduler_and_workers():
    with pytest.raises(ValueError, match="unknown scheduler 'gpu'"):
        parallel.run(abs, [1], scheduler="gpu")
    with pytest.raises(ValueError, match="workers must be >= 1"):
        parallel.run(abs, [1], scheduler="processes", workers=0)


def test_executor_map_gives_the_same_results_on_every_scheduler():
    items = [0.5 * i for i in range(20)]
    expected = [math.sqrt(x) for x in items]
    assert parallel.Executor("serial").map(math.sqrt, items) == expected
    pool = parallel.Executor("processes", workers=2)
    assert pool.map(math.sqrt, items) == expected
    assert list(pool.imap(math.sqrt, items, window=2)) == expected
    assert list(pool(math.sqrt, items)) == expected  # the ordered map the tracer takes


def test_executor_has_one_default_and_converts_scheduler_names_once():
    assert parallel.Executor() == parallel.as_executor() == parallel.as_executor(None)
    assert parallel.Executor().scheduler == parallel.DEFAULT_SCHEDULER == "processes"
    ex = parallel.as_executor("serial", workers=3, progress=True)
    assert ex == parallel.Executor("serial", workers=3, progress=True)
    assert ex.serial and ex.nworkers == 1
    assert parallel.as_executor(scheduler="serial") == parallel.Executor("serial")
    assert parallel.as_executor(ex) is ex
    assert parallel.as_executor(ex, progress=False) == parallel.Executor("serial", workers=3)
    assert parallel.Executor("processes", workers=3).nworkers == 3


@pytest.mark.parametrize("scheduler", ["processes", "local"])
def test_local_workers_are_capped_per_core(scheduler, monkeypatch):
    """A local count far beyond the cores is refused before a process starts."""
    monkeypatch.setattr(os, "cpu_count", lambda: 2)
    cap = parallel.MAX_WORKERS_PER_CORE * 2
    assert parallel.Executor(scheduler, workers=cap).nworkers == cap
    with pytest.raises(ValueError, match=f"workers must be at most {cap} .4 per core"):
        parallel.Executor(scheduler, workers=100_000)
    with pytest.raises(ValueError, match=f"workers must be at most {cap}"):
        parallel.run(abs, [1], scheduler=scheduler, workers=cap + 1)
    # a remote scheduler's workers run elsewhere: not capped by this machine's cores
    assert parallel.Executor("tcp://127.0.0.1:1", workers=100_000).nworkers == 100_000


def test_executor_refuses_bad_options_at_construction():
    with pytest.raises(ValueError, match="unknown scheduler 'gpu'"):
        parallel.Executor("gpu")
    with pytest.raises(ValueError, match="workers must be >= 1, got 0"):
        parallel.Executor("processes", workers=0)
    with pytest.raises(ValueError, match="retries must be >= 0, got -1"):
        parallel.Executor("serial", retries=-1)
    with pytest.raises(ValueError, match="--worker-timeout: expected a finite number"):
        parallel.Executor("serial", worker_timeout=-1.0)
    with pytest.raises(ValueError, match="--tls-ca /nonexistent.pem: no such file"):
        parallel.Executor("serial", tls_ca="/nonexistent.pem", tls_cert="/nonexistent.pem")
    with pytest.raises(ValueError, match="either an executor or a scheduler, not both"):
        parallel.as_executor("serial", scheduler="processes")
    with pytest.raises(ValueError, match="an Executor has its own worker count"):
        parallel.as_executor(parallel.Executor("serial"), workers=2)
    with pytest.raises(ValueError, match="Executor or a scheduler name, got int"):
        parallel.as_executor(3)  # type: ignore[arg-type]


def test_progress_counts_every_task_once_on_one_line_of_a_terminal():
    class Terminal(io.StringIO):
        def isatty(self) -> bool:
            return True

    buf = Terminal()
    bar = Progress(4, "fits", stream=buf)
    for _ in range(4):
        bar.update()
    assert bar.done == 4
    text = buf.getvalue()
    assert text.startswith("\rlabbrdf: fits 0/4") and "\n" not in text  # drawn at once
    assert text.endswith("\r") and text.rsplit("\r", 2)[-2].strip() == ""  # erased at the end


def test_progress_across_workers_is_silent_when_stderr_is_not_a_terminal(capsys):
    out = parallel.run(math.sqrt, range(7), scheduler="processes", workers=2, progress=True)
    assert out == [math.sqrt(x) for x in range(7)]
    assert capsys.readouterr().err == ""


@pytest.fixture(scope="module")
def dask_available():
    pytest.importorskip("dask.distributed")


@pytest.mark.slow
def test_local_cluster_two_workers_matches_serial(dask_available):
    items = [0.25 * i for i in range(12)]
    assert parallel.run(math.sqrt, items, scheduler="local", workers=2) == [
        math.sqrt(x) for x in items
    ]


@pytest.mark.slow
def test_killed_dask_worker_is_retried_and_result_is_complete(dask_available, tmp_path):
    items = [(str(tmp_path / "marker"), v) for v in range(4)]
    out = parallel.run(crash_once, items, scheduler="local", workers=2, retries=2)
    assert out == [0, 2, 4, 6]
    assert (tmp_path / "marker").read_text() == "died"  # a worker really died


@pytest.mark.slow
def test_dask_worker_that_always_dies_fails_loudly(dask_available):
    import dask

    with dask.config.set({"distributed.scheduler.allowed-failures": 0}):
        with pytest.raises(ParallelError, match="no partial result"):
            parallel.run(always_crash, [1, 2], scheduler="local", workers=1, retries=0)


# ======================================================================================
# scale-out: batch fits, tracer, CLI and validate on dask.distributed
# ======================================================================================

#: the tracer run of these tests: 8 blocks of 1500 rays (Al, alpha 0.2, 45 deg), coarse grid,
#: each block its own fold group so that work units can be spread over workers
TRACE = TraceConfig(
    rays=12_000,
    block_rays=1500,
    fold_blocks=1,
    substrate=Substrate(alpha=0.2),
    theta_step_deg=6.0,
    phi_step_deg=6.0,
    scattering="single",
    seed=7,
)
#: columns that hold wall times, the only ones allowed to differ between schedulers
TIMING = ["elapsed_s"]


# ----------------------------------------------------------------------------------------
# fault injection (module level: dask pickles it by reference into the workers)
# ----------------------------------------------------------------------------------------


def trace_block(item: tuple[TraceConfig, tuple[int, ...]]) -> int:
    """Key of a tracer work unit ``(config, fold groups)``: its first group (= block here)."""
    return item[1][0]


def fit_chunk(item: tuple[list[tuple[int, Any, Any]], dict, bool]) -> int:
    """Key of a fit_many chunk ``([(group index, model, FitData), ...], kw, keep)``."""
    return item[0][0][0]


class KillOnce:
    """Run ``module.name(item)``; on the task whose ``key(item) == victim`` first kill the
    worker process (``os._exit``), ``times`` times in all (counted in ``marker``).

    The wrapped function is carried by name and looked up in the worker, so the parent may
    monkeypatch the original with this wrapper (as for ``fit_many``'s chunk function).
    """

    def __init__(self, module: str, name: str, key: Any, victim: int, marker: Path, times=1):
        self.module, self.name, self.key, self.victim = module, name, key, victim
        self.marker, self.times = str(marker), times

    def __call__(self, item: Any) -> Any:
        if self.key(item) == self.victim:
            deaths = Path(self.marker).read_text().count("x") if os.path.exists(self.marker) else 0
            if deaths < self.times:
                with open(self.marker, "a") as fh:
                    fh.write("x")
                os._exit(3)
        return getattr(importlib.import_module(self.module), self.name)(item)


def deaths(marker: Path) -> int:
    return marker.read_text().count("x") if marker.exists() else 0


# ----------------------------------------------------------------------------------------
# data and helpers
# ----------------------------------------------------------------------------------------


def batch_frame(n_wl: int = 6) -> pd.DataFrame:
    """Synthetic smooth3 scans of two samples in the fixtures' geometry and noise model."""
    rng = np.random.default_rng(20260707)
    ti = np.repeat([30.0, 45.0, 60.0], 21)
    tr = ti + np.tile(np.round(np.arange(-2.0, 2.0001, 0.2), 10), 3)
    model = get_model("smooth3")
    frames = []
    for sample, k1 in (("OSR", 0.9), ("mirror", 0.5)):
        for wl in np.linspace(400.0, 900.0, n_wl):
            k = {"k1": k1, "k2": -0.015, "k3": 0.416}
            y = model.evaluate(np.radians(ti), np.radians(tr), params=k)
            sigma = np.hypot(0.005 * y, 1e-4)
            frames.append(
                make_frame(
                    sample=sample,
                    instrument="synthetic",
                    source="test_scaleout",
                    quantity="brdf",
                    value=y + sigma * rng.standard_normal(y.size),
                    sigma=sigma,
                    unit="sr-1",
                    wavelength_nm=wl,
                    theta_i_deg=ti,
                    theta_r_deg=tr,
                    phi_r_deg=180.0,
                )
            )
    return Measurement(pd.concat(frames, ignore_index=True)).data


def assert_same_table(a: pd.DataFrame, b: pd.DataFrame) -> None:
    pd.testing.assert_frame_equal(a.drop(columns=TIMING), b.drop(columns=TIMING), check_exact=True)


def assert_same_trace(a: Any, b: Any) -> None:
    for name in ("sums", "sumsq", "counts", "hemi", "block_hemi", "block_rays"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)
    assert a.ledger == b.ledger
    assert a.events == b.events


def dask_map(**kw: Any) -> Any:
    return functools.partial(parallel.imap, **kw)


@pytest.fixture(scope="module")
def dask_ok() -> None:
    pytest.importorskip("dask.distributed")


@pytest.fixture(scope="module")
def frame() -> pd.DataFrame:
    return batch_frame()


@pytest.fixture(scope="module")
def serial_table(frame: pd.DataFrame) -> pd.DataFrame:
    return fit_many(frame, "smooth3", scheduler="serial", progress=False)


@pytest.fixture(scope="module")
def serial_trace() -> Any:
    return trace(TRACE, map=builtins.map)


@pytest.fixture(scope="module")
def tcp_cluster(dask_ok: None) -> Any:
    """A 2-worker cluster started here; the tests reach it only through its address."""
    from dask.distributed import LocalCluster

    with LocalCluster(
        n_workers=2,
        threads_per_worker=1,
        processes=True,
        dashboard_address=None,
        scheduler_kwargs={"dashboard": False, "dashboard_address": ":0"},
    ) as cluster:
        yield cluster.scheduler_address


@pytest.fixture(scope="module", autouse=True)
def _close_local_cluster() -> Any:
    yield
    parallel.shutdown()


def _progress_counts(err: str, desc: str) -> list[tuple[int, int]]:
    """The counts drawn on a terminal's progress line (every update: no throttling)."""
    pattern = rf"^labbrdf: {re.escape(desc)} (\d+)/(\d+)"
    return [(int(a), int(b)) for a, b in re.findall(pattern, err.replace("\r", "\n"), re.M)]


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


# ----------------------------------------------------------------------------------------
# same numbers on every scheduler
# ----------------------------------------------------------------------------------------


@pytest.mark.slow
def test_batch_fit_on_two_worker_local_cluster_equals_serial_bit_for_bit(
    dask_ok, frame, serial_table
):
    table = fit_many(frame, "smooth3", scheduler="local", workers=2, chunks=5, progress=False)
    assert serial_table["success"].all() and len(serial_table) == 12
    assert_same_table(serial_table, table)
    info = parallel.cluster._LOCAL["client"].scheduler_info()
    assert len(info["workers"]) == 2  # --workers really gave two worker processes


@pytest.mark.slow
def test_trace_on_two_worker_local_cluster_equals_serial_bit_for_bit(dask_ok, serial_trace):
    assert TRACE.n_blocks == 8
    res = trace(TRACE, map=dask_map(scheduler="local", workers=2), blocks_per_unit=3)
    assert_same_trace(serial_trace, res)


def test_trace_on_one_and_two_pool_workers_equals_serial_bit_for_bit(serial_trace):
    for workers, per_unit in ((1, 1), (2, 3)):
        res = trace(
            TRACE, map=dask_map(scheduler="processes", workers=workers), blocks_per_unit=per_unit
        )
        assert_same_trace(serial_trace, res)


@pytest.mark.slow
def test_tcp_scheduler_address_gives_serial_numbers(
    tcp_cluster, frame, serial_table, serial_trace
):
    assert tcp_cluster.startswith("tcp://")
    table = fit_many(frame, "smooth3", scheduler=tcp_cluster, chunks=4, progress=False)
    assert_same_table(serial_table, table)
    assert_same_trace(serial_trace, trace(TRACE, map=dask_map(scheduler=tcp_cluster)))


# ----------------------------------------------------------------------------------------
# a worker that dies mid-run: dask retries, or a loud failure with nothing returned
# ----------------------------------------------------------------------------------------


@pytest.mark.slow
def test_worker_killed_mid_trace_is_retried_and_result_equals_serial(
    dask_ok, serial_trace, tmp_path, monkeypatch
):
    from labbrdf import progress

    terminal = _Terminal()
    monkeypatch.setattr(sys, "stderr", terminal)
    monkeypatch.setattr(progress, "MIN_INTERVAL", 0.0)  # draw every count
    marker = tmp_path / "deaths"
    killer = KillOnce("labbrdf.tracer.walk", "_unit", trace_block, 5, marker)

    def faulty_map(func: Any, items: Any) -> Any:
        assert func.__name__ == "_unit"
        return parallel.imap(
            killer, items, scheduler="local", workers=2, progress=True, desc="trace"
        )

    res = trace(TRACE, map=faulty_map)
    assert deaths(marker) == 1  # a worker really died, mid-run (block 5 of 8)
    assert_same_trace(serial_trace, res)
    counts = _progress_counts(terminal.getvalue(), "trace")
    done = [c for c, _ in counts]
    assert done == sorted(done) and counts[-1] == (8, 8)  # truthful: never past 8/8


@pytest.mark.slow
def test_worker_killed_mid_batch_fit_is_retried_and_table_equals_serial(
    dask_ok, frame, serial_table, tmp_path, monkeypatch
):
    marker = tmp_path / "deaths"
    killer = KillOnce("labbrdf.fitting.batch", "_fit_chunk", fit_chunk, 2, marker)
    monkeypatch.setattr(labbrdf.fitting.batch, "_fit_chunk", killer)
    table = fit_many(frame, "smooth3", scheduler="local", workers=2, chunks=6, progress=False)
    assert deaths(marker) == 1
    assert_same_table(serial_table, table)


@pytest.mark.slow
def test_trace_fails_loudly_when_worker_retries_are_used_up(dask_ok, tmp_path):
    marker = tmp_path / "deaths"
    killer = KillOnce("labbrdf.tracer.walk", "_unit", trace_block, 3, marker)
    faulty = functools.partial(parallel.imap, scheduler="local", workers=2, retries=0, window=2)
    result = None
    with pytest.raises(ParallelError, match="0 retries were used up.*no partial result"):
        result = trace(TRACE, map=lambda f, items: faulty(killer, items))
    assert result is None and deaths(marker) == 1


@pytest.mark.slow
def test_batch_fit_fails_loudly_when_worker_retries_are_used_up(
    dask_ok, frame, tmp_path, monkeypatch
):
    marker = tmp_path / "deaths"
    # dies on every attempt: the first run and the default 2 retries
    killer = KillOnce("labbrdf.fitting.batch", "_fit_chunk", fit_chunk, 1, marker, times=99)
    monkeypatch.setattr(labbrdf.fitting.batch, "_fit_chunk", killer)
    table = None
    with pytest.raises(ParallelError, match="2 retries were used up.*no partial result"):
        table = fit_many(frame, "smooth3", scheduler="local", workers=2, chunks=4, progress=False)
    assert table is None and deaths(marker) == 3


@pytest.mark.slow
def test_task_that_raises_on_dask_is_not_retried_and_propagates(tcp_cluster, tmp_path):
    marker = tmp_path / "calls"
    with pytest.raises(ValueError, match="bad item 2"):
        parallel.run(functools.partial(raise_on_two, str(marker)), range(4), scheduler=tcp_cluster)
    assert marker.read_text() == "x"  # ran once: an exception is an answer, not a crash


def raise_on_two(marker: str, x: int) -> int:
    if x == 2:
        with open(marker, "a") as fh:
            fh.write("x")
        raise ValueError(f"bad item {x}")
    return x


def sleepy_fail(x: int) -> int:
    if x == 1:
        raise ValueError("item 1 is bad")
    time.sleep(0.5)
    return x


def scheduler_tasks(dask_scheduler: Any) -> int:
    return len(dask_scheduler.tasks)


@pytest.mark.slow
def test_failed_dask_run_leaves_no_tasks_running_on_the_reused_cluster(dask_ok):
    with pytest.raises(ValueError, match="item 1 is bad") as excinfo:
        parallel.run(sleepy_fail, range(40), scheduler="local", workers=2)
    # excinfo keeps the generator's frame (and its futures) alive, as a caller's error
    # handler would: only an explicit cancel stops the ~14 submitted tasks (3 s of work)
    client = parallel.cluster._LOCAL["client"]
    deadline = time.monotonic() + 1.0
    while client.run_on_scheduler(scheduler_tasks) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert client.run_on_scheduler(scheduler_tasks) == 0
    assert excinfo.value is not None


def env_var(name: str) -> str | None:
    return os.environ.get(name)


@pytest.mark.slow
def test_local_cluster_workers_start_without_dask_malloc_trim_setting(dask_ok):
    # MALLOC_TRIM_THRESHOLD_ makes glibc mmap each large array afresh: tracer blocks ran
    # 3x slower on dask workers than in a process pool
    out = parallel.run(env_var, ["MALLOC_TRIM_THRESHOLD_", "OMP_NUM_THREADS"], scheduler="local")
    assert out[0] is None
    assert out[1] == "1"  # dask's other worker settings are kept


class LateFuture(Future):
    """Finished, but ``done()`` says False the first time: it finished 'during' the loop."""

    def __init__(self, value: int) -> None:
        super().__init__()
        self.set_result(value)
        self._asked = False

    def done(self) -> bool:
        asked, self._asked = self._asked, True
        return asked


def test_progress_counts_a_task_that_finishes_while_results_are_collected():
    bar = parallel.Progress(5, enabled=False)
    out = list(parallel.executor._ordered(LateFuture, 5, 2, bar, lambda f: f.result()))
    assert out == [0, 1, 2, 3, 4]
    assert bar.done == 5  # every task counted exactly once


# ----------------------------------------------------------------------------------------
# dask is an optional extra
# ----------------------------------------------------------------------------------------


@pytest.mark.parametrize("scheduler", ["local", "tcp://127.0.0.1:8786"])
def test_dask_scheduler_without_dask_says_how_to_install_it(monkeypatch, scheduler):
    parallel.shutdown()
    monkeypatch.setitem(sys.modules, "dask.distributed", None)  # import raises ImportError
    with pytest.raises(ImportError, match=r"pip install labbrdf\[dask\]"):
        parallel.run(abs, [1, -2], scheduler=scheduler, workers=2)


def test_cli_trace_without_dask_exits_2_with_the_install_hint(monkeypatch, capsys, trace_sample):
    parallel.shutdown()
    monkeypatch.setitem(sys.modules, "dask.distributed", None)
    code = main([*trace_sample, "--rays", "1000", "--scheduler", "local"])
    assert code == 2
    assert "pip install labbrdf[dask]" in capsys.readouterr().err


class _ClusterThatFails:
    """A LocalCluster stand-in whose start-up fails as ``error`` says (no process started)."""

    error: BaseException = RuntimeError("Cluster failed to start: Nanny failed to start.")

    def __init__(self, *args: Any, **kw: Any) -> None:
        raise self.error


@pytest.mark.parametrize(
    ("error", "code", "message"),
    [
        (RuntimeError("Cluster failed to start: Nanny failed to start."), 2, "did not start"),
        (TimeoutError("no worker within 60 s"), 2, "did not start"),
        (KeyboardInterrupt(), 130, "interrupted"),
    ],
    ids=["nanny", "timeout", "ctrl-c"],
)
@pytest.mark.usefixtures("dask_ok")
def test_cli_local_cluster_that_does_not_start_is_one_message(
    monkeypatch, capsys, trace_sample, error, code, message
):
    from dask.distributed import Client

    parallel.shutdown()
    monkeypatch.setattr(_ClusterThatFails, "error", error)
    monkeypatch.setattr(parallel.cluster, "_import_dask", lambda: (Client, _ClusterThatFails))
    assert main([*trace_sample, "--rays", "1000", "--scheduler", "local"]) == code
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err
    assert len(err.strip().splitlines()) == 1, err
    if code == 2:
        assert str(error) in err  # the cause, in dask's words


def test_validate_checks_the_scheduler_before_running_any_section(monkeypatch, tmp_path):
    from labbrdf.report import validate

    with pytest.raises(ValueError, match="unknown scheduler 'gpu'"):
        validate(out=tmp_path / "a", quick=True, scheduler="gpu", sections_to_run=[])
    monkeypatch.setitem(sys.modules, "dask.distributed", None)
    with pytest.raises(ImportError, match=r"pip install labbrdf\[dask\]"):
        validate(out=tmp_path / "b", quick=True, scheduler="local", sections_to_run=[])
    assert not (tmp_path / "a").exists() and not (tmp_path / "b").exists()
    out = str(tmp_path / "c")
    assert main(["validate", "--out", out, "--quick", "--scheduler", "local"]) == 2
    assert not (tmp_path / "c").exists()


@pytest.mark.slow
def test_unreachable_tcp_scheduler_is_a_clear_error(dask_ok, frame, tmp_path, capsys):
    import dask

    with dask.config.set({"distributed.comm.timeouts.connect": "1s"}):
        with pytest.raises(ParallelError, match="cannot reach the dask scheduler tcp://127"):
            parallel.run(abs, [1], scheduler="tcp://127.0.0.1:9")
        data = _write_dataset(frame, tmp_path)
        argv = ["fit", data, "--model", "smooth3", "-o", str(tmp_path / "t.csv")]
        assert main([*argv, "--scheduler", "tcp://127.0.0.1:9"]) == 2
    assert "labbrdf fit: cannot reach the dask scheduler" in capsys.readouterr().err
    assert not (tmp_path / "t.csv").exists()  # nothing written


def test_negative_retries_are_rejected(dask_ok):
    with pytest.raises(ValueError, match="retries must be >= 0, got -1"):
        parallel.run(abs, [1], scheduler="tcp://127.0.0.1:9", retries=-1)  # before connecting


# ----------------------------------------------------------------------------------------
# the CLI honours --scheduler and --workers end to end
# ----------------------------------------------------------------------------------------


class Spy:
    """Records the scheduler options of every parallel.imap call, then runs it."""

    def __init__(self) -> None:
        self.calls: list[dict[str, Any]] = []
        self.pools: list[int] = []
        self._imap = parallel.imap

    def imap(self, func: Any, items: Any, **kw: Any) -> Any:
        self.calls.append(dict(kw, func=getattr(func, "__name__", repr(func))))
        return self._imap(func, items, **kw)


@pytest.fixture
def spy(monkeypatch) -> Spy:
    s = Spy()
    monkeypatch.setattr(parallel.executor, "imap", s.imap)
    real_pool = parallel.executor.ProcessPoolExecutor

    def pool(max_workers: int) -> Any:
        s.pools.append(max_workers)
        return real_pool(max_workers=max_workers)

    monkeypatch.setattr(parallel.executor, "ProcessPoolExecutor", pool)
    return s


@pytest.fixture
def trace_blocks(trace_sample: list[str]) -> list[str]:
    """A trace of three blocks (70000 rays, blocks of 32768), seeded, JSON summary."""
    return [*trace_sample, "--rays", "70000", "--seed", "3", "--single-scattering", "--json"]


def _trace_json(capsys, argv: list[str], *extra: str) -> dict[str, Any]:
    assert main([*argv, *extra]) == 0
    out = json.loads(capsys.readouterr().out)
    out.pop("seconds")
    return out


def test_cli_trace_honours_scheduler_and_workers(spy, capsys, trace_blocks):
    serial = _trace_json(capsys, trace_blocks, "--scheduler", "serial")
    assert spy.pools == []  # serial: in this process
    pool = _trace_json(capsys, trace_blocks, "--scheduler", "processes", "--workers", "3")
    assert [(c["scheduler"], c["workers"]) for c in spy.calls] == [
        ("serial", None),
        ("processes", 3),
    ]
    assert spy.pools == [3]  # a pool of 3 worker processes really ran the blocks
    assert pool == serial


@pytest.mark.slow
def test_cli_trace_over_tcp_equals_serial(tcp_cluster, capsys, trace_blocks):
    serial = _trace_json(capsys, trace_blocks, "--scheduler", "serial")
    assert _trace_json(capsys, trace_blocks, "--scheduler", tcp_cluster) == serial


def _write_dataset(frame: pd.DataFrame, tmp_path: Path) -> str:
    path = tmp_path / "scans.csv"
    write(Measurement(frame), path)
    return str(path)


def test_cli_fit_honours_scheduler_and_workers(spy, frame, tmp_path, capsys):
    data = _write_dataset(frame, tmp_path)
    argv = ["fit", data, "--model", "smooth3", "--json", "-o"]
    assert main([*argv, str(tmp_path / "serial.csv"), "--scheduler", "serial"]) == 0
    assert spy.pools == []
    assert main([*argv, str(tmp_path / "pool.csv"), "--scheduler", "processes",
                 "--workers", "2"]) == 0  # fmt: skip
    assert [(c["scheduler"], c["workers"]) for c in spy.calls] == [
        ("serial", None),
        ("processes", 2),
    ]
    assert spy.pools == [2]  # a pool of 2 worker processes really ran the fits
    capsys.readouterr()
    serial = pd.read_csv(tmp_path / "serial.csv")
    assert len(serial) == 12 and serial["success"].all()
    assert_same_table(serial, pd.read_csv(tmp_path / "pool.csv"))


@pytest.mark.slow
def test_cli_fit_over_tcp_equals_serial_bit_for_bit(tcp_cluster, frame, tmp_path, capsys):
    data = _write_dataset(frame, tmp_path)
    argv = ["fit", data, "--model", "smooth3", "--json"]
    assert main([*argv, "-o", str(tmp_path / "serial.csv"), "--scheduler", "serial"]) == 0
    serial = capsys.readouterr().out
    assert main([*argv, "-o", str(tmp_path / "tcp.csv"), "--scheduler", tcp_cluster]) == 0
    assert capsys.readouterr().out == serial
    assert_same_table(pd.read_csv(tmp_path / "serial.csv"), pd.read_csv(tmp_path / "tcp.csv"))


def test_cli_validate_passes_scheduler_and_workers_to_the_report(monkeypatch, tmp_path):
    import labbrdf.report

    seen: dict[str, Any] = {}

    def fake_validate(**kw: Any) -> int:
        seen.update(kw)
        return 0

    monkeypatch.setattr(labbrdf.report, "validate", fake_validate)
    out = str(tmp_path / "rep")
    argv = ["validate", "--out", out, "--quick", "--scheduler", "processes", "--workers", "2"]
    assert main(argv) == 0
    ex = parallel.Executor("processes", workers=2, progress=True)
    assert seen == {"out": out, "quick": True, "progress": True, "executor": ex}


def test_cli_report_passes_its_executor_to_the_report(monkeypatch, fixtures_dir, tmp_path):
    import labbrdf.report

    seen: dict[str, Any] = {}

    def fake_report(*args: Any, **kw: Any) -> int:
        seen.update(kw)
        return 0

    monkeypatch.setattr(labbrdf.report, "user_report", fake_report)
    scan = str(fixtures_dir / "specular" / "osr_specular.csv")
    out = str(tmp_path / "rep")
    argv = ["report", scan, "-o", out, "--quiet", "--scheduler", "serial", "--workers", "2"]
    assert main(argv) == 0
    assert seen["executor"] == parallel.Executor("serial", workers=2, progress=False)
    assert main(["report", scan, "-o", out, "--quiet"]) == 0  # the one default
    assert seen["executor"].scheduler == parallel.DEFAULT_SCHEDULER == "processes"


@pytest.mark.parametrize(
    "bad, message",
    [
        (["--scheduler", "gpu"], "unknown scheduler 'gpu'"),
        (["--workers", "0"], "workers must be >= 1, got 0"),
        (["--worker-timeout", "0"], "--worker-timeout"),
    ],
)
def test_cli_report_refuses_bad_executor_options_before_any_work(
    bad, message, fixtures_dir, tmp_path, capsys
):
    scan = str(fixtures_dir / "specular" / "osr_specular.csv")
    out = tmp_path / "rep"
    assert main(["report", scan, "-o", str(out), "--quiet", *bad]) == 2
    assert message in capsys.readouterr().err
    assert not out.exists()


@pytest.mark.slow
def test_validate_runs_its_fits_and_traces_on_the_requested_scheduler(spy, fixtures_dir, tmp_path):
    from labbrdf.report import validate

    if not (fixtures_dir / "specular").is_dir():
        pytest.skip("fixtures/specular absent")
    code = validate(
        out=tmp_path / "rep",
        quick=True,
        progress=False,
        scheduler="processes",
        workers=2,
        fixtures_dir=fixtures_dir,
        shared_dir=False,
        sections_to_run=["fits", "tracer_maps"],
    )
    assert code in (0, 1)
    funcs = {c["func"] for c in spy.calls}
    assert "_unit" in funcs and funcs & {"fit_task", "_fit_chunk"}  # tracer runs and fits
    assert spy.calls and {(c["scheduler"], c["workers"]) for c in spy.calls} == {("processes", 2)}
    assert set(spy.pools) == {2}


@pytest.mark.parametrize("bad", [["--scheduler", "gpu"], ["--workers", "0"]])
def test_cli_rejects_bad_scheduler_or_workers(bad, capsys, trace_blocks):
    assert main([*trace_blocks[:-1], "--rays", "100", *bad]) == 2
    err = capsys.readouterr().err
    assert re.search(r"unknown scheduler 'gpu'|workers must be >= 1, got 0", err)


# ----------------------------------------------------------- the cluster, not open to the network
#
# The dask cluster is not open to the network.
#
# * ``local`` binds every listening socket (scheduler, its HTTP server, workers, nannies) to
#   127.0.0.1 and starts no dashboard unless asked: checked with psutil in a child process,
#   so that sockets of other tests cannot mix in.
# * ``tls://``: a cluster with mutual TLS (certificates made here with the ``openssl``
#   command) gives the serial numbers for a batch fit and a trace, reached through
#   :func:`labbrdf.parallel.configure` (the CLI's ``--tls-*``) and through the dask config;
#   a client without a certificate is refused.
# * a ``tcp://`` address of another host prints a warning that it is unauthenticated.

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture
def reset_parallel_options() -> Any:
    options = parallel.options._OPTIONS
    saved = dict(options)
    yield
    parallel.shutdown()
    options.clear()
    options.update(saved)


LISTEN = textwrap.dedent(
    """
    import json, os, socket, sys
    import psutil
    from labbrdf import parallel

    def http(port):
        # what a plain HTTP request to 127.0.0.1:port gets back (bounded waits)
        try:
            with socket.create_connection(("127.0.0.1", port), timeout=3) as s:
                s.settimeout(3)
                s.sendall(b"GET /health HTTP/1.0\\r\\nHost: 127.0.0.1\\r\\n\\r\\n")
                return s.recv(64).decode("latin-1")
        except OSError:
            return ""

    def blocked(_):
        import signal
        return signal.SIGINT in signal.pthread_sigmask(signal.SIG_BLOCK, [])

    def main():
        assert parallel.run(abs, [-1, 2], scheduler="local", workers=2) == [1, 2]
        client = parallel.cluster._LOCAL["client"]
        deaf = parallel.run(blocked, [0, 1], scheduler="local", workers=2)
        if os.environ.get("RESTART_A_WORKER"):  # a worker restarted by its nanny
            client.restart_workers([sorted(client.scheduler_info()["workers"])[0]])
            client.wait_for_workers(2, timeout=60)
            assert parallel.run(abs, [-3], scheduler="local", workers=2) == [3]
        me = psutil.Process()
        listen = []
        for p in [me, *me.children(recursive=True)]:
            for c in p.net_connections(kind="inet"):
                if c.status == psutil.CONN_LISTEN:
                    port = c.laddr.port
                    listen.append([p.pid, c.laddr.ip, port, http(port)])
        info = client.scheduler_info()
        addresses = [info["address"]]
        for w, v in info["workers"].items():
            addresses += [w, v.get("nanny")]
        print(json.dumps({"listen": listen, "addresses": addresses, "deaf": deaf,
                          "services": info.get("services", {}),
                          "pids": len(me.children(recursive=True))}))
        parallel.shutdown()

    if __name__ == "__main__":
        main()
    """
)


def _run_listen(env_extra: dict[str, str]) -> dict[str, Any]:
    pytest.importorskip("psutil")
    env = {**os.environ, "PYTHONPATH": str(ROOT), **env_extra}
    r = subprocess.run(
        [sys.executable, "-c", LISTEN], capture_output=True, text=True, env=env, timeout=180
    )
    assert r.returncode == 0, r.stderr[-2000:]
    return json.loads(r.stdout.strip().splitlines()[-1])


@pytest.mark.usefixtures("dask_ok", "reset_parallel_options")
def test_local_cluster_listens_on_loopback_only_and_no_port_answers_http():
    # one worker is restarted by its nanny first: a new worker must be as closed
    info = _run_listen({"LABBRDF_DASK_DASHBOARD": "", "RESTART_A_WORKER": "1"})
    assert info["pids"] >= 2  # the worker processes were inspected too
    assert len(info["listen"]) >= 5, info  # scheduler, 2 nannies, 2 workers: all probed
    for pid, ip, port, _ in info["listen"]:
        assert ip == "127.0.0.1", f"pid {pid} listens on {ip}:{port}"
    for a in info["addresses"]:
        assert a.startswith("tls://127.0.0.1:"), a  # TLS even without certificates
    # dask starts an HTTP server (/health, /metrics, /info, no authentication) on the
    # scheduler and on every worker, dashboard or not: none may be left answering
    answered = [(pid, port, got) for pid, _, port, got in info["listen"] if "HTTP" in got]
    assert answered == []
    # workers ignore the terminal's Ctrl-C (this process closes them): no traceback each
    assert info["deaf"] == [True, True]


@pytest.mark.usefixtures("dask_ok", "reset_parallel_options")
def test_dashboard_only_when_asked_and_on_loopback():
    pytest.importorskip("bokeh")
    info = _run_listen({"LABBRDF_DASK_DASHBOARD": "1"})
    port = info["services"]["dashboard"]
    assert any(ip == "127.0.0.1" and p == port for _, ip, p, _ in info["listen"])
    for _, ip, _, _ in info["listen"]:
        assert ip == "127.0.0.1"
    # the dashboard, asked for, is the one port that answers HTTP
    assert [p for _, _, p, got in info["listen"] if "HTTP" in got] == [port]


# --------------------------------------------------------------------------- TLS


@pytest.fixture(scope="module")
def certs(tmp_path_factory) -> dict[str, str]:
    """A CA and one certificate it signed (for 127.0.0.1/localhost), made with openssl."""
    if shutil.which("openssl") is None:
        pytest.skip("the openssl command is not installed")
    d = tmp_path_factory.mktemp("tls")

    def ossl(*args: str) -> None:
        subprocess.run(["openssl", *args], cwd=d, check=True, capture_output=True, timeout=60)

    days = ["-days", "2"]
    ossl("req", "-x509", "-newkey", "rsa:2048", "-nodes", *days, "-subj", "/CN=labbrdf CA",
         "-keyout", "ca.key", "-out", "ca.pem")  # fmt: skip
    ossl("req", "-newkey", "rsa:2048", "-nodes", "-subj", "/CN=localhost",
         "-keyout", "node.key", "-out", "node.csr")  # fmt: skip
    (d / "ext.cnf").write_text(
        "subjectAltName=IP:127.0.0.1,DNS:localhost\nextendedKeyUsage=serverAuth,clientAuth\n"
    )
    ossl("x509", "-req", "-in", "node.csr", "-CA", "ca.pem", "-CAkey", "ca.key",
         "-CAcreateserial", *days, "-extfile", "ext.cnf", "-out", "node.pem")  # fmt: skip
    return {
        k: str(d / f) for k, f in (("ca", "ca.pem"), ("cert", "node.pem"), ("key", "node.key"))
    }


@pytest.fixture(scope="module")
def serial() -> tuple[Any, Any, Any]:
    frame = batch_frame(n_wl=2)
    return (
        frame,
        fit_many(frame, "smooth3", scheduler="serial", progress=False),
        trace(TRACE, map=builtins.map),
    )


def _tls_cluster(certs: dict[str, str]) -> Any:
    from distributed import LocalCluster
    from distributed.security import Security

    sec = Security(
        tls_ca_file=certs["ca"],
        tls_scheduler_cert=certs["cert"],
        tls_scheduler_key=certs["key"],
        tls_worker_cert=certs["cert"],
        tls_worker_key=certs["key"],
        tls_client_cert=certs["cert"],
        tls_client_key=certs["key"],
        require_encryption=True,
    )
    return LocalCluster(
        n_workers=2,
        threads_per_worker=1,
        processes=True,
        host="127.0.0.1",
        protocol="tls://",
        security=sec,
        dashboard_address=None,
        scheduler_kwargs={"dashboard": False, "dashboard_address": "127.0.0.1:0"},
    )


@pytest.mark.slow
@pytest.mark.usefixtures("dask_ok", "reset_parallel_options")
def test_tls_scheduler_gives_serial_numbers_and_refuses_a_client_without_certificate(
    certs, serial
):
    import functools

    frame, table0, trace0 = serial
    with _tls_cluster(certs) as cluster:
        addr = cluster.scheduler_address
        assert addr.startswith("tls://127.0.0.1:")
        # without certificates: a clear error before anything runs
        with pytest.raises(parallel.ParallelError, match="needs certificates"):
            parallel.run(abs, [1], scheduler=addr)
        # a client with no certificate cannot talk to the cluster
        from distributed import Client

        with pytest.raises(Exception):  # noqa: B017 - TLS handshake or timeout error
            Client(addr.replace("tls://", "tcp://"), timeout="3s", set_as_default=False)
        parallel.configure(tls_ca=certs["ca"], tls_cert=certs["cert"], tls_key=certs["key"])
        table = fit_many(frame, "smooth3", scheduler=addr, chunks=3, progress=False)
        assert_same_table(table0, table)
        res = trace(TRACE, map=functools.partial(parallel.imap, scheduler=addr))
        assert_same_trace(trace0, res)


@pytest.mark.slow
@pytest.mark.usefixtures("dask_ok", "reset_parallel_options")
def test_tls_from_the_dask_config_and_a_local_cluster_on_tls(certs, serial):
    import dask

    frame, table0, _ = serial
    cfg = {
        "distributed.comm.tls.ca-file": certs["ca"],
        "distributed.comm.tls.client.cert": certs["cert"],
        "distributed.comm.tls.client.key": certs["key"],
    }
    with dask.config.set(cfg):
        table = fit_many(frame, "smooth3", scheduler="local", workers=2, chunks=3, progress=False)
        info = parallel.cluster._LOCAL["client"].scheduler_info()
        assert info["address"].startswith("tls://127.0.0.1:")
        assert all(w.startswith("tls://127.0.0.1:") for w in info["workers"])
    assert_same_table(table0, table)


@pytest.mark.usefixtures("dask_ok", "reset_parallel_options")
def test_cli_tls_options_need_existing_files(tmp_path, capsys, specular_scan):
    argv = ["fit", str(specular_scan), "--model", "smooth3", "--scheduler", "tls://127.0.0.1:1"]
    assert main([*argv, "--tls-ca", str(tmp_path / "nope.pem"), "--tls-cert", "x"]) == 2
    assert "nope.pem" in capsys.readouterr().err
    assert main([*argv, "--tls-key", str(tmp_path / "k.pem")]) == 2
    assert "--tls-ca" in capsys.readouterr().err
    assert main(argv) == 2  # tls:// without certificates
    assert "needs certificates" in capsys.readouterr().err


# --------------------------------------------------------------------------- tcp


@pytest.mark.usefixtures("dask_ok", "reset_parallel_options")
def test_tcp_to_another_host_warns_that_it_is_unauthenticated(monkeypatch, capsys):
    class Refused:
        def __init__(self, *a: Any, **k: Any) -> None:
            raise OSError("connection refused")

    monkeypatch.setattr(parallel.cluster, "_import_dask", lambda: (Refused, None))
    with pytest.raises(parallel.ParallelError, match="cannot reach"):
        parallel.run(abs, [1], scheduler="tcp://192.0.2.7:8786")
    err = capsys.readouterr().err
    assert "WARNING" in err and "unauthenticated" in err and "tls://" in err
    with pytest.raises(parallel.ParallelError):
        parallel.run(abs, [1], scheduler="tcp://127.0.0.1:8786")
    assert "unauthenticated" not in capsys.readouterr().err  # this machine: no warning


# --------------------------------------------------------------------------- local on TLS
#
# ``local`` runs on mutual TLS with credentials made in memory for the cluster
# (Security.temporary): another user of the machine who finds the port can connect
# neither without credentials, nor over plain TCP, nor with credentials of their own.


def _identity(addr: str, connection_args: dict[str, Any]) -> dict[str, Any]:
    """Connect to a dask scheduler as a client would and ask who it is."""
    from distributed.comm import connect

    async def ask() -> dict[str, Any]:
        comm = await connect(addr, timeout="10s", **connection_args)
        try:
            await comm.write({"op": "identity"})
            return await comm.read()
        finally:
            await comm.close()

    return asyncio.run(ask())


@pytest.mark.usefixtures("dask_ok", "reset_parallel_options")
def test_local_cluster_is_tls_and_refuses_clients_without_its_credentials():
    import ssl

    from distributed.comm.core import CommClosedError
    from distributed.security import Security

    assert parallel.run(abs, [-1, 2], scheduler="local", workers=1) == [1, 2]
    cluster = parallel.cluster._LOCAL["cluster"]
    addr = cluster.scheduler_address
    assert addr.startswith("tls://127.0.0.1:"), addr
    info = parallel.cluster._LOCAL["client"].scheduler_info()
    assert info["workers"] and all(w.startswith("tls://127.0.0.1:") for w in info["workers"])
    own = cluster.security
    # the cluster's own credentials are answered (so the refusals below are about them)
    assert _identity(addr, own.get_connection_args("client"))["type"] == "Scheduler"
    # TLS that trusts the cluster's CA but shows no client certificate: refused
    ctx = ssl.create_default_context(cadata=own.tls_ca_file)
    ctx.check_hostname = False
    with pytest.raises(CommClosedError):
        _identity(addr, {"ssl_context": ctx, "require_encryption": True})
    # credentials of one's own (another user's temporary ones): refused
    with pytest.raises(CommClosedError):
        _identity(addr, Security.temporary().get_connection_args("client"))
    # plain TCP to the TLS port: refused
    with pytest.raises(CommClosedError):
        _identity(addr.replace("tls://", "tcp://"), {})


@pytest.mark.usefixtures("dask_ok", "reset_parallel_options")
def test_local_cluster_without_cryptography_says_how_to_install_it(monkeypatch):
    from distributed.security import Security

    def no_cryptography(cls: Any, **kw: Any) -> Any:
        raise ImportError("Using `Security.temporary` requires `cryptography`")

    parallel.shutdown()
    monkeypatch.setattr(Security, "temporary", classmethod(no_cryptography))
    with pytest.raises(ImportError, match=r"cryptography.*pip install cryptography"):
        parallel.run(abs, [1], scheduler="local", workers=1)
    assert "client" not in parallel.cluster._LOCAL
    # checked up front too (the CLI and validate call check_scheduler before any work)
    monkeypatch.setitem(sys.modules, "cryptography", None)
    with pytest.raises(ImportError, match=r"pip install cryptography"):
        parallel.check_scheduler("local")
    assert parallel.check_scheduler("serial") == "serial"


# --------------------------------------------------------------------------- no workers


@pytest.fixture
def workerless_scheduler() -> Any:
    """A dask scheduler on 127.0.0.1 (in this process) with no worker attached."""
    pytest.importorskip("dask.distributed")
    from distributed import LocalCluster

    with LocalCluster(
        n_workers=0,
        processes=False,
        host="127.0.0.1",
        protocol="tcp://",
        dashboard_address=None,
        scheduler_kwargs={"dashboard": False, "dashboard_address": "127.0.0.1:0"},
    ) as cluster:
        yield cluster.scheduler_address


@pytest.mark.usefixtures("reset_parallel_options")
def test_scheduler_without_workers_fails_after_the_timeout_naming_the_address(
    workerless_scheduler,
):
    addr = workerless_scheduler
    parallel.configure(worker_timeout=1.0)
    t0 = time.perf_counter()
    with pytest.raises(ParallelError) as exc:
        parallel.run(abs, [1, 2], scheduler=addr)
    assert time.perf_counter() - t0 < 30
    msg = str(exc.value)
    assert addr in msg and "no worker" in msg and "within 1 s" in msg
    assert f"dask worker {addr}" in msg and "--worker-timeout" in msg


@pytest.mark.usefixtures("reset_parallel_options")
def test_cli_scheduler_without_workers_exits_2_with_the_address(
    workerless_scheduler, frame, tmp_path, capsys
):
    addr = workerless_scheduler
    data = _write_dataset(frame, tmp_path)
    out = tmp_path / "t.csv"
    argv = ["fit", data, "--model", "smooth3", "-o", str(out), "--scheduler", addr]
    assert main([*argv, "--worker-timeout", "1"]) == 2
    err = capsys.readouterr().err
    assert f"labbrdf fit: the dask scheduler {addr} has no worker" in err
    assert "Traceback" not in err and not out.exists()


def test_default_worker_timeout_is_a_minute():
    assert parallel.DEFAULT_WORKER_TIMEOUT == 60.0
    assert parallel.options._OPTIONS.get("worker_timeout") is None  # the default applies


@pytest.mark.parametrize("bad", ["0", "-1", "nan", "inf"])
@pytest.mark.usefixtures("reset_parallel_options")
def test_bad_worker_timeout_is_refused(bad, capsys, specular_scan):
    argv = ["fit", str(specular_scan), "--model", "smooth3", "--scheduler", "serial"]
    assert main([*argv, "--worker-timeout", bad]) == 2
    assert "--worker-timeout: expected a finite number of seconds > 0" in capsys.readouterr().err
    with pytest.raises(ValueError, match="worker-timeout"):
        parallel.configure(worker_timeout=float(bad))
