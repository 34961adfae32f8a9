"""Delta robots: a tree opened at the platform plus loop closures, in Pinocchio (docs/delta.md).

>>> from pinarms.robots.delta import load_delta, forward_position, inverse_position
>>> delta = load_delta("delta_flexpicker")
>>> p = forward_position(delta.geometry, [0.3, 0.3, 0.3])      # platform centre [m]
"""

from pinarms.robots.delta.closures import (CLOSURE_TYPES, MAX_CLOSURES, MAX_CLOSURES_BYTES, ClosureSet, LoopClosure, closures_to_xml,
                       constraint_models, parse_closures, read_closures, write_closures)
from pinarms.robots.delta.errors import ClosuresFileError, DeltaInputError, DeltaUnreachable, NotADelta, ProjectionFailed
from pinarms.robots.delta.family import family_closures
from pinarms.robots.delta.dynamics import ClosedChainState, check_with_constraint_dynamics, closed_chain_state, motor_torques
from pinarms.robots.delta.geometry import LEG_COUNT, DeltaGeometry
from pinarms.robots.delta.kinematics import (BRANCH_COUNT, PRIMARY_BRANCH, branch_signs, elbow_positions, forward_position,
                         inverse_position, inverse_position_branches, virtual_elbows)
from pinarms.robots.delta.jacobian import constraint_matrices, platform_jacobian, platform_jacobian_pinocchio
from pinarms.robots.delta.model import DeltaRobot, MotorLimits
from pinarms.robots.delta.rods import rod_endpoints
from pinarms.robots.delta.singularities import SingularityReport, singularities
from pinarms.robots.delta.virtual_work import body_frames, virtual_work_torques
from pinarms.robots.delta.workspace import CylinderDome, WorkspaceSamples, cylinder_dome, reachable, sample_workspace
from pinarms.robots.delta.shipped import DeltaInfo, delta_from_files, delta_info, delta_names, load_delta

__all__ = [
    "DeltaRobot", "MotorLimits", "DeltaGeometry", "LEG_COUNT", "DeltaInfo", "load_delta", "delta_from_files",
    "delta_names", "delta_info", "LoopClosure", "ClosureSet", "MAX_CLOSURES", "MAX_CLOSURES_BYTES", "CLOSURE_TYPES",
    "parse_closures", "read_closures", "closures_to_xml", "write_closures", "constraint_models", "family_closures",
    "forward_position", "inverse_position", "inverse_position_branches", "elbow_positions", "virtual_elbows",
    "branch_signs", "BRANCH_COUNT", "PRIMARY_BRANCH", "constraint_matrices", "platform_jacobian",
    "platform_jacobian_pinocchio", "SingularityReport", "singularities", "CylinderDome", "WorkspaceSamples",
    "cylinder_dome", "reachable", "sample_workspace", "ClosedChainState", "closed_chain_state", "motor_torques",
    "check_with_constraint_dynamics", "body_frames", "virtual_work_torques", "rod_endpoints",
    "ClosuresFileError", "NotADelta", "DeltaUnreachable", "ProjectionFailed", "DeltaInputError",
]
