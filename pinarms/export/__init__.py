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

from __future__ import annotations

from pinarms.lazy import lazy_exports

#: Where each public name is defined: loaded on first use (:func:`pinarms.lazy.lazy_exports`).
_EXPORTS = {
    "AccelerationWarning": "pinarms.export.acceleration_check",
    "ExportedCell": "pinarms.export.cell",
    "export_cell": "pinarms.export.cell",
    "ExportError": "pinarms.export.errors",
    "InvalidJointName": "pinarms.export.errors",
    "InvalidRate": "pinarms.export.errors",
    "JointMismatch": "pinarms.export.errors",
    "MeshNotAllowed": "pinarms.export.errors",
    "MeshNotFound": "pinarms.export.errors",
    "TrajectoryFileError": "pinarms.export.errors",
    "SITE_SIZE_M": "pinarms.export.robot",
    "ExportedMJCF": "pinarms.export.robot",
    "ExportedURDF": "pinarms.export.urdf_files",
    "export_mjcf": "pinarms.export.robot",
    "export_urdf": "pinarms.export.robot",
    "mesh_references": "pinarms.export.urdf_files",
    "SRDF_REASON": "pinarms.export.srdf",
    "contact_pairs": "pinarms.export.srdf",
    "cycle_states": "pinarms.export.srdf",
    "srdf_text": "pinarms.export.srdf",
    "ControllerTrajectory": "pinarms.export.trajectory",
    "check_joint_names": "pinarms.export.trajectory",
    "controller_trajectory": "pinarms.export.trajectory",
    "write_trajectory_csv": "pinarms.export.trajectory",
    "write_trajectory_yaml": "pinarms.export.trajectory",
    "read_trajectory_csv": "pinarms.export.trajectory_read",
    "read_trajectory_yaml": "pinarms.export.trajectory_read",
    "EngineComparison": "pinarms.export.verify",
    "compare_configurations_in_mujoco": "pinarms.export.verify",
    "compare_in_mujoco": "pinarms.export.verify",
}

__all__ = [
    "AccelerationWarning", "ExportedURDF", "ExportedMJCF", "ExportedCell", "export_urdf", "export_mjcf",
    "export_cell", "mesh_references", "SITE_SIZE_M", "srdf_text", "cycle_states", "contact_pairs", "SRDF_REASON",
    "ControllerTrajectory", "controller_trajectory", "write_trajectory_yaml", "write_trajectory_csv",
    "read_trajectory_yaml", "read_trajectory_csv", "EngineComparison", "compare_in_mujoco",
    "compare_configurations_in_mujoco", "ExportError", "MeshNotFound", "MeshNotAllowed", "InvalidRate",
    "JointMismatch", "InvalidJointName", "TrajectoryFileError", "check_joint_names",
]

__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
