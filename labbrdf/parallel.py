"""One way to run a list of independent tasks: serially, on local processes, or on dask.

>>> from labbrdf import parallel
>>> parallel.run(abs, [-1, -2, 3], scheduler="serial")
[1, 2, 3]

Schedulers
----------
``serial``
    In this process, in order. For debugging and for tiny jobs.
``processes`` (default)
    A :class:`concurrent.futures.ProcessPoolExecutor` with ``workers`` processes
    (default: the machine's core count).
``local``
    A ``dask.distributed.LocalCluster`` with ``workers`` single-threaded worker processes.
``tcp://host:port`` (or ``tls://``)
    A running ``dask scheduler``; the workers are whatever ``dask worker tcp://host:port``
    processes are attached to it (they need labbrdf installed).

Results always come back in the order of the items, so a computation whose tasks carry
their own seeds gives the same numbers whatever the scheduler and the worker count.
A worker that dies makes dask retry the task (``retries``); on a process pool, or when
the retries are used up, the run fails with :class:`ParallelError` and returns nothing:
never a silent partial result.

This module imports nothing from labbrdf, so every layer may use it.
"""

from __future__ import annotations

import os
import sys
import time
import uuid
from collections import deque
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from typing import Any, TypeVar

__all__ = ["SCHEDULERS", "ParallelError", "Progress", "check_scheduler", "imap", "run"]

T = TypeVar("T")
R = TypeVar("R")

#: the scheduler names besides ``tcp://`` / ``tls://`` addresses
SCHEDULERS = ("serial", "processes", "local")

_DASK_HINT = (
    "the dask schedulers need dask.distributed: install it with "
    "`pip install labbrdf[dask]` (or `pip install 'dask[distributed]'`)"
)


class ParallelError(RuntimeError):
    """A task or a worker failed; no partial result is returned."""


def check_scheduler(scheduler: str) -> str:
    """Validate a scheduler name and return it.

    Raises
    ------
    ValueError
        For anything but ``serial``, ``processes``, ``local`` or a ``tcp://``/``tls://``
        address.
    """
    if scheduler in SCHEDULERS or scheduler.startswith(("tcp://", "tls://")):
        return scheduler
    raise ValueError(
        f"unknown scheduler {scheduler!r}; use one of {list(SCHEDULERS)} "
        "or a dask scheduler address such as tcp://host:8786"
    )


def _workers(workers: int | None) -> int:
    if workers is None:
        return max(1, os.cpu_count() or 1)
    if int(workers) < 1:
        raise ValueError(f"workers must be >= 1, got {workers}")
    return int(workers)


class Progress:
    """A plain progress bar on stderr that counts finished tasks (from any worker).

    On a terminal it redraws one line; elsewhere (CI logs) it prints a line at each
    10% step. ``enabled=False`` makes it silent.
    """

    def __init__(self, total: int, desc: str = "", enabled: bool = True, stream: Any = None):
        self.total = int(total)
        self.desc = desc or "tasks"
        self.enabled = bool(enabled) and self.total > 0
        self.stream = stream if stream is not None else sys.stderr
        self.done = 0
        self._t0 = time.perf_counter()
        self._tty = bool(getattr(self.stream, "isatty", lambda: False)())
        self._last_decile = -1

    def update(self, n: int = 1) -> None:
        self.done += n
        if not self.enabled:
            return
        frac = self.done / self.total
        elapsed = time.perf_counter() - self._t0
        if self._tty:
            width = 30
            bar = "#" * int(frac * width)
            self.stream.write(
                f"\r{self.desc}: [{bar:<{width}}] {self.done}/{self.total} {elapsed:6.1f} s"
            )
            if self.done >= self.total:
                self.stream.write("\n")
        else:
            decile = int(frac * 10)
            if decile > self._last_decile or self.done >= self.total:
                self._last_decile = decile
                self.stream.write(f"{self.desc}: {self.done}/{self.total} ({elapsed:.1f} s)\n")
        self.stream.flush()


def _dask_client(scheduler: str, workers: int | None) -> tuple[Any, Any]:
    try:
        from dask.distributed import Client, LocalCluster
    except ImportError as exc:  # pragma: no cover - exercised only without the extra
        raise ImportError(_DASK_HINT) from exc
    if scheduler == "local":
        cluster = LocalCluster(
            n_workers=_workers(workers),
            threads_per_worker=1,
            processes=True,
            dashboard_address=None,
        )
        return Client(cluster), cluster
    return Client(scheduler), None


def imap(
    func: Callable[[T], R],
    items: Iterable[T],
    *,
    scheduler: str = "processes",
    workers: int | None = None,
    progress: bool = False,
    desc: str = "",
    retries: int = 2,
    window: int | None = None,
) -> Iterator[R]:
    """Apply ``func`` to each item on ``scheduler`` and yield the results in item order.

    At most ``window`` tasks (default ``2 * workers``) are in flight at once, so the
    caller can fold results as they arrive with bounded memory.

    Parameters
    ----------
    func : callable
        A module-level (picklable) function of one argument.
    items : iterable
        The task inputs.
    scheduler : str
        ``serial``, ``processes``, ``local`` or ``tcp://host:port``.
    workers : int, optional
        Worker processes (``processes``, ``local``); default: the core count.
    progress : bool
        Show a progress bar on stderr.
    desc : str
        Label of the progress bar.
    retries : int
        dask retries of a task whose worker died.
    window : int, optional
        Tasks in flight at once.

    Raises
    ------
    ParallelError
        A task raised, or a worker died (after dask's retries): nothing partial is returned.
    """
    check_scheduler(scheduler)
    items = list(items)
    bar = Progress(len(items), desc, progress)
    if scheduler == "serial":
        for it in items:
            yield func(it)
            bar.update()
        return
    n = _workers(workers)
    window = window or max(2 * n, 2)
    if scheduler == "processes":
        yield from _imap_pool(func, items, n, window, bar)
    else:
        yield from _imap_dask(func, items, scheduler, workers, window, bar, retries)


def _ordered(
    submit: Callable[[int], Future],
    n_items: int,
    window: int,
    bar: Progress,
    result: Callable[[Future], Any],
) -> Iterator[Any]:
    """Keep ``window`` futures in flight, count completions, yield results in order."""
    pending: deque[tuple[int, Future]] = deque()
    nxt = 0
    counted: set[int] = set()
    while nxt < n_items or pending:
        while nxt < n_items and len(pending) < window:
            pending.append((nxt, submit(nxt)))
            nxt += 1
        # progress counts every finished task, in whatever order workers finish them
        wait([f for _, f in pending], return_when=FIRST_COMPLETED)
        for i, f in pending:
            if f.done() and i not in counted:
                counted.add(i)
                bar.update()
        while pending and pending[0][1].done():
            i, f = pending.popleft()
            counted.discard(i)
            yield result(f)


def _imap_pool(
    func: Callable[[T], R], items: list[T], n: int, window: int, bar: Progress
) -> Iterator[R]:
    def result(f: Future) -> Any:
        try:
            return f.result()
        except BrokenProcessPool as exc:
            raise ParallelError(
                "a worker process died (killed or out of memory); the run is abandoned "
                "and no partial result is returned"
            ) from exc

    with ProcessPoolExecutor(max_workers=n) as ex:
        yield from _ordered(lambda i: ex.submit(func, items[i]), len(items), window, bar, result)


def _imap_dask(
    func: Callable[[T], R],
    items: list[T],
    scheduler: str,
    workers: int | None,
    window: int,
    bar: Progress,
    retries: int,
) -> Iterator[R]:
    from concurrent.futures import Future as CFuture

    client, cluster = _dask_client(scheduler, workers)
    run_id = uuid.uuid4().hex[:12]
    try:
        from distributed import KilledWorker

        def submit(i: int) -> CFuture:
            # bridge a dask future into a concurrent.futures one, so one ordering loop
            # serves every scheduler
            cf: CFuture = CFuture()
            df = client.submit(
                func, items[i], pure=False, retries=retries, key=f"labbrdf-{run_id}-{i}"
            )

            def done(d: Any) -> None:
                try:
                    cf.set_result(d.result())
                except BaseException as exc:  # noqa: BLE001 - re-raised in result()
                    cf.set_exception(exc)

            df.add_done_callback(done)
            cf.dask_future = df  # type: ignore[attr-defined]
            return cf

        def result(f: CFuture) -> Any:
            try:
                return f.result()
            except KilledWorker as exc:
                raise ParallelError(
                    f"a dask worker died running a task and {retries} retries were used "
                    "up; the run is abandoned and no partial result is returned"
                ) from exc

        yield from _ordered(submit, len(items), window, bar, result)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def run(
    func: Callable[[T], R],
    items: Iterable[T],
    *,
    scheduler: str = "processes",
    workers: int | None = None,
    progress: bool = False,
    desc: str = "",
    retries: int = 2,
) -> list[R]:
    """Apply ``func`` to every item and return the results as a list in item order.

    See :func:`imap` for the parameters. Exceptions raised by a task propagate unchanged
    (after the remaining tasks are cancelled); a dead worker gives :class:`ParallelError`.
    """
    return list(
        imap(
            func,
            items,
            scheduler=scheduler,
            workers=workers,
            progress=progress,
            desc=desc,
            retries=retries,
        )
    )
