"""Robots as data: URDF models in Pinocchio with batched kinematics (SI units).

>>> from pinarms import robots
>>> arm = robots.load("aubo_i3")
>>> T = arm.fk(arm.neutral)          # (4, 4) tcp → base
"""

from .errors import (
    ExecutionError,
    InvalidInput,
    CellError,
    CellNotFound,
    CollisionError,
    CollisionGeometryError,
    LimitViolation,
    MissingMesh,
    ModelError,
    PinarmsError,
    RobotNotFound,
    UnreachableTarget,
    XacroArgError,
    XacroError,
    XacroFileNotFound,
    XacroForbidden,
    XacroLimitExceeded,
)
from .registry import builtin_names, from_urdf, from_urdf_text, from_xacro, info, load, names
from .robot import Robot

__all__ = [
    "Robot",
    "load",
    "names",
    "builtin_names",
    "info",
    "from_urdf",
    "from_urdf_text",
    "from_xacro",
    "PinarmsError",
    "InvalidInput",
    "RobotNotFound",
    "ModelError",
    "UnreachableTarget",
    "LimitViolation",
    "ExecutionError",
    "XacroError",
    "XacroForbidden",
    "XacroFileNotFound",
    "XacroLimitExceeded",
    "XacroArgError",
    "MissingMesh",
    "CellError",
    "CellNotFound",
    "CollisionGeometryError",
    "CollisionError",
]

# workspace analysis and station layout
from .reach.layout import LayoutReport, check_layout  # noqa: E402
from .reach.table_band import RecommendedRegion, recommend_region  # noqa: E402
from .self_collision import SelfCollision  # noqa: E402
from .reach.voxels import VoxelMap, suggest_voxel_size  # noqa: E402
from .reach.workspace import SphereFit, Workspace, WorkspaceSummary, fit_sphere, sample_workspace  # noqa: E402
from .reach.workspace_stream import StreamedWorkspace, stream_workspace  # noqa: E402

__all__ += [
    "Workspace",
    "WorkspaceSummary",
    "SphereFit",
    "sample_workspace",
    "fit_sphere",
    "StreamedWorkspace",
    "stream_workspace",
    "VoxelMap",
    "suggest_voxel_size",
    "RecommendedRegion",
    "recommend_region",
    "SelfCollision",
    "LayoutReport",
    "check_layout",
]

# dynamics: payloads, joint torques (Robot.inverse_dynamics, Robot.gravity, Robot.with_payload)
from .dynamics import MissingInertials  # noqa: E402
from .payload import InvalidPayload, Payload  # noqa: E402

__all__ += ["Payload", "InvalidPayload", "MissingInertials"]

# users' xacro files, expanded behind a wall
from .xacro_expand import XacroLimits, expand_xacro  # noqa: E402

__all__ += ["XacroLimits", "expand_xacro"]

# cells: several arms, fixtures, collision checks
from .cell import (  # noqa: E402
    ArmMotion,
    Cell,
    CellArm,
    Clearance,
    Collisions,
    CollisionPair,
    MotionCheck,
    cell_names,
    load_cell,
)
from .cell.compose import ArmPlacement, FixturePrimitive, ToolPoint, compose_cell  # noqa: E402

__all__ += ["Cell", "CellArm", "Clearance", "Collisions", "CollisionPair", "ArmMotion", "MotionCheck", "cell_names",
            "load_cell", "ArmPlacement", "FixturePrimitive", "ToolPoint", "compose_cell"]

# reachability maps: tool poses per voxel, orientation sets, HDF5 files
from .reach.orientations import (  # noqa: E402
    OrientationSet,
    so3_orientations,
    tool_axis_orientations,
    tool_down_orientations,
)
from .reach.reach_io import ReachabilityFileError, load_reachability, save_reachability  # noqa: E402
from .reach.reachability import ReachabilityMap, reach_bound, reachability_map  # noqa: E402
from ._checks import MAX_RESTARTS  # noqa: E402
from .reach.inverse_reach import BasePlacements, base_placements, tool_down_poses  # noqa: E402

__all__ += [
    "ReachabilityMap",
    "MAX_RESTARTS",
    "reachability_map",
    "reach_bound",
    "OrientationSet",
    "so3_orientations",
    "tool_axis_orientations",
    "tool_down_orientations",
    "ReachabilityFileError",
    "save_reachability",
    "load_reachability",
    "BasePlacements",
    "base_placements",
    "tool_down_poses",
]
