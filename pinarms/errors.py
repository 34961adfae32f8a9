"""Exceptions of pinarms.

Every error pinarms raises on purpose derives from :class:`PinarmsError`, so a caller
can catch the whole family with one ``except``. The hierarchy lives here, in the floor
that every package may import (with the execution layer, atomic files and units), and
imports nothing of ours; the packages above derive their own errors from it.

This is the one module users import errors from: the classes of the floor and of the robots are
defined here; the errors of each area above (trajectories and paths, optimisation and motion
planning, the line, sessions and viewers, exports) are defined in that area's ``errors`` module and
offered here too (:data:`AREA_ERRORS`), loaded on first use, so that this module imports nothing of
the packages above it: ``from pinarms.errors import NoPathFound, SessionFormatError``.
"""

from __future__ import annotations

from pinarms.lazy import lazy_exports

__all__ = [
    "PinarmsError",
    "InvalidInput",
    "RobotNotFound",
    "ModelError",
    "UnreachableTarget",
    "LimitViolation",
    "ExecutionError",
    "XacroError",
    "XacroForbidden",
    "XacroLimitExceeded",
    "XacroArgError",
    "MissingMesh",
    "CellError",
    "CellNotFound",
    "XacroFileNotFound",
    "CellTooLarge",
    "PlacementError",
    "ArmStateError",
    "SelfContactError",
    "CollisionGeometryError",
    "CollisionError",
]


class PinarmsError(Exception):
    """Base of every error pinarms raises on purpose."""


class InvalidInput(PinarmsError, ValueError):
    """An argument has the wrong shape, type or value (NaN, inf, negative count, ...)."""


class RobotNotFound(PinarmsError, LookupError):
    """A robot name is not known to :func:`pinarms.robots.load`."""


class ModelError(PinarmsError):
    """A robot description (xacro or URDF) is malformed or cannot be modelled."""


class UnreachableTarget(PinarmsError):
    """No configuration within the joint limits reaches the requested target."""


class LimitViolation(PinarmsError):
    """A configuration or trajectory violates the robot's limits."""


class ExecutionError(PinarmsError):
    """A chunk of a sweep failed: its task raised, or the worker running it died.

    Raised by :func:`pinarms.execution.map_chunks` (serial loop or Dask cluster alike) instead
    of returning a partial result. ``chunk`` is the failing task's index in the task list
    (``None`` when the cluster itself could not be reached), ``seed`` the task's seed when it
    carries one, ``cause`` a one-line description of the original error. Re-run the chunk on
    its own with that seed to reproduce it.
    """

    def __init__(self, message: str, *, chunk: int | None = None, seed: int | None = None,
                 cause: str = "") -> None:
        super().__init__(message)
        self.chunk = chunk
        self.seed = seed
        self.cause = cause

    def __reduce__(self):  # keep the fields when the error crosses a process boundary
        return (_rebuild_execution_error, (str(self), self.chunk, self.seed, self.cause))


def _rebuild_execution_error(message, chunk, seed, cause):
    return ExecutionError(message, chunk=chunk, seed=seed, cause=cause)


class XacroError(ModelError):
    """xacro cannot expand a file: unknown macro, undefined property, malformed XML, missing file."""


class XacroForbidden(XacroError):
    """A xacro file reads outside its allowed folders or uses a construct pinarms refuses."""


class XacroLimitExceeded(XacroError):
    """Expanding a xacro file took too long, needed too much memory or produced too much text."""


class XacroArgError(XacroError, InvalidInput):
    """A xacro argument is not declared by the file, or is not a number where a number is due."""


class MissingMesh(ModelError):
    """A mesh file named by a description does not exist."""


class CellError(ModelError):
    """A cell description is malformed: duplicate names, no arm, an arm that cannot be modelled."""


class CellTooLarge(CellError):
    """A cell file, mesh, or the cell's count of arms, fixtures or geometries is above pinarms' limit."""


class _PairsInContact(Exception):
    """An error carrying ``pairs``: ``(body_a, body_b, share, depth)`` per pair of links, the share of
    the sampled configurations in contact and the deepest penetration found [m]."""

    def __init__(self, message: str, *, pairs: tuple = ()) -> None:
        super().__init__(message)
        self.pairs = tuple(pairs)

    def __reduce__(self):  # keep the pairs when the error crosses a process boundary
        return (_rebuild_pairs_error, (type(self), str(self), self.pairs))


def _rebuild_pairs_error(cls: type, message: str, pairs: tuple) -> Exception:
    return cls(message, pairs=pairs)


class PlacementError(_PairsInContact, CellError):
    """A fixture or an arm meets a moving link in (almost) every configuration: placed through it.

    ``pairs`` holds ``(body_a, body_b, share, depth)`` per pair of links: the share of the
    sampled configurations in contact and the deepest penetration found [m]. Move the fixture
    or the arm, or declare the contact by name in the cell file (``<disable_collisions>``).
    """


class ArmStateError(CellError):
    """A cell arm's named state, hold pose or frozen joint value is outside its joint limits, has the
    wrong number of values, or names a state the arm does not have (the message names the arm and the joint)."""


class SelfContactError(_PairsInContact, ModelError):
    """Two links of one arm are in contact in (almost) every configuration, and no proof explains it.

    ``pairs`` holds ``(body_a, body_b, share, depth)`` per pair of links: the share of the sampled
    configurations in contact and the deepest penetration found [m]. Fix the collision shapes, or
    declare the contact by name in the URDF (``<disable_collisions link1= link2= reason=/>``).
    """


class CollisionGeometryError(ModelError):
    """A collision geometry cannot be loaded or a pair of geometries cannot be checked."""


class CollisionError(PinarmsError):
    """A motion cannot be made collision-free; the message says which bodies block it."""


class CellNotFound(RobotNotFound):
    """A cell name is not a built-in cell, or a cell file does not exist."""


class XacroFileNotFound(XacroError, CellNotFound):
    """A xacro file, a file it includes or a yaml file it loads does not exist (the message names it).

    Both a :class:`XacroError` and the not-found error of cells (:class:`CellNotFound`, a
    ``LookupError``), so a cell whose included arm file is missing is caught either way.
    """


#: The errors of the areas above the floor, each defined in its area's ``errors`` module and offered
#: here on first use (:func:`pinarms.lazy.lazy_exports`): every error of pinarms from one module.
AREA_ERRORS = {
    "TrajectoryError": "pinarms.planning.errors",
    "ConditionCountError": "pinarms.planning.errors",
    "OutOfTimeRange": "pinarms.planning.errors",
    "BlendTooLarge": "pinarms.planning.errors",
    "PathError": "pinarms.planning.errors",
    "SingularityOnPath": "pinarms.planning.errors",
    "JointLimitOnPath": "pinarms.planning.errors",
    "UnreachableOnPath": "pinarms.planning.errors",
    "OptimError": "pinarms.optim.errors",
    "InfeasibleProblem": "pinarms.optim.errors",
    "InvalidLimits": "pinarms.optim.errors",
    "InvalidSettings": "pinarms.optim.errors",
    "SettingOutOfRange": "pinarms.optim.errors",
    "PlanningError": "pinarms.optim.errors",
    "EndpointInCollision": "pinarms.optim.errors",
    "StartInCollision": "pinarms.optim.errors",
    "GoalInCollision": "pinarms.optim.errors",
    "NoPathFound": "pinarms.optim.errors",
    "BeltOutOfReach": "pinarms.optim.line.errors",
    "ArrivalsFileError": "pinarms.optim.line.errors",
    "TaskMapError": "pinarms.optim.line.errors",
    "VizError": "pinarms.viz.errors",
    "SessionFormatError": "pinarms.viz.errors",
    "ViewerError": "pinarms.viz.errors",
    "ExportError": "pinarms.export.errors",
    "MeshNotFound": "pinarms.export.errors",
    "MeshNotAllowed": "pinarms.export.errors",
    "InvalidRate": "pinarms.export.errors",
    "JointMismatch": "pinarms.export.errors",
    "InvalidJointName": "pinarms.export.errors",
    "TrajectoryFileError": "pinarms.export.errors",
    "ClosuresFileError": "pinarms.robots.delta.errors",
    "NotADelta": "pinarms.robots.delta.errors",
    "DeltaUnreachable": "pinarms.robots.delta.errors",
    "ProjectionFailed": "pinarms.robots.delta.errors",
    "DeltaInputError": "pinarms.robots.delta.errors",
}

__all__ += list(AREA_ERRORS)

__getattr__, __dir__ = lazy_exports(__name__, AREA_ERRORS)
