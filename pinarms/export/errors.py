"""Errors of the export package (each is also the project's matching general class)."""

from __future__ import annotations

from pinarms.errors import InvalidInput, MissingMesh, PinarmsError

__all__ = ["ExportError", "MeshNotFound", "MeshNotAllowed", "InvalidRate", "JointMismatch", "InvalidJointName", "TrajectoryFileError"]


class ExportError(PinarmsError):
    """Something pinarms was asked to export cannot be written as asked."""


class MeshNotFound(ExportError, MissingMesh):
    """A mesh the exported description references cannot be found (the folder would not load elsewhere)."""


class MeshNotAllowed(ExportError, InvalidInput):
    """A mesh or texture an export may not copy: outside the allowed folders (links followed), not a mesh or
    image file by its suffix, or not a regular file. The message names the reference and what to pass."""


class InvalidRate(ExportError, InvalidInput):
    """A controller sample rate that is not a finite number > 0 [Hz]."""


class JointMismatch(ExportError, InvalidInput):
    """A trajectory whose joints are not those of the robot or arm it is written for."""


class InvalidJointName(ExportError, InvalidInput):
    """A joint name a controller file cannot carry: outside the ROS name rule (``[A-Za-z/][A-Za-z0-9_/]*``)."""


class TrajectoryFileError(ExportError, InvalidInput):
    """A trajectory file (YAML or CSV) that is not what the readers accept (the message names the file)."""
