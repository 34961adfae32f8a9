"""Progress bars: drawn on a terminal's stderr only, never with --json or into a pipe."""

from __future__ import annotations

import io

import numpy as np

from pinarms import robots
from pinarms.progress import ProgressBar, wanted


class _Tty(io.StringIO):
    def isatty(self) -> bool:
        return True


def _last_line(out: _Tty) -> str:
    """The last state drawn, without click's cursor hide/show sequences."""
    return out.getvalue().split("\r")[-1].replace("\x1b[?25l", "").replace("\x1b[?25h", "").replace("\x1b[2K", "")


def test_wanted_only_for_a_terminal_without_json():
    assert wanted(False, _Tty()) is True
    assert wanted(True, _Tty()) is False
    assert wanted(False, io.StringIO()) is False  # a pipe or a file


def test_bar_counts_and_ends_its_line():
    out = _Tty()
    with ProgressBar("GA generations", 300, stream=out, min_interval=0.0) as bar:
        for g in range(1, 301):
            bar(g)
    text = out.getvalue()
    last = _last_line(out)
    assert last.startswith("GA generations  [########################]  300/300  100%") and last.rstrip().endswith(" s")
    assert last.endswith("\n")
    assert text.count("\n") == 1


def test_disabled_bar_writes_nothing():
    out = _Tty()
    with ProgressBar("demo", 4, enabled=False, stream=out) as bar:
        bar.advance(note="seed 001")
        bar(4)
    assert out.getvalue() == ""


def test_unknown_total_and_notes_are_drawn():
    out = _Tty()
    with ProgressBar("planning", stream=out, min_interval=0.0) as bar:
        bar.step("motion 1")
        bar.advance(note="motion 2")
    last = _last_line(out)
    assert last.startswith("planning  [") and "1  " in last and last.rstrip().endswith("motion 2")


def test_redraws_are_throttled():
    out = _Tty()
    bar = ProgressBar("samples", 10**6, stream=out, min_interval=3600.0)
    for k in range(1, 1001):
        bar(k * 1000)
    bar.close()
    assert out.getvalue().count("\r") <= 3  # the first draw, the finished state (and nothing between)


def test_workspace_sampling_reports_every_sample():
    calls: list[tuple[int, int]] = []
    ws = robots.sample_workspace(robots.load("aubo_i3"), n=70_000, seed=0, chunk=16384, progress=lambda d, t: calls.append((d, t)))
    assert [t for _, t in calls] == [70_000] * 5
    assert sorted(d for d, _ in calls) == [d for d, _ in calls] and calls[-1][0] == 70_000
    quiet = robots.sample_workspace(robots.load("aubo_i3"), n=70_000, seed=0, chunk=16384)
    np.testing.assert_array_equal(ws.points, quiet.points)


def test_a_bar_with_after_draws_only_once_its_step_has_taken_that_long():
    """The command line's long steps (the belt's maps for --robot) draw after 2 s: a quick step
    leaves stderr empty, a long one draws its line."""
    import time

    quick = _Tty()
    with ProgressBar("task map 'arm 1' (item)", 10, stream=quick, min_interval=0.0, after=2.0) as bar:
        for k in range(1, 11):
            bar(k)
    assert quick.getvalue() == ""
    slow = _Tty()
    with ProgressBar("task map 'arm 1' (item)", 10, stream=slow, min_interval=0.0, after=0.05) as bar:
        bar(1)
        time.sleep(0.06)
        bar(2)
    assert _last_line(slow).startswith("task map 'arm 1' (item)") and "2/10" in _last_line(slow)
