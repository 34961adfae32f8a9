"""Exceptions of the optimisation package.

All derive from :class:`robots.errors.PinarmsError`, so one ``except PinarmsError``
catches everything pinarms raises on purpose.
"""

from __future__ import annotations

from pinarms.robots.errors import PinarmsError

__all__ = ["OptimError", "InfeasibleProblem", "InvalidLimits", "InvalidSettings"]


class OptimError(PinarmsError):
    """Base of the errors raised by :mod:`optim`."""


class InfeasibleProblem(OptimError):
    """No candidate within the bounds satisfies the constraints.

    Raised instead of returning an infeasible answer: widen the bounds (larger
    upper bounds on the segment durations) or relax the limits.
    """


class InvalidLimits(OptimError, ValueError):
    """A kinematic limit is missing, not finite, not positive or has the wrong shape."""


class InvalidSettings(OptimError, ValueError):
    """A GA setting, a bound or an argument of an optimiser is out of range."""
