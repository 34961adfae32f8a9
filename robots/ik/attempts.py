"""How :meth:`pinarms.robots.ik.numerical.NumericalIK.solve_checked` searches: one frozen object.

The numerical solver's inner entry point takes a target, a start and an :class:`IKAttempts`:
what counts as reached (``position_only``, ``tol``), how many seeded restarts and from which
random stream (``max_restarts``, ``seed``), whether the joint limits hold (``limits``) and which
stages run (``first``: the attempt from the start; ``polish``: the final projected descent of a
failed solve; ``compiled``: the attempts in one native call rather than step by step). Callers
that solve many targets build it once.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pinarms.errors import InvalidInput

__all__ = ["IKAttempts"]


@dataclass(frozen=True)
class IKAttempts:
    """The attempts of one numerical IK solve (module doc).

    Raises:
        InvalidInput: ``tol`` not a finite positive number [m, rad], ``max_restarts`` not a
            non-negative integer, a ``seed`` that is neither an integer >= 0 nor a
            ``numpy.random.Generator``.
    """

    position_only: bool = False
    tol: float = 1e-9
    max_restarts: int = 0
    seed: int | np.random.Generator = 0
    limits: bool = True
    first: bool = True
    polish: bool = True
    compiled: bool = True

    def __post_init__(self) -> None:
        if not (np.isfinite(self.tol) and self.tol > 0.0):
            raise InvalidInput(f"tol [m, rad] must be a finite positive number, got {self.tol!r}")
        if isinstance(self.max_restarts, bool) or int(self.max_restarts) != self.max_restarts or self.max_restarts < 0:
            raise InvalidInput(f"max_restarts must be a non-negative integer, got {self.max_restarts!r}")
        if not isinstance(self.seed, np.random.Generator) and (
                isinstance(self.seed, bool) or not isinstance(self.seed, (int, np.integer)) or self.seed < 0):
            raise InvalidInput(f"seed must be an integer >= 0 or a numpy.random.Generator, got {self.seed!r}")
