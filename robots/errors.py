"""Exceptions of pinarms.

Every error pinarms raises on purpose derives from :class:`PinarmsError`, so a caller
can catch the whole family with one ``except``. The base lives here, in the bottom
package of the one-way flow (robots → planning → optim → viz), and the packages above
derive their own errors from it.
"""

from __future__ import annotations

__all__ = [
    "PinarmsError",
    "InvalidInput",
    "RobotNotFound",
    "ModelError",
    "UnreachableTarget",
    "LimitViolation",
    "XacroError",
    "XacroForbidden",
    "XacroLimitExceeded",
    "XacroArgError",
    "MissingMesh",
    "CellError",
    "CellNotFound",
    "CollisionGeometryError",
    "CollisionError",
]


class PinarmsError(Exception):
    """Base of every error pinarms raises on purpose."""


class InvalidInput(PinarmsError, ValueError):
    """An argument has the wrong shape, type or value (NaN, inf, negative count, ...)."""


class RobotNotFound(PinarmsError, LookupError):
    """A robot name is not known to :func:`robots.load`."""


class ModelError(PinarmsError):
    """A robot description (xacro or URDF) is malformed or cannot be modelled."""


class UnreachableTarget(PinarmsError):
    """No configuration within the joint limits reaches the requested target."""


class LimitViolation(PinarmsError):
    """A configuration or trajectory violates the robot's limits."""


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


class CollisionGeometryError(ModelError):
    """A collision geometry cannot be loaded or a pair of geometries cannot be checked."""


class CollisionError(PinarmsError):
    """A motion cannot be made collision-free; the message says which bodies block it."""


class CellNotFound(RobotNotFound):
    """A cell name is not a built-in cell, or a cell file does not exist."""
