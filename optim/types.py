"""Names for the kinds of values the optimisers' public calls take (annotations only).

- :data:`JointLimit`: a limit per joint, one number for every joint or an ``(n,)`` array, SI
  (rad/s, rad/s², rad/s³, N·m; m/… for prismatic joints);
- :data:`JointVector`: one joint configuration ``(n,)`` [rad or m];
- :data:`AxisRange`: one coordinate of a placement grid, a fixed value or ``(lo, hi, step)``,
  or of a random draw, a fixed value or ``(lo, hi)`` [m or rad];
- :data:`Placement`: a base placement ``(x, y, z, yaw)`` [m, rad], or ``(N, 4)`` of them;
- :data:`Scheduler` (from :mod:`pinarms.execution`): where tasks run.
"""

from __future__ import annotations

from typing import Sequence, Union

import numpy as np

from pinarms.execution import Scheduler

__all__ = ["JointLimit", "JointVector", "AxisRange", "Placement", "Scheduler"]

JointLimit = Union[float, Sequence[float], np.ndarray]
JointVector = Union[Sequence[float], np.ndarray]
AxisRange = Union[float, tuple[float, float], tuple[float, float, float]]
Placement = Union[Sequence[float], np.ndarray]
