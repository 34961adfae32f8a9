"""What the dynamics, payload and joint-limit helpers read from a robot: :class:`RobotModel`, the structural type of a
:class:`~pinarms.robots.Robot`.

:mod:`pinarms.robots.dynamics`, :mod:`pinarms.robots.payload` and :mod:`pinarms.robots.ik.near_limits` are called
by :class:`~pinarms.robots.Robot`'s methods and take the robot as their first argument. They annotate it with
this protocol, which imports none of them, so they need not import :mod:`pinarms.robots.robot` (which imports
them back): no circle, not even through imports for type checkers. Units: SI (m, rad, s, kg).
"""

from __future__ import annotations

from typing import Protocol

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

__all__ = ["RobotModel"]


class RobotModel(Protocol):
    """The attributes and methods of a robot its helpers use (see :class:`~pinarms.robots.Robot` for each)."""

    name: str
    model: pin.Model

    @property
    def nq(self) -> int: ...

    @property
    def joint_names(self) -> tuple[str, ...]: ...

    @property
    def joint_units(self) -> tuple[str, ...]: ...

    @property
    def lower(self) -> np.ndarray: ...

    @property
    def upper(self) -> np.ndarray: ...

    @property
    def neutral(self) -> np.ndarray: ...

    @property
    def velocity_limit(self) -> np.ndarray: ...

    @property
    def has_analytic_ik(self) -> bool: ...

    def check_q(self, q: ArrayLike) -> tuple[np.ndarray, bool]: ...

    def q_to_pinocchio(self, q: ArrayLike) -> np.ndarray: ...

    def random_q(self, n: int, seed: int | np.random.Generator | None = 0) -> np.ndarray: ...

    def frame_id(self, frame: str) -> int: ...

    def ik_all(self, target: ArrayLike, q_ref: ArrayLike | None = None, *, respect_limits: bool = True,
               equivalents: bool = False, limit_tolerance: float = 0.0) -> np.ndarray | list[np.ndarray]: ...
