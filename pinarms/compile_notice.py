"""A progress line on stderr while numba compiles kernels for more than 2 s (command line only).

A process whose kernels are not in numba's disk cache yet (``pinarms warm`` not run, or the
sources changed) compiles them on first use: a minute or more where the command would
otherwise print nothing. :class:`CompileNotice` listens to numba's ``numba:compile`` events
(compiles only: a kernel loaded from the cache raises none) and, once this process has spent
``after`` seconds compiling, draws while compiling::

    compiling numba kernels on first use: 12.3 s (kept in numba's cache; `pinarms warm` compiles them all once)

redrawn in place (carriage return, erase line) and erased when the compile ends, so other
progress bars draw on the same line. :meth:`CompileNotice.close` ends with one line of the total
when it exceeded ``after``. The library's own functions stay quiet: only the command line
starts a notice, and only where :func:`pinarms.progress.wanted` says so.

Importing numba costs about a second, which a command that compiles nothing should not pay: a
notice started before numba is imported is attached to numba's events by :func:`attach`, which
:mod:`pinarms.compiled` calls when it is imported (before any kernel exists). This module imports
nothing of pinarms (the floor).
"""

from __future__ import annotations

import sys
import threading
import time
from typing import IO, Any

__all__ = ["CompileNotice", "attach"]

_TEXT = "compiling numba kernels on first use: {:.1f} s (kept in numba's cache; `pinarms warm` compiles them all once)"


class CompileNotice:
    """Draw :data:`_TEXT` on ``stream`` while numba compiles, after ``after`` seconds of compiling in this process.

    Use as a context manager (:meth:`start` / :meth:`close`); ``enabled=False`` draws nothing.
    """

    def __init__(self, *, enabled: bool = True, stream: IO[str] | None = None, after: float = 2.0,
                 interval: float = 0.25) -> None:
        self.enabled = bool(enabled)
        self.after = float(after)
        self.interval = float(interval)
        self._stream = sys.stderr if stream is None else stream
        self._lock = threading.Lock()
        self._depth = 0
        self._since = 0.0       # perf_counter at the start of the outermost compile under way
        self._done = 0.0        # [s] compiling finished so far
        self._drawn = False
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self._registered = False

    @property
    def seconds(self) -> float:
        """[s] spent compiling in this process since :meth:`start`."""
        with self._lock:
            return self._done + (time.perf_counter() - self._since if self._depth else 0.0)

    def notify(self, event: Any) -> None:
        """numba's listener interface (``numba.core.event.Listener``): a compile starts or ends."""
        if event.is_start:
            self.on_start(event)
        elif event.is_end:
            self.on_end(event)

    def on_start(self, event: Any) -> None:
        with self._lock:
            self._depth += 1
            if self._depth == 1:
                self._since = time.perf_counter()

    def on_end(self, event: Any) -> None:
        with self._lock:
            self._depth -= 1
            if self._depth:
                return
            self._done += time.perf_counter() - self._since
            if self._drawn:
                self._stream.write("\r\x1b[2K")
                self._stream.flush()
                self._drawn = False

    def _watch(self) -> None:
        while not self._stop.wait(self.interval):
            with self._lock:
                if not self._depth:
                    continue
                spent = self._done + time.perf_counter() - self._since
                if spent >= self.after:
                    self._stream.write("\r\x1b[2K" + _TEXT.format(spent))
                    self._stream.flush()
                    self._drawn = True

    def start(self) -> "CompileNotice":
        """Listen to numba's compiles (and draw, when enabled)."""
        if self.enabled and self._thread is None:
            _started.append(self)
            if "pinarms.compiled" in sys.modules:
                attach()
            self._thread = threading.Thread(target=self._watch, name="compile-notice", daemon=True)
            self._thread.start()
        return self

    def close(self) -> None:
        """Stop listening; one line of the time spent compiling when it exceeded ``after``."""
        if self._thread is None:
            return
        self._stop.set()
        self._thread.join()
        self._thread = None
        _started.remove(self)
        if self._registered:
            from numba.core import event

            event.unregister("numba:compile", self)
            self._registered = False
        with self._lock:
            if self._drawn:
                self._stream.write("\r\x1b[2K")
                self._drawn = False
            if self._done >= self.after:
                self._stream.write(f"compiled numba kernels on first use in {self._done:.1f} s (now in numba's cache; "
                                   "`pinarms warm` compiles them all once)\n")
            self._stream.flush()

    def __enter__(self) -> "CompileNotice":
        return self.start()

    def __exit__(self, *exc: Any) -> None:
        self.close()


#: notices started in this process (attached to numba's events once numba is imported)
_started: list[CompileNotice] = []


def attach() -> None:
    """Register every started notice with numba's ``numba:compile`` event (called by :mod:`pinarms.compiled`)."""
    if not _started:
        return
    from numba.core import event

    event.Listener.register(CompileNotice)  # numba's listener interface: notify(event)
    for notice in _started:
        if not notice._registered:
            event.register("numba:compile", notice)
            notice._registered = True
