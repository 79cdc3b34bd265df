"""One way to run a list of independent tasks: serially, on local processes, or on dask.

>>> from labbrdf import parallel
>>> parallel.Executor("serial").map(abs, [-1, -2, 3])
[1, 2, 3]

An :class:`Executor` names where tasks run (scheduler, worker count, the dask security and
timeout options); batch fits, tracer runs and reports all take one, and the CLI builds one
from its options (``--scheduler``, ``--workers``, ``--tls-*``, ``--worker-timeout``,
``--dashboard``). :func:`as_executor` turns None or a scheduler string into one, so that a
Python caller may still write ``scheduler="serial"``. :func:`run` and :func:`imap` are the
same runs with the options spelt out.

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
    processes are attached to it (they need labbrdf installed). A scheduler with no worker
    is waited for at most ``worker_timeout`` seconds (:func:`configure`, ``labbrdf
    --worker-timeout``, default :data:`DEFAULT_WORKER_TIMEOUT`), then the run fails with
    :class:`ParallelError` naming the address: tasks sent to a scheduler without workers
    would wait forever.

Security
--------
Whoever can connect to a dask scheduler can run any code on every worker. ``local`` binds
the scheduler, the workers and their nannies to ``127.0.0.1``, and leaves no port that
answers HTTP: dask's HTTP servers on the scheduler and on every worker (``/health``,
``/metrics``, ``/info``, unauthenticated) are started without routes and closed once the
cluster is up, unless the dashboard is asked for (:func:`configure` ``dashboard=True``,
``labbrdf --dashboard`` or ``LABBRDF_DASK_DASHBOARD=1``; the scheduler's then listens on
``127.0.0.1:8787`` or a free port). A cluster that does not start raises
:class:`ParallelError`; its worker processes ignore the terminal's Ctrl-C, which interrupts
this process, and it closes them.
Loopback alone does not keep out the other users of a shared machine, so ``local`` always
runs on mutual TLS: with the certificates configured below, or else with temporary
credentials that dask makes in memory for this cluster
(``distributed.security.Security.temporary()``, which needs the ``cryptography`` package):
a self-signed CA and key that exist only in this process and its workers, so no other
process can connect. A ``tcp://`` address is neither authenticated nor encrypted: a remote
one prints a warning. ``tls://`` uses dask's mutual TLS: the CA, certificate and key come
from :func:`configure` (``labbrdf --tls-ca/--tls-cert/--tls-key``) or from the dask config
``distributed.comm.tls.*``.

Results always come back in the order of the items, so a computation whose tasks carry
their own seeds gives the same numbers whatever the scheduler and the worker count.
A worker that dies makes dask run the task again on another worker (up to ``retries``
times); on a process pool, or when the retries are used up, the run fails with
:class:`ParallelError` and returns nothing: never a silent partial result.

The ``local`` LocalCluster is started once and reused by later calls with the same
``workers`` and ``retries`` (starting one costs seconds, a tracer sweep calls the executor
once per configuration); :func:`shutdown` closes it, and it is closed at interpreter exit.
A process pool is started per call (about 20 ms with ``fork``), so every call sees the
parent's state at that moment.

Notes
-----
On a ``tcp://`` cluster the number of runs a task gets after worker deaths is the remote
scheduler's ``distributed.scheduler.allowed-failures`` (dask's default 3), not ``retries``.
``local`` workers are started without dask's default ``MALLOC_TRIM_THRESHOLD_=65536``,
which made NumPy-heavy tracer blocks 3x slower on dask workers than in a process pool.

This module imports nothing from labbrdf but :mod:`labbrdf.errors`, so every layer may use it.
"""

from __future__ import annotations

import asyncio
import atexit
import functools
import os
import sys
import threading
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

from . import progress
from .errors import LabbrdfError

__all__ = [
    "DEFAULT_SCHEDULER",
    "DEFAULT_WORKER_TIMEOUT",
    "SCHEDULERS",
    "Executor",
    "ParallelError",
    "Progress",
    "as_executor",
    "check_scheduler",
    "configure",
    "imap",
    "run",
    "shutdown",
]

T = TypeVar("T")
R = TypeVar("R")

#: the scheduler names besides ``tcp://`` / ``tls://`` addresses
SCHEDULERS = ("serial", "processes", "local")

#: the scheduler of an :class:`Executor` (and of :func:`run`, :func:`imap`) when none is named
DEFAULT_SCHEDULER = "processes"

#: how long a run waits for a worker on a ``tcp://`` / ``tls://`` scheduler that has none [s]
DEFAULT_WORKER_TIMEOUT = 60.0

_DASK_HINT = (
    "the dask schedulers need dask.distributed: install it with "
    "`pip install labbrdf[dask]` (or `pip install 'dask[distributed]'`)"
)


_CRYPTOGRAPHY_HINT = (
    "the local dask cluster runs on TLS and needs the cryptography package to make its "
    "temporary credentials: `pip install cryptography` (or `pip install labbrdf[dask]`), "
    "or configure certificates (--tls-ca, --tls-cert, --tls-key)"
)


class ParallelError(LabbrdfError, RuntimeError):
    """A worker died (retries used up) or the dask scheduler is unreachable.

    No partial result is returned.
    """


def _import_dask() -> tuple[Any, Any]:
    try:
        from dask.distributed import Client, LocalCluster
    except ImportError as exc:
        raise ImportError(_DASK_HINT) from exc
    return Client, LocalCluster


def check_scheduler(scheduler: str) -> str:
    """Validate a scheduler name and return it.

    Raises
    ------
    ValueError
        For anything but ``serial``, ``processes``, ``local`` or a ``tcp://``/``tls://``
        address.
    ImportError
        For a dask scheduler (``local``, an address) when dask.distributed is not
        installed, or for ``local`` without certificates when the ``cryptography``
        package (its temporary TLS credentials) is missing; the message says how to
        install it.
    """
    if not isinstance(scheduler, str):
        raise ValueError(f"scheduler must be a string, got {type(scheduler).__name__}")
    if scheduler in ("serial", "processes"):
        return scheduler
    if scheduler == "local" or scheduler.startswith(("tcp://", "tls://")):
        _import_dask()
        if scheduler == "local" and _tls_files() is None:
            try:
                import cryptography  # noqa: F401 - the temporary TLS credentials need it
            except ImportError as exc:
                raise ImportError(_CRYPTOGRAPHY_HINT) from exc
        return scheduler
    raise ValueError(
        f"unknown scheduler {scheduler!r}; use one of {list(SCHEDULERS)} "
        "or a dask scheduler address such as tcp://host:8786"
    )


#: options of the dask schedulers, set by :func:`configure`
_OPTIONS: dict[str, Any] = {"dashboard": None, "tls": None, "worker_timeout": None}

_LOOPBACK = ("127.0.0.1", "localhost", "[::1]", "::1")


def configure(
    *,
    dashboard: bool | None = None,
    tls_ca: str | os.PathLike[str] | None = None,
    tls_cert: str | os.PathLike[str] | None = None,
    tls_key: str | os.PathLike[str] | None = None,
    worker_timeout: float | None = None,
) -> None:
    """Set the dask options of this process (the CLI calls it from its flags).

    Parameters
    ----------
    dashboard : bool, optional
        Start the ``local`` cluster's dashboard on 127.0.0.1 (default: off, or on when the
        environment has ``LABBRDF_DASK_DASHBOARD=1``).
    tls_ca, tls_cert, tls_key : path-like, optional
        PEM files for mutual TLS: the CA that signed every cluster certificate, and this
        process's certificate and key (the key may be inside the certificate file). Used
        for ``tls://`` addresses and, when given, for the ``local`` cluster as well
        (otherwise ``local`` makes temporary credentials of its own).
    worker_timeout : float, optional
        How long to wait for a worker on a ``tcp://`` / ``tls://`` scheduler that has none
        [s] (default :data:`DEFAULT_WORKER_TIMEOUT`).

    Raises
    ------
    ValueError
        A certificate option without ``tls_ca`` and ``tls_cert``, a file that does not
        exist, or a ``worker_timeout`` that is not a finite number > 0.
    """
    if worker_timeout is not None:
        t = float(worker_timeout)
        if not (t > 0 and t < float("inf")):
            raise ValueError(
                f"--worker-timeout: expected a finite number of seconds > 0, got {t:g}"
            )
        _OPTIONS["worker_timeout"] = t
    if dashboard is not None:
        _OPTIONS["dashboard"] = bool(dashboard)
    if tls_ca is None and tls_cert is None and tls_key is None:
        return
    if tls_ca is None or tls_cert is None:
        raise ValueError("TLS needs at least --tls-ca and --tls-cert (and --tls-key)")
    files = {"--tls-ca": tls_ca, "--tls-cert": tls_cert, "--tls-key": tls_key}
    for opt, f in files.items():
        if f is not None and not os.path.isfile(f):
            raise ValueError(f"{opt} {f}: no such file; expected a PEM file")
    _OPTIONS["tls"] = {k: (os.fspath(v) if v is not None else None) for k, v in files.items()}


def _dashboard_wanted() -> bool:
    if _OPTIONS["dashboard"] is not None:
        return bool(_OPTIONS["dashboard"])
    return os.environ.get("LABBRDF_DASK_DASHBOARD", "").strip().lower() in ("1", "true", "yes")


def _security() -> Any | None:
    """Build the dask Security from :func:`configure`, else from the dask config.

    The config keys are ``distributed.comm.tls.*``; None when neither names a CA and a
    certificate.
    """
    from distributed.security import Security

    files = _tls_files()
    if files is None:
        return None
    ca, cert, key = files
    return Security(
        tls_ca_file=ca,
        tls_client_cert=cert,
        tls_client_key=key,
        tls_scheduler_cert=cert,
        tls_scheduler_key=key,
        tls_worker_cert=cert,
        tls_worker_key=key,
        require_encryption=True,
    )


def _temporary_security() -> Any:
    """Mutual-TLS credentials made in memory for one ``local`` cluster.

    A self-signed certificate and key that only this process holds (dask passes them to
    the workers it starts); nothing is written to disk.

    Raises
    ------
    ImportError
        The ``cryptography`` package is missing (the message says how to install it).
    """
    from distributed.security import Security

    try:
        return Security.temporary()
    except ImportError as exc:
        raise ImportError(_CRYPTOGRAPHY_HINT) from exc


def _tls_files() -> tuple[str, str, str | None] | None:
    """(CA, certificate, key) from :func:`configure`, else from the dask config."""
    tls = _OPTIONS["tls"]
    if tls is not None:
        return tls["--tls-ca"], tls["--tls-cert"], tls["--tls-key"]
    import dask

    get = functools.partial(dask.config.get, default=None)
    ca = get("distributed.comm.tls.ca-file")
    cert = get("distributed.comm.tls.client.cert") or get("distributed.comm.tls.scheduler.cert")
    key = get("distributed.comm.tls.client.key") or get("distributed.comm.tls.scheduler.key")
    if ca and cert:
        return ca, cert, key
    return None


def _host(address: str) -> str:
    rest = address.split("://", 1)[1]
    if rest.startswith("["):
        return rest[: rest.find("]") + 1]
    return rest.rsplit(":", 1)[0] if ":" in rest else rest


def _warn(msg: str) -> None:
    sys.stderr.write(f"labbrdf: WARNING: {msg}\n")
    sys.stderr.flush()


#: the most worker processes this machine starts (``processes``, ``local``), per core:
#: each is a Python with NumPy and its own tracer tables (about 100 MB), so a count far
#: beyond the cores buys no speed and can exhaust memory. A remote scheduler's count is not
#: capped: its workers run elsewhere
MAX_WORKERS_PER_CORE = 4


def _workers(workers: int | None, scheduler: str | None = None) -> int:
    if workers is None:
        return max(1, os.cpu_count() or 1)
    if int(workers) < 1:
        raise ValueError(f"workers must be >= 1, got {workers}")
    cap = MAX_WORKERS_PER_CORE * max(1, os.cpu_count() or 1)
    if scheduler in ("processes", "local") and int(workers) > cap:
        raise ValueError(
            f"workers must be at most {cap} ({MAX_WORKERS_PER_CORE} per core) on this "
            f"machine, got {workers}"
        )
    return int(workers)


class Progress:
    """Counts finished tasks (from any worker) on the one progress line of :mod:`labbrdf.progress`.

    The line of the running command when one is shown, else its own: redrawn in place on a
    terminal, silent elsewhere (pipes, CI logs). ``enabled=False`` makes it silent.
    """

    def __init__(self, total: int, desc: str = "", enabled: bool = True, stream: Any = None):
        self.total = int(total)
        self.desc = desc or "tasks"
        self.enabled = bool(enabled) and self.total > 0
        self.done = 0
        outer = progress.active()
        self._own = outer is None
        self._line = outer or progress.ProgressLine("labbrdf", stream=stream, enabled=enabled)
        if self.enabled and self._line.enabled:  # what runs, before the first task ends
            self._line.update(phase=self.desc, done=0, total=self.total)

    def update(self, n: int = 1) -> None:
        """Count ``n`` more finished tasks and show the progress (when enabled)."""
        self.done += n
        if not (self.enabled and self._line.enabled):
            return
        self._line.update(phase=self.desc, done=self.done, total=self.total)
        if self._own and self.done >= self.total:
            self._line.clear()


#: the reusable LocalCluster: {"key": (workers, retries, tls files, dashboard), "client": ...}
_LOCAL: dict[str, Any] = {}
_LOCAL_LOCK = threading.Lock()
_ATEXIT: list[bool] = []


def shutdown() -> None:
    """Close the reusable ``local`` LocalCluster, if one is running (also done at exit)."""
    with _LOCAL_LOCK:
        client, cluster = _LOCAL.pop("client", None), _LOCAL.pop("cluster", None)
        _LOCAL.clear()
    for obj in (client, cluster):
        if obj is not None:
            try:
                obj.close()
            except Exception:  # noqa: BLE001, S110 - closing at exit, nothing left to report
                pass


def _dask_client(scheduler: str, workers: int | None, retries: int) -> tuple[Any, bool]:
    """A Client for ``scheduler`` and whether the caller must close it.

    ``local``: the reusable LocalCluster whose scheduler lets a task survive ``retries``
    worker deaths (``allowed_failures``). ``tcp://``: a new Client; the remote scheduler's
    own ``distributed.scheduler.allowed-failures`` setting decides the retries there.
    """
    Client, LocalCluster = _import_dask()
    if scheduler != "local":
        kw: dict[str, Any] = {}
        if scheduler.startswith("tls://"):
            sec = _security()
            if sec is None:
                raise ParallelError(
                    f"{scheduler}: a tls:// scheduler needs certificates: --tls-ca, "
                    "--tls-cert and --tls-key (or the dask config distributed.comm.tls.*)"
                )
            kw["security"] = sec
        elif _host(scheduler) not in _LOOPBACK:
            _warn(
                f"{scheduler} is an unauthenticated, unencrypted connection: anyone who can "
                "reach that port can run code on every worker and read the data. Use "
                "tls:// with certificates, or a scheduler on a trusted network only."
            )
        try:
            client = Client(scheduler, set_as_default=False, **kw)
        except OSError as exc:  # refused, timed out, unknown host
            raise ParallelError(
                f"cannot reach the dask scheduler {scheduler} ({exc}); start one with "
                "`dask scheduler` and attach workers with `dask worker <address>`"
            ) from exc
        _wait_for_a_worker(client, scheduler)
        return client, True
    sec = _security()
    dash = _dashboard_wanted()
    key = (_workers(workers, "local"), int(retries), _tls_files(), dash)
    with _LOCAL_LOCK:
        client = _LOCAL.get("client")
        if client is not None and _LOCAL.get("key") == key and client.status == "running":
            return client, False
    shutdown()
    if sec is None:
        sec = _temporary_security()
    import dask

    # dask's nannies start workers with MALLOC_TRIM_THRESHOLD_=65536, which makes glibc
    # mmap every array over 128 kB afresh: a tracer block then takes 3x longer (71 against
    # 24 ms measured). Our workers run NumPy-heavy tasks: start them without it (and drop
    # it from os.environ where an earlier nanny left dask's value).
    env = dict(dask.config.get("distributed.nanny.pre-spawn-environ", {}))
    trim = env.pop("MALLOC_TRIM_THRESHOLD_", None)
    if trim is not None and os.environ.get("MALLOC_TRIM_THRESHOLD_") == str(trim):
        del os.environ["MALLOC_TRIM_THRESHOLD_"]
    client, cluster = _start_local(Client, LocalCluster, key, sec, env, dash)
    with _LOCAL_LOCK:
        _LOCAL.update(key=key, client=client, cluster=cluster)
        if not _ATEXIT:
            # registered after distributed's own exit hooks, so it runs before them
            atexit.register(shutdown)
            _ATEXIT.append(True)
    return client, False


def _start_local(
    Client: Any, LocalCluster: Any, key: tuple, sec: Any, env: dict, dash: bool
) -> tuple[Any, Any]:
    """Start the ``local`` LocalCluster and its Client; ParallelError if it cannot start.

    Everything listens on the loopback interface, on TLS. dask always starts an HTTP
    server on the scheduler and on each worker (``/health``, ``/metrics``, ``/info``,
    without authentication): the workers' are started with no route
    (``distributed.worker.http.routes``) and then closed (:func:`_close_http`), and so is
    the scheduler's unless its dashboard is asked for.

    Raises
    ------
    ParallelError
        The cluster did not start (a worker that died at start-up, a port that could not
        be bound, a timeout): the message says why; anything started is closed.
    KeyboardInterrupt
        Ctrl-C during start-up, after closing whatever had started.
    """
    import dask

    # workers never serve HTTP; the scheduler only when its dashboard is asked for
    config: dict[str, Any] = {
        "distributed.nanny.pre-spawn-environ": env,
        "distributed.nanny.preload": [
            *dask.config.get("distributed.nanny.preload", []),
            __name__,  # dask_setup below: workers start deaf to Ctrl-C
        ],
        "distributed.worker.http.routes": [],
    }
    if not dash:
        config["distributed.scheduler.http.routes"] = []
    cluster = client = None
    before = _spec_clusters()
    try:
        with dask.config.set(config):
            cluster = LocalCluster(
                n_workers=key[0],
                threads_per_worker=1,
                processes=True,
                host="127.0.0.1",
                dashboard_address="127.0.0.1:8787" if dash else None,
                # each worker's own HTTP server: older distributed releases (2024.8) bind it
                # to 0.0.0.0 unless told
                worker_dashboard_address="127.0.0.1:0",
                scheduler_kwargs={
                    "allowed_failures": key[1],
                    "dashboard": dash,
                    "dashboard_address": "127.0.0.1:8787" if dash else "127.0.0.1:0",
                },
                security=sec,
                protocol="tls://",
            )
            client = Client(cluster, set_as_default=False, security=sec)
            _close_http(client, scheduler=not dash)
    except BaseException as exc:
        # the cluster, or (interrupted inside its constructor) the half-started one
        started = [client, cluster, *(_spec_clusters() - before)]
        _close_quietly([obj for obj in started if obj is not None])
        if isinstance(exc, (KeyboardInterrupt, SystemExit, GeneratorExit)):
            raise
        raise ParallelError(
            f"the local dask cluster did not start ({type(exc).__name__}: {exc}); "
            "nothing was run. Check free memory and that labbrdf imports in a fresh "
            "Python, or use --scheduler processes"
        ) from exc
    if dash:
        _warn(f"dask dashboard (no authentication, this machine only): {client.dashboard_link}")
    return client, cluster


def dask_setup(nanny: Any) -> None:
    """Nanny preload of the ``local`` cluster: its worker processes ignore Ctrl-C.

    Called by dask on the event-loop thread before the nanny starts its worker process. It
    blocks SIGINT in that thread (Python handles signals in the main thread only, so this
    changes nothing here); the threads that start worker processes and the processes
    themselves inherit the blocked signal. A Ctrl-C in the terminal, which reaches every
    process of the group, then interrupts this process alone, which closes the cluster,
    instead of printing a traceback from each worker that was still starting.
    """
    import signal
    from multiprocessing import resource_tracker

    # started first: starting it later would unblock SIGINT in the starting thread
    resource_tracker.ensure_running()
    signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})


def _spec_clusters() -> set[Any]:
    """The dask clusters of this process (a constructor that fails leaves one behind)."""
    from distributed.deploy.spec import SpecCluster

    return set(SpecCluster._instances)


def _close_quietly(objs: list[Any]) -> None:
    """Close clients and clusters of a failed or interrupted start-up, saying nothing.

    A cluster interrupted while its workers start cannot close cleanly (dask asserts on
    the workers' state); it is not closed again at exit, where dask would print that.
    """
    for obj in objs:
        try:
            obj.close(timeout=10)
        except BaseException:  # noqa: BLE001, S110 - already failing; the cause is reported
            pass
        if hasattr(obj, "shutdown_on_close"):
            obj.shutdown_on_close = False


def _stop_scheduler_http(dask_scheduler: Any) -> None:
    """Stop the scheduler's HTTP server from listening (run on the scheduler)."""
    dask_scheduler.http_server.stop()


def _no_http_plugin() -> Any:
    """A worker plugin that stops each worker's HTTP server (restarted workers too)."""
    from distributed.diagnostics.plugin import WorkerPlugin

    class NoHTTP(WorkerPlugin):  # defined here: dask sends it to the workers by value
        name = "labbrdf-no-http"

        def setup(self, worker: Any) -> None:
            worker.http_server.stop()

    return NoHTTP()


def _close_http(client: Any, scheduler: bool) -> None:
    """Close the HTTP servers of the ``local`` cluster's workers, and of its scheduler.

    The workers' through a plugin, so that a worker restarted later is closed too; the
    scheduler's only when ``scheduler`` (not when its dashboard was asked for).
    """
    if scheduler:
        client.run_on_scheduler(_stop_scheduler_http)
    client.register_plugin(_no_http_plugin())


def _wait_for_a_worker(client: Any, scheduler: str) -> None:
    """Wait up to the configured worker timeout for one worker; else close and fail.

    Raises
    ------
    ParallelError
        No worker attached to ``scheduler`` within the timeout (the client is closed).
    """
    timeout = _OPTIONS["worker_timeout"] or DEFAULT_WORKER_TIMEOUT
    try:
        client.wait_for_workers(1, timeout=timeout)
    except TimeoutError:  # asyncio.TimeoutError is TimeoutError since Python 3.11
        client.close()
        raise ParallelError(
            f"the dask scheduler {scheduler} has no worker: none attached within "
            f"{timeout:g} s. Start workers with `dask worker {scheduler}` (they need labbrdf "
            "installed), or wait longer with --worker-timeout SECONDS"
        ) from None


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
