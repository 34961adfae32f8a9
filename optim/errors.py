"""Exceptions of the optimisation package.

All derive from :class:`pinarms.errors.PinarmsError`, so one ``except PinarmsError``
catches everything pinarms raises on purpose.
"""

from __future__ import annotations

import numpy as np

from pinarms.errors import CollisionError, InvalidInput, PinarmsError

__all__ = ["OptimError", "InfeasibleProblem", "InvalidLimits", "InvalidSettings", "SettingOutOfRange", "PlanningError",
           "EndpointInCollision", "StartInCollision", "GoalInCollision", "NoPathFound"]


class OptimError(PinarmsError):
    """Base of the errors raised by :mod:`pinarms.optim`."""


class InfeasibleProblem(OptimError):
    """No candidate within the bounds satisfies the constraints.

    Raised instead of returning an infeasible answer: widen the bounds (larger
    upper bounds on the segment durations) or relax the limits.
    """


class InvalidLimits(OptimError, ValueError):
    """A kinematic limit is missing, not finite, not positive or has the wrong shape."""


class InvalidSettings(OptimError, ValueError):
    """A GA setting, a bound or an argument of an optimiser is out of range."""


class SettingOutOfRange(InvalidSettings, InvalidInput):
    """A setting (a count, a step, a time, a grid size) is not a finite number inside its cap.

    The message names the setting, its value and the range allowed (:mod:`pinarms.optim.caps`).
    Caught by ``except InvalidSettings`` and by ``except InvalidInput`` alike.
    """


class PlanningError(OptimError):
    """A collision-free motion could not be planned (:func:`pinarms.optim.plan_motion`)."""


class EndpointInCollision(PlanningError, CollisionError):
    """The start or the goal of a motion is itself too close to something.

    Attributes:
        which: ``"start"``, ``"goal"``, or ``"hold"`` (an arm that does not move touches
            something at its hold pose; the message names the arm).
        pairs: ``(body_a, body_b)`` of the pair nearest its margin, one per configuration
            tried (one for a joint goal, one per IK branch for a pose goal).
        distances: their distances [m] (negative: penetration depth).
        configurations: the joint values in collision, one row per configuration tried
            (``(k, n)`` planned joints; ``(1, nq)`` the cell configuration for ``"hold"``), or
            ``None`` (a goal point inside a fixture: no configuration was solved).
    """

    def __init__(self, message: str, *, which: str = "", pairs: tuple = (), distances: tuple = (),
                 configurations: np.ndarray | None = None) -> None:
        super().__init__(message)
        self.which = which
        self.pairs = tuple(pairs)
        self.distances = tuple(distances)
        self.configurations = None if configurations is None else np.array(configurations, dtype=float, ndmin=2)


class StartInCollision(EndpointInCollision):
    """The start configuration is closer than the margin to a fixture, another arm or itself."""


class GoalInCollision(EndpointInCollision):
    """Every goal configuration (each IK branch of a pose goal) is closer than the margin to something."""


class NoPathFound(PlanningError):
    """The planner found no collision-free path within its time limit (never a silent straight line).

    Attributes:
        planner: the OMPL planner used; ``time_limit`` and ``seconds`` [s]; ``states``: the
        states it explored; ``goals``: the goal configurations it aimed at.
    """

    def __init__(self, message: str, *, planner: str = "", time_limit: float = 0.0, seconds: float = 0.0,
                 states: int = 0, goals: int = 0) -> None:
        super().__init__(message)
        self.planner = planner
        self.time_limit = time_limit
        self.seconds = seconds
        self.states = states
        self.goals = goals
