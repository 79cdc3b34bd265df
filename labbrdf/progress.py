"""One updating progress line on a terminal for long work: what runs, how far, time left.

Long work (a fit's nlopt stages, a film fit's profile intervals, a tracer run's tasks, a
height map's leave-one-block-out passes) calls :func:`report` with what it knows; that is
a no-op unless a line is shown (:func:`shown`, which the command line opens around every
command). The line is redrawn in place on stderr at most every ``interval`` seconds and
erased when the work ends, so the answer that follows starts on a clean line. Nothing is
written when stderr is not a terminal (a pipe, a log file, CI) or with ``--quiet``.

The fields of :func:`report` (all optional, keywords):

- ``phase`` (str), with ``done`` and ``total`` (int): a coarse step of the work, e.g.
  ``"profile intervals"`` 2 of 5 or ``"tracer tasks"`` 40 of 64; a new ``phase`` restarts
  its clock. The time left is ``elapsed / done x (total - done)``.
- ``stage`` (str) with ``budget`` (int): a finer step with an evaluation budget (an nlopt
  stage); without a phase fraction, the time left is estimated from the evaluations spent
  in the stage and its budget, an upper bound (a stage may converge before its budget),
  shown as ``<= N s``.
- ``evaluations`` (int, a running count) and ``best`` (float, the best chi-square so far).

Plain standard library, no import of numpy: the command line may import it at start-up.
"""

from __future__ import annotations

import contextlib
import math
import shutil
import sys
import time
from collections.abc import Callable, Iterator
from contextvars import ContextVar
from typing import IO, Any

__all__ = ["ProgressLine", "active", "clear", "report", "shown"]

#: least time between two redraws of a line [s] (the default of :class:`ProgressLine`)
MIN_INTERVAL = 0.25

_ACTIVE: ContextVar[ProgressLine | None] = ContextVar("labbrdf_progress_line", default=None)


def _is_tty(stream: Any) -> bool:
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError):  # no isatty, or a closed stream
        return False


def _duration(seconds: float) -> str:
    """``42 s``, ``3 min 5 s``, ``2 h 4 min``."""
    s = int(round(seconds))
    if s < 60:
        return f"{s} s"
    if s < 3600:
        return f"{s // 60} min {s % 60} s"
    return f"{s // 3600} h {s % 3600 // 60} min"


class ProgressLine:
    """One line on ``stream`` (default stderr), redrawn in place; silent off a terminal.

    Parameters
    ----------
    label : str
        What the line is about, e.g. ``"labbrdf film"``.
    stream : file, optional
        Where to draw (default ``sys.stderr``).
    enabled : bool
        False: never draw (``--quiet``). True draws only when ``stream`` is a terminal.
    interval : float, optional
        Least time between two redraws [s] (default :data:`MIN_INTERVAL`).
    clock : callable
        Monotonic time [s] (tests pass a fake one).
    """

    def __init__(
        self,
        label: str,
        *,
        stream: IO[str] | None = None,
        enabled: bool = True,
        interval: float | None = None,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.label = label
        self.stream = stream if stream is not None else sys.stderr
        self.enabled = bool(enabled) and _is_tty(self.stream)
        self.interval = MIN_INTERVAL if interval is None else float(interval)
        self.clock = clock
        self.fields: dict[str, Any] = {}
        self._t_phase = self._t_stage = clock()
        self._evals_at_stage = 0
        self._done_at_phase = 0
        self._drawn = 0  # width of what is on the terminal now
        self._t_drawn = -math.inf

    def update(self, **fields: Any) -> None:
        """Take new values of the fields (see the module's docstring) and redraw if due."""
        now = self.clock()
        if "phase" in fields and fields["phase"] != self.fields.get("phase"):
            self._t_phase = now
            self._done_at_phase = int(fields.get("done") or 0)  # the rate counts from here
            for k in ("done", "total"):
                self.fields.pop(k, None)
        if "stage" in fields:
            self._t_stage = now
            self._evals_at_stage = int(
                fields.get("evaluations", self.fields.get("evaluations", 0))
            )
            self.fields.pop("budget", None)
        self.fields.update({k: v for k, v in fields.items() if v is not None})
        if self.enabled and now - self._t_drawn >= self.interval:
            self._draw(self.text(now))
            self._t_drawn = now

    def left(self, now: float) -> str | None:
        """The estimated time left, or None (nothing to estimate from yet)."""
        f = self.fields
        done, total = f.get("done"), f.get("total")
        if done and total and self._done_at_phase < done < total:
            rate = (now - self._t_phase) / (done - self._done_at_phase)
            return "~" + _duration(rate * (total - done))
        spent = int(f.get("evaluations", 0)) - self._evals_at_stage
        budget = f.get("budget")
        if budget and 0 < spent < budget:
            return "<= " + _duration((now - self._t_stage) / spent * (budget - spent))
        return None

    def text(self, now: float | None = None) -> str:
        """The line as it is drawn (without the terminal's control characters)."""
        now = self.clock() if now is None else now
        f = self.fields
        parts = []
        if "phase" in f:
            count = f" {f['done']}/{f['total']}" if "done" in f and "total" in f else ""
            parts.append(f"{f['phase']}{count}")
        if "stage" in f:
            parts.append(str(f["stage"]))
        if "evaluations" in f:
            parts.append(f"{f['evaluations']} evaluations")
        best = f.get("best")
        if isinstance(best, (int, float)) and math.isfinite(best):
            parts.append(f"best chi2 {best:.5g}")
        left = self.left(now)
        if left is not None:
            parts.append(f"{left} left")
        return f"{self.label}: " + ", ".join(parts)

    def _draw(self, text: str) -> None:
        width = max(shutil.get_terminal_size((80, 24)).columns - 1, 10)
        text = text[:width]
        pad = " " * max(self._drawn - len(text), 0)
        self.stream.write(f"\r{text}{pad}")
        self.stream.flush()
        self._drawn = len(text)

    def clear(self) -> None:
        """Erase the line (before other output, and when the work ends)."""
        if self.enabled and self._drawn:
            self.stream.write("\r" + " " * self._drawn + "\r")
            self.stream.flush()
            self._drawn = 0
            self._t_drawn = -math.inf


@contextlib.contextmanager
def shown(
    label: str, *, enabled: bool = True, stream: IO[str] | None = None
) -> Iterator[ProgressLine]:
    """Show the progress that :func:`report` calls give, for the duration of the block.

    Within an outer :func:`shown` block the outer line is kept (one line at a time).
    """
    outer = _ACTIVE.get()
    if outer is not None:
        yield outer
        return
    line = ProgressLine(label, stream=stream, enabled=enabled)
    token = _ACTIVE.set(line)
    try:
        yield line
    finally:
        _ACTIVE.reset(token)
        line.clear()


def active() -> ProgressLine | None:
    """The line shown now, or None."""
    return _ACTIVE.get()


def report(**fields: Any) -> None:
    """Tell the shown line how far the work is (a no-op when none is shown)."""
    line = _ACTIVE.get()
    if line is not None and line.enabled:
        line.update(**fields)


def clear() -> None:
    """Erase the shown line, if any, before writing something else to the terminal."""
    line = _ACTIVE.get()
    if line is not None:
        line.clear()
