"""Progress bars for work that takes seconds, on stderr, for a person at a terminal.

The library stays quiet: long functions take a ``progress(done, total)`` callback (the
convention of :func:`pinarms.execution.map_chunks`), and the command line passes a
:class:`ProgressBar`, which *is* such a callback. A bar is drawn only when
:func:`wanted` says so: never with ``--json`` and never when stderr is not a terminal (a
pipe, a file, CI), so machine-readable output and logs stay clean.

>>> with ProgressBar("workspace samples", enabled=wanted(as_json)) as bar:
...     ws = sample_workspace(arm, n=10**7, progress=bar)

The line is drawn by click's progress bar (``click.progressbar``, click being the command
line's own library) and looks like
``workspace samples  [############............]  5000000/10000000   50%  1.2 s``; it is
redrawn in place (carriage return, erase line) at most every 0.1 s and :meth:`ProgressBar.close` ends it. What stays here
is the callback interface, the throttling and the decision whether to draw at all.
"""

from __future__ import annotations

import itertools
import sys
import time
from typing import IO, Any

import click

__all__ = ["ProgressBar", "wanted"]


def wanted(as_json: bool = False, stream: IO[str] | None = None) -> bool:
    """Whether to draw progress: not for ``--json`` output, only when ``stream`` (stderr) is a terminal."""
    stream = sys.stderr if stream is None else stream
    isatty = getattr(stream, "isatty", None)
    return (not as_json) and bool(isatty and isatty())


class ProgressBar:
    """A one-line progress bar on ``stream`` (stderr); a callable ``bar(done, total)``.

    Args:
        label: what is counted (``"GA generations"``).
        total: the amount of work, when known before the first call.
        enabled: draw anything at all (``wanted(as_json)``); a disabled bar does nothing.
        stream: where to draw (default ``sys.stderr``).
        width: characters of the bar itself.
        min_interval: seconds between two redraws (the last state is always drawn).
        after: seconds of work before the first draw (a step done sooner draws nothing; the command
            line's long steps use 2 s).
    """

    def __init__(self, label: str, total: int | None = None, *, enabled: bool = True, stream: IO[str] | None = None,
                 width: int = 24, min_interval: float = 0.1, after: float = 0.0) -> None:
        self.label = label
        self.done = 0
        self.note = ""
        self.enabled = bool(enabled)
        self._stream = sys.stderr if stream is None else stream
        self._min_interval = min_interval
        self.after = float(after)
        self._start = time.perf_counter()
        self._last_draw = -float("inf")
        self._drawn: tuple | None = None  # (done, total, note) last drawn
        self._closed = False
        # click draws; an endless iterable stands for a total not known yet
        self._bar = click.progressbar(iterable=None if total else itertools.repeat(None), length=total or None,
                                      label=label, file=self._stream, width=width, show_pos=True, show_percent=True,
                                      show_eta=False, fill_char="#", empty_char=".", item_show_func=self._tail)

    @property
    def total(self) -> int | None:
        """The amount of work (None while unknown)."""
        return self._bar.length

    @total.setter
    def total(self, value: int | None) -> None:
        self._bar.length = value or None

    def _tail(self, _item: Any) -> str:
        note = f"  {self.note}" if self.note else ""
        return f"{time.perf_counter() - self._start:.1f} s{note}"

    def __call__(self, done: int, total: int | None = None) -> None:
        """Set the work done so far (and the total, when it becomes known)."""
        if total is not None:
            self.total = total
        self.done = done
        self._draw()

    def advance(self, n: int = 1, note: str | None = None) -> None:
        """Count ``n`` more units of work; ``note`` names the step under way (shown after the count)."""
        self.done += n
        if note is not None:
            self.note = note
        self._draw()

    def step(self, note: str) -> None:
        """Name the step under way without counting it."""
        self.note = note
        self._draw(force=True)

    def text(self) -> str:
        """The line as drawn now."""
        self._bar.pos = self.done
        return self._bar.format_progress_line()

    def _draw(self, force: bool = False) -> None:
        if not self.enabled or self._closed:
            return
        now = time.perf_counter()
        if now - self._start < self.after:
            return
        finished = self.total is not None and self.done >= self.total
        if not (force or finished) and now - self._last_draw < self._min_interval:
            return
        self._last_draw = now
        # click formats the line; it is written here, since whether to draw was decided by ``wanted``
        # (click itself would print only the label on a stream that is not a terminal)
        self._stream.write("\r\x1b[2K" + self.text())
        self._stream.flush()
        self._drawn = (self.done, self.total, self.note)

    def close(self) -> None:
        """Draw the final state and end the line (idempotent)."""
        if self._closed:
            return
        if self.enabled:
            if self._drawn != (self.done, self.total, self.note):
                self._draw(force=True)
            if self._drawn is not None:
                self._stream.write("\n")
                self._stream.flush()
        self._closed = True

    def __enter__(self) -> "ProgressBar":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()
