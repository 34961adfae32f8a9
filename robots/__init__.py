"""Robots as data: URDF models in Pinocchio with batched kinematics (SI units).

>>> import robots
>>> arm = robots.load("aubo_i3")
>>> T = arm.fk(arm.neutral)          # (4, 4) tcp → base
"""

from .errors import (
    InvalidInput,
    LimitViolation,
    ModelError,
    PinarmsError,
    RobotNotFound,
    UnreachableTarget,
)
from .registry import builtin_names, from_urdf, from_urdf_text, info, load, names
from .robot import Robot

__all__ = [
    "Robot",
    "load",
    "names",
    "builtin_names",
    "info",
    "from_urdf",
    "from_urdf_text",
    "PinarmsError",
    "InvalidInput",
    "RobotNotFound",
    "ModelError",
    "UnreachableTarget",
    "LimitViolation",
]

# workspace analysis and station layout
from .layout import LayoutReport, check_layout  # noqa: E402
from .workspace import Workspace, sample_workspace  # noqa: E402

__all__ += ["Workspace", "sample_workspace", "LayoutReport", "check_layout"]

# the four papers' published numbers, as printed (data only)
from . import papers  # noqa: E402

__all__ += ["papers"]
