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

The package's modules: :mod:`~labbrdf.parallel.options` (scheduler names and dask options),
:mod:`~labbrdf.parallel.cluster` (the dask clients), :mod:`~labbrdf.parallel.executor` (the
runs). It imports nothing from labbrdf but :mod:`labbrdf.errors` and :mod:`labbrdf.progress`,
so every layer may use it.
"""

from __future__ import annotations

from .cluster import shutdown
from .executor import Executor, as_executor, imap, run
from .options import (
    DEFAULT_SCHEDULER,
    DEFAULT_WORKER_TIMEOUT,
    MAX_WORKERS_PER_CORE,
    SCHEDULERS,
    ParallelError,
    Progress,
    check_scheduler,
    configure,
)

__all__ = [
    "DEFAULT_SCHEDULER",
    "DEFAULT_WORKER_TIMEOUT",
    "MAX_WORKERS_PER_CORE",
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
