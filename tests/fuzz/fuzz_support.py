"""What every fuzz test checks: a named PinarmsError or a finite result, in bounded time."""

from __future__ import annotations

import contextlib
import dataclasses
import math
import os
import signal
import warnings
from pathlib import Path
from typing import Any, Callable, Iterator

import numpy as np
from hypothesis import event
from hypothesis.errors import InvalidArgument

from pinarms.errors import PinarmsError

EXPLORE = 10 if os.environ.get("HYPOTHESIS_PROFILE") == "explore" else 1


class Hang(BaseException):
    """A call ran past its time bound (BaseException: no ``except Exception`` in the code swallows it)."""


@contextlib.contextmanager
def time_bound(seconds: float) -> Iterator[None]:
    """Raise :class:`Hang` in the main thread after ``seconds`` (checked between Python bytecodes)."""

    def alarm(signum: int, frame: Any) -> None:
        raise Hang(f"no answer within {seconds} s")

    old = signal.signal(signal.SIGALRM, alarm)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


def assert_finite(value: Any, where: str = "result", depth: int = 0) -> None:
    """No NaN anywhere in ``value`` (arrays, numbers, tuples, lists, dicts, dataclasses)."""
    if depth > 6:
        return
    if isinstance(value, np.ndarray):
        if value.dtype.kind in "fc":
            assert not np.isnan(value).any(), f"{where} holds NaN"
    elif isinstance(value, (float, np.floating)):
        assert not math.isnan(value), f"{where} is NaN"
    elif isinstance(value, (list, tuple)):
        for i, v in enumerate(value[:1000]):
            assert_finite(v, f"{where}[{i}]", depth + 1)
    elif isinstance(value, dict):
        for k, v in list(value.items())[:1000]:
            assert_finite(v, f"{where}[{k!r}]", depth + 1)
    elif dataclasses.is_dataclass(value) and not isinstance(value, type):
        for f in dataclasses.fields(value):
            assert_finite(getattr(value, f.name), f"{where}.{f.name}", depth + 1)


def outcome(fn: Callable[..., Any], *args: Any, seconds: float = 10.0, **kwargs: Any) -> tuple[Any, PinarmsError | None]:
    """Call ``fn``: a result without NaN, or a named PinarmsError subclass with a message; anything else fails.

    Returns ``(result, None)`` or ``(None, error)``.
    """
    try:
        with time_bound(seconds), warnings.catch_warnings():
            # a complex number silently made real, or an overflow on the way to a result, is a bug too
            warnings.simplefilter("error", np.exceptions.ComplexWarning)
            warnings.simplefilter("error", RuntimeWarning)
            result = fn(*args, **kwargs)
    except PinarmsError as exc:
        assert type(exc) is not PinarmsError, f"a bare PinarmsError instead of a named subclass: {exc}"
        assert str(exc).strip(), f"{type(exc).__name__} without a message"
        _event(f"{getattr(fn, '__name__', 'call')}: {type(exc).__name__}")
        return None, exc
    assert_finite(result)
    _event(f"{getattr(fn, '__name__', 'call')}: returned")
    return result, None


def _event(label: str) -> None:
    """Count outcomes in Hypothesis' statistics (pytest --hypothesis-show-statistics)."""
    try:
        event(label)
    except InvalidArgument:  # outside a Hypothesis test (the corpus)
        pass


def listing(*folders: Path) -> dict[str, set[str]]:
    """Every file under ``folders`` (to show that nothing was written outside a target)."""
    out = {}
    for folder in folders:
        out[str(folder)] = {str(p.relative_to(folder)) for p in Path(folder).rglob("*")}
    return out


def damaged_file(folder: Path, name: str, data: bytes, kind: str, offset: int, xor: int) -> Path:
    """``data`` with one byte flipped (``kind == "flip"``: xor ``xor`` at ``offset`` modulo its
    length) or cut at ``offset`` (``"cut"``), written to ``folder / name``."""
    data = bytearray(data)
    offset %= len(data)
    if kind == "flip":
        data[offset] ^= xor
    else:
        del data[offset:]
    path = folder / name
    path.write_bytes(bytes(data))
    return path
