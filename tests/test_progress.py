"""The one progress line: drawn in place on a terminal, silent elsewhere, fed by long work."""

from __future__ import annotations

import io

import numpy as np
import pytest

from labbrdf import progress
from labbrdf.parallel import Progress


class Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


class Clock:
    def __init__(self) -> None:
        self.t = 0.0

    def __call__(self) -> float:
        return self.t


def test_line_shows_stage_evaluations_best_chi2_and_an_upper_bound_of_time_left():
    clock, tty = Clock(), Terminal()
    line = progress.ProgressLine("labbrdf film", stream=tty, interval=0.0, clock=clock)
    line.update(stage="GN_CRS2_LM", budget=400)
    clock.t = 10.0
    line.update(evaluations=100, best=1234.56789)
    assert line.text() == (
        "labbrdf film: GN_CRS2_LM, 100 evaluations, best chi2 1234.6, <= 30 s left"
    )
    assert tty.getvalue().startswith("\r") and "\n" not in tty.getvalue()


def test_phase_fraction_gives_the_time_left_and_a_new_stage_restarts_its_count():
    clock = Clock()
    line = progress.ProgressLine("x", stream=Terminal(), interval=0.0, clock=clock)
    line.update(phase="profile interval of d", done=0, total=4)
    clock.t = 20.0
    line.update(done=1)
    assert "profile interval of d 1/4" in line.text() and "~1 min 0 s left" in line.text()
    line.update(phase="tracer tasks", done=0, total=8)  # a new phase: a new clock
    assert "left" not in line.text()
    line.update(stage="LN_BOBYQA", budget=10, evaluations=500)
    clock.t = 21.0
    line.update(evaluations=505)  # 5 of 10 in 1 s (the 500 before belong to earlier stages)
    assert "<= 1 s left" in line.text()
    line.update(phase="passes", done=1, total=26)  # reported first after one pass
    assert "~" not in line.text()  # no rate yet: the pass before the phase was not seen
    clock.t = 23.0
    line.update(done=2)
    assert "passes 2/26" in line.text() and "~48 s left" in line.text()  # 24 x 2 s


def test_redraws_are_throttled_and_the_line_is_erased_at_the_end():
    clock, tty = Clock(), Terminal()
    line = progress.ProgressLine("x", stream=tty, interval=1.0, clock=clock)
    clock.t = 5.0
    for i in range(100):
        line.update(evaluations=i)
    assert tty.getvalue().count("\r") == 1
    line.clear()
    assert tty.getvalue().endswith("\r")
    assert tty.getvalue().rsplit("\r", 2)[-2].strip() == ""


@pytest.mark.parametrize("enabled", [True, False])
def test_nothing_is_written_off_a_terminal_or_when_quiet(enabled):
    stream = io.StringIO() if enabled else Terminal()
    with progress.shown("x", stream=stream, enabled=enabled):
        progress.report(stage="s", evaluations=3, best=1.0)
        progress.clear()
    assert stream.getvalue() == ""


def test_report_is_a_no_op_without_a_line_and_inner_blocks_share_the_outer_line():
    progress.report(evaluations=1)  # nothing shown: nothing happens
    assert progress.active() is None
    tty = Terminal()
    with progress.shown("outer", stream=tty) as outer:
        with progress.shown("inner") as inner:
            assert inner is outer
    assert progress.active() is None


def test_a_fit_feeds_the_line_with_its_stages_and_evaluations():
    from labbrdf.fitting import FitData, fit
    from labbrdf.models import get

    ti = np.repeat([30.0, 45.0, 60.0], 21)
    tr = ti + np.tile(np.linspace(-2.0, 2.0, 21), 3)
    k = {"k1": 0.4, "k2": 0.16, "k3": 0.37}
    data = FitData(ti, tr, get("smooth3").evaluate(np.radians(ti), np.radians(tr), params=k))
    tty = Terminal()
    seen: list[str] = []
    with progress.shown("labbrdf fit", stream=tty) as line:
        line.interval = 0.0
        real = line._draw
        line._draw = lambda text: (seen.append(text), real(text))  # type: ignore[method-assign]
        fit("smooth3", data, maxeval=50)
    assert any("GN_CRS2_LM" in s and "evaluations" in s and "best chi2" in s for s in seen)
    assert any("LN_BOBYQA" in s for s in seen)
    assert tty.getvalue().endswith("\r")  # erased before the answer is printed


def test_executor_task_count_is_silent_off_a_terminal_and_on_the_line_on_one():
    piped = io.StringIO()
    bar = Progress(10, "tracer tasks", True, stream=piped)
    for _ in range(10):
        bar.update()
    assert piped.getvalue() == ""
    tty = Terminal()
    with progress.shown("labbrdf trace", stream=tty) as line:
        line.interval = 0.0
        bar = Progress(10, "tracer tasks", True)
        bar.update(3)
        assert "labbrdf trace: tracer tasks 3/10" in tty.getvalue()


def test_every_command_takes_quiet():
    from labbrdf.cli import build_parser

    p = build_parser()
    (sub,) = [a for a in p._actions if a.dest == "command"]
    for name, sp in sub.choices.items():
        quiet = [a for a in sp._actions if "--quiet" in a.option_strings]
        assert len(quiet) == 1 and quiet[0].dest == "quiet" and quiet[0].nargs == 0, name
