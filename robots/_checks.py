"""Argument checks shared by :class:`~pinarms.robots.Robot` and its solvers (no other imports).

Kept apart from :mod:`.robot` so that the solvers in :mod:`.ik` can use them without
importing the ``Robot`` module (imports stay one-way: ``robot`` → ``ik``).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from pinarms.errors import InvalidInput

__all__ = ["real_array", "as_batch", "check_seed", "as_generator", "check_tolerance", "check_restarts", "MAX_RESTARTS", "check_path_name"]

#: Most random restarts of one numerical IK solve (default 40; one restart costs up to a few
#: ms, so the cap bounds an unreachable target at a few seconds).
MAX_RESTARTS = 1000


def real_array(values: Any, what: str) -> np.ndarray:
    """``values`` as a float array; complex numbers, text and other objects are :class:`InvalidInput` naming ``what``."""
    try:
        if np.iscomplexobj(values):
            raise TypeError("complex numbers")
        return np.asarray(values, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InvalidInput(f"{what} must be numbers (real), got {values!r}") from exc


def as_batch(values: Any, width: int, what: str) -> tuple[np.ndarray, bool]:
    """Validate ``values`` as ``(width,)`` or ``(N, width)`` finite floats.

    Returns the ``(N, width)`` array and whether the input was a single vector.
    """
    arr = real_array(values, what)
    single = arr.ndim == 1
    if single:
        arr = arr[None, :]
    if arr.ndim != 2 or arr.shape[1] != width:
        raise InvalidInput(
            f"{what} must have shape ({width},) or (N, {width}), got {np.shape(values)}"
        )
    if not np.all(np.isfinite(arr)):
        bad = np.argwhere(~np.isfinite(arr))[0]
        raise InvalidInput(f"{what} holds a non-finite value at index {tuple(bad.tolist())}")
    return arr, single


def check_seed(seed: Any, what: str = "seed") -> Any:
    """``seed`` unchanged if it is ``None``, a non-negative int or a ``numpy.random.Generator``.

    Raises:
        InvalidInput: anything else (a negative or fractional number, a string, ...).
    """
    if seed is None or isinstance(seed, np.random.Generator):
        return seed
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise InvalidInput(f"{what} must be None, a non-negative integer or a numpy.random.Generator, got {seed!r}")
    return seed


def as_generator(seed: Any, what: str = "seed") -> np.random.Generator:
    """``seed`` (see :func:`check_seed`) as a ``numpy.random.Generator`` (a Generator is returned as is)."""
    seed = check_seed(seed, what)
    return seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)


def check_tolerance(tol: Any, what: str, *, positive: bool = False) -> float:
    """``tol`` as a finite float ``>= 0`` (``> 0`` when ``positive``); :class:`InvalidInput` otherwise."""
    ok = isinstance(tol, (int, float, np.integer, np.floating)) and not isinstance(tol, bool)
    value = float(tol) if ok else float("nan")
    if not (np.isfinite(value) and (value > 0.0 if positive else value >= 0.0)):
        sign = "positive" if positive else "non-negative"
        raise InvalidInput(f"{what} must be a finite {sign} number, got {tol!r}")
    return value


def check_restarts(value: Any, what: str = "max_restarts") -> int:
    """``value`` as an int from 0 to :data:`MAX_RESTARTS`; else :class:`InvalidInput` naming ``what``."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or not 0 <= value <= MAX_RESTARTS:
        raise InvalidInput(f"{what} must be an integer from 0 to {MAX_RESTARTS} (random restarts of the numerical "
                           f"IK per target), got {value!r}")
    return int(value)


def check_path_name(path: Any, what: str) -> None:
    """:class:`InvalidInput` for a path no file can have: a NUL byte in it, or a name the system
    refuses as too long (``ENAMETOOLONG``: a part over 255 bytes or the whole over 4096 on Linux)."""
    import errno
    import os

    text = os.fsdecode(os.fspath(path))
    if "\0" in text:
        raise InvalidInput(f"{what} {text!r} contains a NUL byte: no file has such a name; check the path")
    try:
        os.stat(text)
    except OSError as exc:
        if exc.errno == errno.ENAMETOOLONG:
            raise InvalidInput(f"{what} {text[:80]!r}... ({len(text)} characters) is too long a path for this "
                               "system (a part over 255 bytes or the whole over 4096): check the path") from None
