"""The report of a trajectory's limit check: one :class:`Violation` per joint, kind and piece.

:meth:`pinarms.planning.Trajectory.check` finds the exact extrema of the trajectory (and the torque
peaks with a robot); the functions here compare them with a :class:`pinarms.planning.JointLimits`
spec and list what exceeds it, each at the time of its worst value, in a :class:`LimitReport`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import NamedTuple, TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from pinarms.robots.robot import Robot
    from pinarms.planning.limits import JointLimits

__all__ = ["Violation", "LimitReport", "KIND_BY_ORDER", "limited_orders", "torque_violations",
           "derivative_violations", "position_violations", "limit_report"]

#: Names of the derivative orders, as used in :class:`Violation` and the peak report.
KIND_BY_ORDER = {1: "velocity", 2: "acceleration", 3: "jerk"}


class Violation(NamedTuple):
    """One limit violation: joint index, time (s) of the worst value, kind, value, limit.

    ``kind`` is one of ``"position_lower"``, ``"position_upper"``, ``"velocity"``,
    ``"acceleration"``, ``"jerk"``, ``"torque"``. For velocity/acceleration/jerk/torque
    ``value`` is the peak magnitude on the offending piece; for positions it is the extreme
    position.
    """

    joint: int
    time: float
    kind: str
    value: float
    limit: float

    @property
    def ratio(self) -> float:
        """``value / limit`` (how far past the limit; positions: the signed ratio)."""
        return self.value / self.limit if self.limit != 0.0 else float("inf")


@dataclass(frozen=True, eq=False)
class LimitReport:
    """Result of :meth:`Trajectory.check`: every violation, at most one per joint, kind and piece."""

    violations: tuple[Violation, ...] = field(default_factory=tuple)
    joint_names: tuple[str, ...] | None = None

    @property
    def ok(self) -> bool:
        """True when no limit is violated."""
        return not self.violations

    def __bool__(self) -> bool:
        return self.ok

    def __str__(self) -> str:
        if self.ok:
            return "all limits respected"
        lines = [f"{len(self.violations)} limit violation(s):"]
        for v in self.violations:
            name = f" ({self.joint_names[v.joint]})" if self.joint_names and v.joint < len(self.joint_names) else ""
            ratio = f" (ratio {v.ratio:.4g})" if v.kind in ("velocity", "acceleration", "jerk", "torque") else ""
            lines.append(
                f"  joint {v.joint}{name} at t = {v.time:.6g} s: {v.kind} {v.value:.6g} exceeds limit {v.limit:.6g}{ratio}"
            )
        return "\n".join(lines)


def limited_orders(limits: JointLimits) -> tuple[int, ...]:
    """The derivative orders (1 velocity, 2 acceleration, 3 jerk) that ``limits`` bounds."""
    return tuple(r for r, name in KIND_BY_ORDER.items() if getattr(limits, name) is not None)


def torque_violations(peak: np.ndarray, when: np.ndarray, lim: np.ndarray, rtol: float) -> list[Violation]:
    """Torque peaks (m, n) at instants ``when`` (m, n) [s] beyond the limits ``lim`` (n,) by more than ``rtol``."""
    found = []
    for seg, j in zip(*np.nonzero(peak > lim[None, :] * (1.0 + rtol))):
        found.append(Violation(int(j), float(when[seg, j]), "torque", float(peak[seg, j]), float(lim[j])))
    return found


def derivative_violations(values: np.ndarray, times: np.ndarray, orders: tuple[int, ...], limits: JointLimits, n: int,
                          rtol: float) -> list[Violation]:
    """Velocity, acceleration and jerk beyond ``limits``: ``values`` and ``times`` (len(orders), m, n, C) are
    the candidate extrema per piece (:meth:`Trajectory._extrema`); the worst of each piece is compared."""
    found = []
    mag = np.abs(values)
    best = np.argmax(mag, axis=3)[..., None]
    peak = np.take_along_axis(mag, best, axis=3)[..., 0]  # (o, m, n)
    when = np.take_along_axis(times, best, axis=3)[..., 0]
    for o, r in enumerate(orders):
        name = KIND_BY_ORDER[r]
        lim = limits.for_joints(name, n)
        bad = peak[o] > lim[None, :] * (1.0 + rtol)
        for seg, j in zip(*np.nonzero(bad)):
            found.append(Violation(int(j), float(when[o, seg, j]), name, float(peak[o, seg, j]), float(lim[j])))
    return found


def position_violations(v: np.ndarray, tm: np.ndarray, limits: JointLimits, n: int, rtol: float) -> list[Violation]:
    """Positions below ``limits.lower`` or above ``limits.upper``, from the candidate extrema ``v`` at ``tm``
    (m, n, C); the tolerance is ``rtol`` of the largest |position| (at least 1)."""
    found = []
    span = np.maximum(np.abs(v).max(), 1.0)
    if limits.lower is not None:
        lo = limits.for_joints("lower", n)
        idx = np.argmin(v, axis=2)[..., None]
        vmin = np.take_along_axis(v, idx, axis=2)[..., 0]
        tmin = np.take_along_axis(tm, idx, axis=2)[..., 0]
        for seg, j in zip(*np.nonzero(vmin < lo[None, :] - rtol * span)):
            found.append(Violation(int(j), float(tmin[seg, j]), "position_lower", float(vmin[seg, j]), float(lo[j])))
    if limits.upper is not None:
        hi = limits.for_joints("upper", n)
        idx = np.argmax(v, axis=2)[..., None]
        vmax = np.take_along_axis(v, idx, axis=2)[..., 0]
        tmax = np.take_along_axis(tm, idx, axis=2)[..., 0]
        for seg, j in zip(*np.nonzero(vmax > hi[None, :] + rtol * span)):
            found.append(Violation(int(j), float(tmax[seg, j]), "position_upper", float(vmax[seg, j]), float(hi[j])))
    return found


def limit_report(found: list[Violation], robot: Robot, n: int) -> LimitReport:
    """The violations sorted by time (then joint, kind), named by ``robot``'s joints when it has ``n``."""
    found.sort(key=lambda v: (v.time, v.joint, v.kind))
    names = tuple(robot.joint_names) if robot is not None and getattr(robot, "nq", None) == n else None
    return LimitReport(tuple(found), names)
