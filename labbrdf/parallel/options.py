"""Where tasks may run and how: the scheduler names, worker counts and dask options.

:func:`check_scheduler` checks a scheduler name, :func:`configure` sets this process's dask
options (dashboard, TLS files, worker timeout), :class:`ParallelError` is what a failed run
raises, and :class:`Progress` counts finished tasks on the progress line.
"""

from __future__ import annotations

import functools
import os
import sys
from typing import Any

from .. import progress
from ..errors import LabbrdfError

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
