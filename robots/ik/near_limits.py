"""Closed-form solutions that miss the joint ranges by a little: how far, and which joints.

A printed pose often needs a joint a rounding error past its range end (seed 004's
(−90, 25, −30, 90)° lands the koji arm's shoulder 0.0011° above its 25° end). The solvers
rightly drop such solutions; :func:`near_limit_solutions` finds them again and says by how
much each joint misses, so that a caller can tell the user, who may then accept them with
``Robot.ik(..., limit_tolerance=...)`` / ``Robot.ik_all(..., limit_tolerance=...)``.

Units: rad for revolute joints, m for prismatic ones. A revolute angle is taken at its 2π
equivalent nearest its range (its excess is the smallest one over all equivalents).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from pinarms.errors import InvalidInput
from pinarms.robots.robot_model import RobotModel

__all__ = ["OutsideLimits", "limit_excess", "near_limit_solutions"]

_TWO_PI = 2.0 * np.pi


@dataclass(frozen=True)
class OutsideLimits:
    """A configuration outside the joint limits, and by how much.

    Attributes:
        q: ``(nq,)`` the configuration [rad or m] (revolute angles at the 2π equivalent
            nearest their range).
        excess: ``(nq,)`` signed distance outside each range [rad or m]: ``> 0`` above the
            upper limit, ``< 0`` below the lower one, ``0`` within.
        joints: names of the joints outside their range, in ``q`` order.
    """

    q: np.ndarray
    excess: np.ndarray
    joints: tuple[str, ...]

    @property
    def worst(self) -> float:
        """Largest ``|excess|`` [rad or m]."""
        return float(np.max(np.abs(self.excess))) if self.excess.size else 0.0


def limit_excess(robot: RobotModel, q: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """``(q_wrapped, excess)`` of configurations ``q (N, nq)`` (or ``(nq,)``): see :class:`OutsideLimits`."""
    arr, single = robot.check_q(q)
    arr = arr.copy()
    lo, hi = robot.lower, robot.upper
    revolute = np.array([u == "rad" for u in robot.joint_units])
    if revolute.any():
        mid = 0.5 * (lo + hi)
        wrapped = mid + (arr - mid + np.pi) % _TWO_PI - np.pi
        arr[:, revolute] = wrapped[:, revolute]
    excess = np.where(arr > hi, arr - hi, np.where(arr < lo, arr - lo, 0.0))
    return (arr[0], excess[0]) if single else (arr, excess)


def near_limit_solutions(robot: RobotModel, target: ArrayLike, within: float) -> list[OutsideLimits]:
    """Closed-form solutions of one pose ``(4, 4)`` that lie outside the joint ranges by at most ``within``.

    Args:
        robot: a :class:`pinarms.robots.Robot` with a closed form (``robot.has_analytic_ik``).
        target: tcp pose ``(4, 4)``, frame → base [m].
        within: the largest excess of any joint [rad or m] reported (> 0).

    Returns:
        The solutions outside the limits, smallest worst excess first (ties: the order of
        :meth:`pinarms.robots.Robot.ik_all`); solutions within the limits are not listed.
    """
    if isinstance(within, bool) or not isinstance(within, (int, float, np.integer, np.floating)) \
            or not (np.isfinite(within) and within > 0):
        raise InvalidInput(f"within must be a positive distance in rad or m, got {within!r}")
    free = np.atleast_2d(robot.ik_all(target, respect_limits=False))
    if free.size == 0:
        return []
    q, excess = limit_excess(robot, free)
    worst = np.max(np.abs(excess), axis=1)
    keep = np.flatnonzero((worst > 1e-9) & (worst <= within))
    keep = keep[np.argsort(worst[keep], kind="stable")]
    names = robot.joint_names
    return [OutsideLimits(q[k], excess[k], tuple(n for n, e in zip(names, excess[k]) if e != 0.0)) for k in keep]
