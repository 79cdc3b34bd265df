"""The executor layer: same results on every scheduler, truthful progress, loud failures."""

from __future__ import annotations

import io
import math
import os

import pytest

from labbrdf import parallel
from labbrdf.parallel import ParallelError, Progress


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


def test_progress_counts_every_task_once():
    buf = io.StringIO()
    bar = Progress(4, "fits", stream=buf)
    for _ in range(4):
        bar.update()
    lines = buf.getvalue().splitlines()
    assert lines[-1].startswith("fits: 4/4")
    assert bar.done == 4


def test_progress_across_workers_reaches_total(capsys):
    parallel.run(math.sqrt, range(7), scheduler="processes", workers=2, progress=True, desc="w")
    err = capsys.readouterr().err.splitlines()
    assert err[-1].startswith("w: 7/7")


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
