"""Exceptions of the delta family, each a kind of the project's own (:mod:`pinarms.errors`)."""

from __future__ import annotations

from pinarms.errors import InvalidInput, ModelError, UnreachableTarget

__all__ = ["ClosuresFileError", "NotADelta", "DeltaUnreachable", "ProjectionFailed", "DeltaInputError"]


class ClosuresFileError(ModelError):
    """A loop-closures file is missing, too large, malformed or names frames the model lacks."""


class NotADelta(ModelError):
    """A model and its closures do not form a three-legged delta (legs, frames or symmetry missing)."""


class DeltaUnreachable(UnreachableTarget):
    """A platform position is outside the delta's workspace (no real inverse-kinematics branch)."""


class ProjectionFailed(ModelError):
    """Newton's projection onto the loop closures did not reach the tolerance (a singular or unassemblable pose)."""


class DeltaInputError(InvalidInput):
    """An argument of the delta API has the wrong shape, is not finite or is out of its range."""
