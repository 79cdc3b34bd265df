"""The executor options of the commands that run tasks, and the executor they describe."""

from __future__ import annotations

import argparse
import functools
from typing import Any

from ._options import UsageError
from ._paths import InputPath


def _add_scheduler(p: argparse.ArgumentParser) -> None:
    """The executor options of a command that runs tasks (:func:`_executor` reads them)."""
    from ..parallel import DEFAULT_SCHEDULER

    p.add_argument(
        "--scheduler",
        default=DEFAULT_SCHEDULER,
        help=f"serial, processes, local (dask LocalCluster on 127.0.0.1; default "
        f"{DEFAULT_SCHEDULER}), "
        "tls://host:port (a dask scheduler with TLS) or tcp://host:port (unauthenticated: "
        "a trusted network only)",
    )
    p.add_argument("--workers", type=int, default=None, help="worker processes (default: cores)")
    p.add_argument(
        "--tls-ca", action=InputPath, default=None, metavar="PEM", help="CA certificate (tls://)"
    )
    p.add_argument(
        "--tls-cert",
        action=InputPath,
        default=None,
        metavar="PEM",
        help="this client's certificate",
    )
    p.add_argument(
        "--tls-key",
        action=InputPath,
        default=None,
        metavar="PEM",
        help="this client's private key",
    )
    p.add_argument(
        "--dashboard", action="store_true", help="start the local cluster's dashboard (127.0.0.1)"
    )
    p.add_argument(
        "--worker-timeout",
        type=float,
        default=None,
        metavar="SECONDS",
        help="how long to wait for a worker on a tcp:// or tls:// scheduler that has none "
        "(default 60)",
    )


def _executor(args: argparse.Namespace, progress: bool = True) -> Any:
    """The :class:`labbrdf.parallel.Executor` of the command's options, built once.

    A bad ``--scheduler``, ``--workers`` or security option is refused here, before any
    work is done (exit 2).
    """
    from ..parallel import Executor, check_scheduler, configure

    if args.workers is not None and args.workers < 1:
        raise UsageError(f"--workers must be >= 1, got {args.workers}")
    try:  # first: certificates given here decide what --scheduler local needs
        configure(
            dashboard=True if args.dashboard else None,
            tls_ca=args.tls_ca,
            tls_cert=args.tls_cert,
            tls_key=args.tls_key,
            worker_timeout=args.worker_timeout,
        )
    except ValueError as exc:
        raise UsageError(str(exc)) from None
    try:
        check_scheduler(args.scheduler)
    except ValueError as exc:
        raise UsageError(f"--scheduler: {exc}") from None
    return Executor(
        args.scheduler,
        workers=args.workers,
        progress=progress,
        dashboard=True if args.dashboard else None,
        tls_ca=args.tls_ca,
        tls_cert=args.tls_cert,
        tls_key=args.tls_key,
        worker_timeout=args.worker_timeout,
    )


def _executor_errors(cmd: Any) -> Any:
    """Make a run abandoned by the executor exit with code 2 and the reason.

    Dead workers, an unreachable scheduler or a local cluster that did not start give the
    reason on stderr, not a traceback; nothing partial has been written. Ctrl-C says that
    the run was interrupted (exit 130, from :func:`labbrdf.cli.main`).
    """

    @functools.wraps(cmd)
    def wrapper(args: argparse.Namespace) -> int:
        from ..parallel import ParallelError

        try:
            return cmd(args)
        except ParallelError as exc:
            raise UsageError(str(exc)) from None

    return wrapper
