"""Run one command: labbrdf's warnings as one line each, every error as an exit code."""

from __future__ import annotations

import contextlib
import os
import sys
import warnings
from collections.abc import Iterator, Sequence
from typing import Any

from .. import progress
from ._options import UsageError
from ._parser import build_parser, chosen_command
from ._paths import _checked_outputs


@contextlib.contextmanager
def _labbrdf_warnings(command: str) -> Iterator[None]:
    """Print labbrdf's own warnings as one line each, without Python's source-line dump.

    A reader's doubts (:class:`~labbrdf.adapters.AdapterWarning`, always shown), a tracer
    cache file that was rebuilt, an ill-conditioned inversion: every warning class defined
    in labbrdf. Other libraries' warnings keep Python's format.
    """
    from ..errors import AdapterWarning  # not the readers: nothing heavy at start-up

    with warnings.catch_warnings():
        original = warnings.showwarning

        def show(message: Any, category: Any, *rest: Any, **kw: Any) -> None:
            progress.clear()  # the warning starts on a clean line
            if category.__module__.partition(".")[0] == "labbrdf":
                print(f"labbrdf {command}: warning: {message}", file=sys.stderr)
            else:
                original(message, category, *rest, **kw)

        warnings.simplefilter("always", AdapterWarning)
        warnings.showwarning = show
        yield


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit code.

    Only the chosen command's module is imported (:func:`._parser.build_parser`).
    """
    words = sys.argv[1:] if argv is None else list(argv)
    command = chosen_command(words)
    try:
        parser = build_parser(commands=() if command is None else (command,))
    except KeyboardInterrupt:
        print("labbrdf: interrupted", file=sys.stderr)
        return 130
    args = parser.parse_args(words)
    try:
        with (
            _checked_outputs(args),
            _labbrdf_warnings(args.command),
            progress.shown(f"labbrdf {args.command}", enabled=not args.quiet),
        ):
            return int(args.func(args))
    except UsageError as exc:
        print(f"labbrdf {args.command}: {exc}", file=sys.stderr)
        return 2
    except (ValueError, NotImplementedError, ImportError) as exc:
        # AdapterError, DatasetError, ModelError, FitError are ValueErrors with a message
        print(f"labbrdf {args.command}: {exc}", file=sys.stderr)
        return 2
    except BrokenPipeError:
        # the reader of our output stopped early (`labbrdf ingest --json | head`): not an
        # error of ours; point stdout at devnull so that Python's exit flush stays quiet
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return 141
    except OSError as exc:  # an output or input the OS refused: no traceback
        where = f"{exc.filename}: " if exc.filename else ""
        print(f"labbrdf {args.command}: {where}{exc.strerror or exc}", file=sys.stderr)
        return 2
    except MemoryError:
        print(f"labbrdf {args.command}: out of memory (is an input a huge file?)", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"labbrdf {args.command}: interrupted; the run is abandoned", file=sys.stderr)
        return 130
