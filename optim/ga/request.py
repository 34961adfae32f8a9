"""What a GA run is asked: :class:`GARequest`, one frozen object checked when built, and
:class:`GAStop`, why :func:`pinarms.optim.run_ga` stopped.

Statuses and exceptions (:mod:`pinarms.optim.status`): bad bounds, settings, seed, budgets or initial
individuals raise :class:`InvalidSettings` (or :class:`SettingOutOfRange`) when the request is
built, before any objective is evaluated. A run that ends returns a :class:`GAResult` whose
``stop_reason`` is a :class:`GAStop`; whether its best satisfies the constraints is
``feasible`` (a run that never met them is still an answer: its least-violating individual).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from pinarms.optim.caps import MAX_GENERATIONS
from pinarms.optim.errors import InvalidSettings, SettingOutOfRange
from pinarms.optim.ga.settings import GASettings
from pinarms.optim.status import Status

__all__ = ["GARequest", "GAStop", "Objective", "random_generator", "checked_bounds", "checked_initial", "run_budget",
           "count_option"]

#: A vectorised objective or constraint: (pop, dim) individuals to (pop,) values or (pop, n_con) rows.
Objective = Callable[[np.ndarray], np.ndarray]


class GAStop(Status):
    """Why a GA run stopped (the value is the word printed)."""

    #: the generation budget was spent
    MAX_GENERATIONS = "max_generations"
    #: the best did not improve by ``stall_tolerance`` for ``stall_generations``
    STALL = "stall"
    #: the wall-clock budget ran out (checked after each generation)
    TIME_LIMIT = "time_limit"
    #: the callback returned True
    CALLBACK = "callback"


def random_generator(seed: int | np.random.Generator) -> np.random.Generator:
    """The random generator of a run: a given Generator, or one seeded by a non-negative int."""
    if isinstance(seed, np.random.Generator):
        return seed
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise InvalidSettings(f"seed={seed!r}: give a non-negative integer or a "
                              "numpy.random.Generator")
    return np.random.default_rng(int(seed))


def count_option(value: object, name: str, minimum: int) -> int:
    """An integer option >= minimum (generations)."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < minimum:
        raise InvalidSettings(f"{name}={value!r}: use an integer >= {minimum}")
    return int(value)


def checked_bounds(bounds: np.ndarray | tuple) -> np.ndarray:
    """``bounds`` as (dim, 2) rows of finite (lower, upper), lower <= upper (a (2, dim) array is turned)."""
    b = np.asarray(bounds, dtype=float)
    if b.ndim == 2 and b.shape[0] == 2 and b.shape[1] != 2:
        b = b.T
    if b.ndim != 2 or b.shape[1] != 2 or b.shape[0] < 1:
        raise InvalidSettings(f"bounds of shape {np.shape(bounds)}: give (dim, 2) rows of "
                              "(lower, upper)")
    lower, upper = b[:, 0], b[:, 1]
    if not (np.all(np.isfinite(lower)) and np.all(np.isfinite(upper))):
        raise InvalidSettings(f"bounds {b.tolist()}: every bound must be finite")
    if np.any(lower > upper):
        raise InvalidSettings(f"bounds {b.tolist()}: lower > upper in rows "
                              f"{np.nonzero(lower > upper)[0].tolist()}")
    return np.array(b, dtype=float)


def checked_initial(initial: object, b: np.ndarray) -> np.ndarray:
    dim = b.shape[0]
    try:
        init = np.atleast_2d(np.asarray(initial, dtype=float))
    except (TypeError, ValueError):
        raise InvalidSettings(f"initial={initial!r} is not numeric: give (k, {dim}) "
                              "individuals") from None
    if init.ndim != 2 or init.shape[1] != dim:
        raise InvalidSettings(f"initial of shape {init.shape}: rows must have {dim} genes")
    if not np.all(np.isfinite(init)):
        raise InvalidSettings("initial individuals hold NaN or inf: give finite genes")
    if np.any(init < b[:, 0] - 1e-12) or np.any(init > b[:, 1] + 1e-12):
        raise InvalidSettings("initial individuals must lie within the bounds")
    return np.array(init)


def run_budget(settings: GASettings, max_generations: int | None, stall_generations: int | None,
               time_limit: float | None) -> tuple[int, int | None]:
    """The generation budget and the stall count of a run, checked (``time_limit`` too)."""
    G = settings.max_generations if max_generations is None else count_option(max_generations, "max_generations", 0)
    if G > MAX_GENERATIONS:
        raise SettingOutOfRange(f"max_generations = {G:,} is more than the {MAX_GENERATIONS:,} allowed")
    stall = (settings.stall_generations if stall_generations is None
             else count_option(stall_generations, "stall_generations", 1))
    if time_limit is not None and not (isinstance(time_limit, (int, float, np.number))
                                       and np.isfinite(time_limit) and time_limit >= 0):
        raise InvalidSettings(f"time_limit={time_limit!r}: give a finite number of seconds >= 0 "
                              "or None")
    return G, stall


@dataclass(frozen=True, eq=False)
class GARequest:
    """Minimise ``objective`` over a box with the real-coded GA: what and how long.

    Attributes:
        objective: Maps a population (pop, dim) to objective values (pop,). NaN/inf
            count as infeasible.
        bounds: (dim, 2) rows of (lower, upper) (stored checked, read-only).
        settings: :class:`GASettings` (None: ``GASettings()``).
        constraints: Maps (pop, dim) to (pop, n_con), feasible where every entry <= 0.
        seed: Integer seed or ``numpy.random.Generator``; same seed, same result.
        max_generations: Generation budget (default ``settings.max_generations``).
        stall_generations: Stop after this many generations without relative improvement
            of the best by ``settings.stall_tolerance`` (default from settings).
        time_limit: Wall-clock budget in seconds (checked after each generation).
        initial: (k, dim) individuals placed in the initial population (the first ``population``).

    Raises (when built):
        InvalidSettings: bad bounds, settings, seed, budgets or initial individuals (named).
        SettingOutOfRange: ``max_generations`` beyond :data:`pinarms.optim.caps.MAX_GENERATIONS`.
    """

    objective: Objective
    bounds: np.ndarray
    settings: GASettings | None = None
    constraints: Objective | None = None
    seed: int | np.random.Generator = 0
    max_generations: int | None = None
    stall_generations: int | None = None
    time_limit: float | None = None
    initial: np.ndarray | None = None

    def __post_init__(self) -> None:
        if not callable(self.objective):
            raise InvalidSettings(f"objective must be callable (pop, dim) -> (pop,), got {self.objective!r}")
        if self.constraints is not None and not callable(self.constraints):
            raise InvalidSettings(f"constraints must be callable (pop, dim) -> (pop, n_con) or None, "
                                  f"got {self.constraints!r}")
        settings = GASettings() if self.settings is None else self.settings
        if not isinstance(settings, GASettings):
            raise InvalidSettings(f"settings must be an optim.GASettings, got {type(settings).__name__}")
        b = checked_bounds(self.bounds)
        random_generator(self.seed)
        run_budget(settings, self.max_generations, self.stall_generations, self.time_limit)
        init = None if self.initial is None else checked_initial(self.initial, b)
        for name, value in (("bounds", b), ("initial", init)):
            if value is not None:
                value.setflags(write=False)
            object.__setattr__(self, name, value)
        object.__setattr__(self, "settings", settings)
