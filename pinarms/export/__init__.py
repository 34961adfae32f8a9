"""Hand-off to other tools: URDF, SRDF and MJCF of arms and whole cells, controller trajectories, a MuJoCo re-check.

- :mod:`.robot`: one arm as a self-contained URDF folder (:func:`export_urdf`, with
  ``srdf=True`` an SRDF beside it) or MuJoCo model (:func:`export_mjcf`);
- :mod:`.cell`: a whole cell (arms and fixtures) as URDF + SRDF + MJCF (:func:`export_cell`);
- :mod:`.srdf`: the SRDF (groups, end effectors, named states, disable_collisions from
  pinarms' proven pair classification);
- :mod:`.trajectory`: planned trajectories as ROS 2 ``JointTrajectory`` YAML and CSV at a
  controller rate; :mod:`.trajectory_read`: their readers, bounded;
- :mod:`.mesh_sources`: which mesh and texture files an export may copy (the allowed
  folders, the suffixes) and their names in the folder;
- :mod:`.verify`: a planned motion replayed in MuJoCo through the exported MJCF, distances
  compared with pinarms' (coal's).

docs/export.md shows the commands and what each consumer does with the files.
"""

from .acceleration_check import AccelerationWarning
from .cell import ExportedCell, export_cell
from .errors import ExportError, InvalidJointName, InvalidRate, JointMismatch, MeshNotAllowed, MeshNotFound, TrajectoryFileError
from .robot import SITE_SIZE_M, ExportedMJCF, ExportedURDF, export_mjcf, export_urdf, mesh_references
from .srdf import SRDF_REASON, contact_pairs, cycle_states, srdf_text
from .trajectory import (
    ControllerTrajectory,
    check_joint_names,
    controller_trajectory,
    write_trajectory_csv,
    write_trajectory_yaml,
)
from .trajectory_read import read_trajectory_csv, read_trajectory_yaml
from .verify import EngineComparison, compare_configurations_in_mujoco, compare_in_mujoco

__all__ = [
    "AccelerationWarning",
    "ExportedURDF",
    "ExportedMJCF",
    "ExportedCell",
    "export_urdf",
    "export_mjcf",
    "export_cell",
    "mesh_references",
    "SITE_SIZE_M",
    "srdf_text",
    "cycle_states",
    "contact_pairs",
    "SRDF_REASON",
    "ControllerTrajectory",
    "controller_trajectory",
    "write_trajectory_yaml",
    "write_trajectory_csv",
    "read_trajectory_yaml",
    "read_trajectory_csv",
    "EngineComparison",
    "compare_in_mujoco",
    "compare_configurations_in_mujoco",
    "ExportError",
    "MeshNotFound",
    "MeshNotAllowed",
    "InvalidRate",
    "JointMismatch",
    "InvalidJointName",
    "TrajectoryFileError",
    "check_joint_names",
]
