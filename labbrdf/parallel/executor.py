"""The runs: :func:`imap` / :func:`run` of a list of tasks, and :class:`Executor`, their options.

Serially, on a process pool (:func:`_imap_pool`) or on dask (:func:`_imap_dask`), with at
most a window of tasks in flight and the results yielded in item order.
"""

from __future__ import annotations

import asyncio
import os
import uuid
from collections import deque
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import (
    FIRST_COMPLETED,
    CancelledError,
    Future,
    ProcessPoolExecutor,
    wait,
)
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass, replace
from typing import Any, TypeVar

from .cluster import _dask_client
from .options import (
    DEFAULT_SCHEDULER,
    ParallelError,
    Progress,
    _workers,
    check_scheduler,
    configure,
)

T = TypeVar("T")


R = TypeVar("R")


def imap(
    func: Callable[[T], R],
    items: Iterable[T],
    *,
    scheduler: str = DEFAULT_SCHEDULER,
    workers: int | None = None,
    progress: bool = False,
    desc: str = "",
    retries: int = 2,
    window: int | None = None,
) -> Iterator[R]:
    """Apply ``func`` to each item on ``scheduler`` and yield the results in item order.

    At most ``window`` tasks are in flight (or finished but not yet yielded) at once, so the
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
        How many times dask runs a task again after its worker died (``local``; on a
        ``tcp://`` cluster the scheduler's ``allowed-failures`` setting decides). A task
        that *raises* is not retried: its exception propagates.
    window : int, optional
        Tasks in flight (or finished but not yet yielded) at once; it bounds the memory
        held by results. Default: ``2 * workers`` on a process pool, ``max(16, 4 x the
        cluster's worker threads)`` on dask, whose scheduler round trip is longer.

    Raises
    ------
    ParallelError
        A worker died (after dask's retries), or the dask scheduler cannot be reached:
        nothing partial is returned. An exception raised by a task propagates unchanged.
    ValueError
        Unknown scheduler, ``workers`` < 1, ``retries`` < 0 or ``window`` < 1.
    ImportError
        A dask scheduler without dask.distributed installed (the message says how to
        install it).
    """
    check_scheduler(scheduler)
    items = list(items)
    bar = Progress(len(items), desc, progress)
    if scheduler == "serial":
        for it in items:
            yield func(it)
            bar.update()
        return
    n = _workers(workers, scheduler)
    if window is not None and int(window) < 1:
        raise ValueError(f"window must be >= 1, got {window}")
    if scheduler == "processes":
        yield from _imap_pool(func, items, n, window or max(2 * n, 2), bar)
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
            if i in counted:
                counted.discard(i)
            else:  # finished between the count above and this check: count it now
                bar.update()
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


class _Box:
    """An opaque container that dask passes through without looking inside."""

    __slots__ = ("item",)

    def __init__(self, item: Any) -> None:
        self.item = item

    def __getstate__(self) -> Any:
        return self.item

    def __setstate__(self, state: Any) -> None:
        self.item = state


def _unbox_call(func: Callable[[Any], Any], box: _Box) -> Any:
    """Run ``func`` on a boxed item (module level: picklable by reference)."""
    return func(box.item)


def _imap_dask(
    func: Callable[[T], R],
    items: list[T],
    scheduler: str,
    workers: int | None,
    window: int | None,
    bar: Progress,
    retries: int,
) -> Iterator[R]:
    """Keep ``window`` unyielded tasks on the cluster; yield the results in item order.

    Results arrive through dask's ``as_completed`` (fetched in the background, batched).

    The default window, 4 per worker thread of the cluster and at least 16, hides the
    scheduler round trip (a few ms); tasks are submitted in batches of half a window.
    """
    if int(retries) < 0:
        raise ValueError(f"retries must be >= 0, got {retries}")
    client, own = _dask_client(scheduler, workers, retries)
    if window is None:
        window = max(16, 4 * sum(client.nthreads().values()))
    from distributed import KilledWorker, as_completed

    run_id = uuid.uuid4().hex[:12]
    index: dict[Any, int] = {}
    futures: list[Any] = []  # by item; None once yielded (the cluster may forget it)
    arrived: dict[int, tuple[bool, Any]] = {}
    stream = as_completed(loop=client.loop, with_results=True, raise_errors=False)

    # helpers, so that no local name outlives its future (a failed run's traceback keeps
    # this frame alive; the futures it names would keep their tasks on the cluster)
    def submit(start: int, stop: int) -> None:
        keys = [f"labbrdf-{run_id}-{i}" for i in range(start, stop)]
        # boxed: older dask (< 2024.12) executes any argument tuple whose first element is
        # callable as a task spec, and our items are tuples that may start with a model
        boxed = [_Box(it) for it in items[start:stop]]
        batch = client.map(_unbox_call, [func] * len(boxed), boxed, key=keys, pure=False)
        index.update({f.key: i for i, f in enumerate(batch, start=start)})
        futures.extend(batch)
        stream.update(batch)

    def receive() -> None:
        f, res = next(stream)
        bar.update()  # each task completes once, whichever worker (or retry) ran it
        if f.status == "finished":
            arrived[index[f.key]] = (True, res)
        else:  # "error": res is (type, exception, traceback); or cancelled
            exc = res[1].with_traceback(res[2]) if isinstance(res, tuple) else res
            arrived[index[f.key]] = (False, exc)

    nxt = got = 0
    try:
        while got < len(items):
            if nxt < len(items) and nxt - got <= window // 2:
                # refill in batches: one message to the scheduler per batch, not per task
                stop = min(len(items), got + window)
                submit(nxt, stop)
                nxt = stop
            while got not in arrived:
                receive()
            ok, value = arrived.pop(got)
            futures[got] = None  # let the cluster forget the result
            got += 1
            if ok:
                yield value
            elif isinstance(value, KilledWorker):
                raise ParallelError(
                    f"a dask worker died running a task and {retries} retries were used "
                    "up; the run is abandoned and no partial result is returned"
                ) from value
            elif isinstance(value, (asyncio.CancelledError, CancelledError)):
                raise ParallelError(
                    "a dask task was cancelled (scheduler restarted or lost?); the run is "
                    "abandoned and no partial result is returned"
                ) from value
            else:
                raise value
    finally:
        # an abandoned run (error, generator closed) leaves nothing on the cluster: tasks
        # not yet run are cancelled, results not yet yielded forgotten
        pending = [f for f in futures if f is not None]
        stream.clear()
        if pending and client.status == "running":
            client.cancel(pending)
        if own:
            client.close()


def run(
    func: Callable[[T], R],
    items: Iterable[T],
    *,
    scheduler: str = DEFAULT_SCHEDULER,
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


@dataclass(frozen=True)
class Executor:
    """Where a workflow's tasks run: one object passed to fits, traces and reports alike.

    Parameters
    ----------
    scheduler : str
        ``serial``, ``processes`` (default, :data:`DEFAULT_SCHEDULER`), ``local`` or a
        ``tcp://`` / ``tls://`` dask scheduler address (see the module docstring).
    workers : int, optional
        Worker processes (``processes``, ``local``); default: the core count.
    progress : bool
        Show a progress bar on stderr for each run.
    retries : int
        Runs of a task after its worker died (``local``; see :func:`imap`).
    dashboard : bool, optional
        Start the ``local`` cluster's dashboard on 127.0.0.1.
    tls_ca, tls_cert, tls_key : path-like, optional
        PEM files for mutual TLS (see :func:`configure`).
    worker_timeout : float, optional
        How long to wait for a worker on a ``tcp://`` / ``tls://`` scheduler [s].

    Raises
    ------
    ValueError
        An unknown scheduler, ``workers`` < 1, ``retries`` < 0, or a bad security or
        timeout option (:func:`configure`): at construction, before any work.
    ImportError
        A dask scheduler without dask.distributed (or ``local`` without ``cryptography``
        and without certificates); the message says what to install.

    Notes
    -----
    The dask options are those of this process (:func:`configure`): building an Executor
    with any of them set configures the process, so the last Executor built decides them.
    Results do not depend on the executor: every run returns its results in item order.
    """

    scheduler: str = DEFAULT_SCHEDULER
    workers: int | None = None
    progress: bool = False
    retries: int = 2
    dashboard: bool | None = None
    tls_ca: str | os.PathLike[str] | None = None
    tls_cert: str | os.PathLike[str] | None = None
    tls_key: str | os.PathLike[str] | None = None
    worker_timeout: float | None = None

    def __post_init__(self) -> None:
        # first the certificates: they decide what `local` needs (cryptography or not)
        configure(
            dashboard=self.dashboard,
            tls_ca=self.tls_ca,
            tls_cert=self.tls_cert,
            tls_key=self.tls_key,
            worker_timeout=self.worker_timeout,
        )
        check_scheduler(self.scheduler)
        if self.workers is not None:
            _workers(self.workers, self.scheduler)
        if int(self.retries) < 0:
            raise ValueError(f"retries must be >= 0, got {self.retries}")

    @property
    def serial(self) -> bool:
        """Whether tasks run in this process, in order."""
        return self.scheduler == "serial"

    @property
    def nworkers(self) -> int:
        """Worker processes a run is planned for (1 when serial; the core count by default)."""
        return 1 if self.serial else _workers(self.workers, self.scheduler)

    def imap(
        self,
        func: Callable[[T], R],
        items: Iterable[T],
        *,
        desc: str = "",
        window: int | None = None,
    ) -> Iterator[R]:
        """``func`` of each item, yielded in item order (see :func:`imap`)."""
        return imap(
            func,
            items,
            scheduler=self.scheduler,
            workers=self.workers,
            progress=self.progress,
            desc=desc,
            retries=self.retries,
            window=window,
        )

    def map(self, func: Callable[[T], R], items: Iterable[T], *, desc: str = "") -> list[R]:
        """``[func(it) for it in items]`` on this executor, as a list in item order."""
        return list(self.imap(func, items, desc=desc))

    def __call__(self, func: Callable[[T], R], items: Iterable[T]) -> Iterator[R]:
        """The ordered ``map(func, items)`` that :func:`labbrdf.tracer.trace` takes."""
        return self.imap(func, items)

    def with_progress(self, progress: bool) -> Executor:
        """The same executor with the progress bar switched on or off."""
        return replace(self, progress=bool(progress))


def as_executor(
    executor: Executor | str | None = None,
    *,
    scheduler: str | None = None,
    workers: int | None = None,
    progress: bool | None = None,
) -> Executor:
    """The :class:`Executor` a workflow runs on, from what its caller gave.

    Parameters
    ----------
    executor : Executor or str, optional
        An Executor (returned as it is, but for ``progress``), or a scheduler name.
    scheduler : str, optional
        The older keyword for a scheduler name (not together with ``executor``).
    workers : int, optional
        Worker processes, with a scheduler name or none (an Executor has its own).
    progress : bool, optional
        Progress bar on stderr (default: the Executor's setting; off for a name).

    Returns
    -------
    Executor
        None and no scheduler give ``Executor()``: :data:`DEFAULT_SCHEDULER`.

    Raises
    ------
    ValueError
        Both ``executor`` and ``scheduler``, ``workers`` with an Executor, something
        that is neither an Executor nor a string, or what :class:`Executor` refuses.
    ImportError
        As :class:`Executor` raises it.
    """
    if executor is not None and scheduler is not None:
        raise ValueError("give either an executor or a scheduler, not both")
    if isinstance(executor, Executor):
        if workers is not None:
            raise ValueError("workers: an Executor has its own worker count")
        return executor if progress is None else executor.with_progress(progress)
    spec = executor if executor is not None else scheduler
    if spec is not None and not isinstance(spec, str):
        raise ValueError(
            f"executor must be an Executor or a scheduler name, got {type(spec).__name__}"
        )
    return Executor(spec or DEFAULT_SCHEDULER, workers=workers, progress=bool(progress))
