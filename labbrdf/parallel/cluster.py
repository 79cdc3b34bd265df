"""The dask clients: the reusable ``local`` cluster on loopback TLS, or a remote scheduler.

:func:`_dask_client` gives the Client of a scheduler (the ``local`` LocalCluster started
once by :func:`_start_local` and reused, closed by :func:`shutdown` and at exit), with the
HTTP servers closed unless the dashboard is asked for; :func:`dask_setup` is the workers'
preload (they ignore Ctrl-C).
"""

from __future__ import annotations

import atexit
import os
import threading
from typing import Any

from .options import (
    _LOOPBACK,
    _OPTIONS,
    DEFAULT_WORKER_TIMEOUT,
    ParallelError,
    _dashboard_wanted,
    _host,
    _import_dask,
    _security,
    _temporary_security,
    _tls_files,
    _warn,
    _workers,
)

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
