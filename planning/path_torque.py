"""Joint torque limits along a geometric path: :class:`planning.torque.JointTorqueConstraint`.

Kept so that ``from pinarms.planning.path_torque import JointTorqueConstraint`` still works;
the one torque-limit class (path timing and segment timing) lives in :mod:`planning.torque`.
Its keyword for the limits is ``limit`` (this module's former class called it ``tau_max``).
"""

from __future__ import annotations

from pinarms.planning.torque import JointTorqueConstraint

__all__ = ["JointTorqueConstraint"]
