"""Joint limits of the numerical IK solver: wrapping, projection and the exact check (interpreted).

Rules (the compiled solver follows the same ones, :mod:`._limits_kernel`):

- continuous joints are wrapped to ``(-π, π]`` (their range is one turn);
- a free descent's revolute angles are wrapped to the ``2π`` window centred on each joint's
  range (the pose is unchanged);
- a projection puts ``q`` into the limits: a bounded revolute joint whose range spans a full
  turn or more (the UR's ±2π) is shifted by ∓2π when it leaves its range, other joints are
  clipped;
- ``in_limits`` is exact (no tolerance).

:class:`JointLimitRules` is a base class of :class:`.numerical.NumericalIK`. Units: rad or m.
"""

from __future__ import annotations

import numpy as np

from pinarms.robots.kinematic_tree import REVOLUTE

__all__ = ["JointLimitRules"]

_TWO_PI = 2.0 * np.pi


class JointLimitRules:
    """The limit rules of one robot's independent joints (see the module docstring).

    Attributes:
        lower, upper: limits ``(nq,)`` [rad or m] (continuous joints: ``±π``).
        unbounded: continuous joints; full_turn: bounded revolute joints whose range spans a full turn.
    """

    def _init_limits(self, robot) -> None:
        """Read the limits and joint kinds of ``robot`` (called by the solver's constructor)."""
        tree = robot.kinematic_tree
        nq = robot.nq
        self.unbounded = np.array(tree.coordinates.is_unbounded, dtype=bool)
        self._any_unbounded = bool(self.unbounded.any())
        self.lower = np.where(self.unbounded, -np.pi, robot.lower)
        self.upper = np.where(self.unbounded, np.pi, robot.upper)
        revolute = np.zeros(nq, dtype=bool)
        model = robot.model
        for i in range(1, model.njoints):
            joint = model.joints[i]
            if "Mimic" not in joint.shortname() and tree.kind[i] == REVOLUTE:
                revolute[joint.idx_v] = True
        #: bounded revolute joints whose range spans a full turn: leaving the range is undone by ∓2π
        self.full_turn = revolute & ~self.unbounded & (self.upper - self.lower >= _TWO_PI)
        self._any_full_turn = bool(self.full_turn.any())
        window = revolute & ~self.unbounded  # wrapped to the 2π window centred on their range
        self._any_revolute = bool(window.any())
        self._window_low = np.where(window, 0.5 * (self.lower + self.upper) - np.pi, 0.0)
        self._window_turns = np.where(window, 1.0 / _TWO_PI, 0.0)  # 0: the joint is never shifted

    def in_limits(self, q: np.ndarray) -> bool:
        """``lower ≤ q ≤ upper`` exactly (no tolerance)."""
        return not ((q < self.lower).any() or (q > self.upper).any())

    def _wrap(self, q: np.ndarray) -> np.ndarray:
        """Revolute angles of ``q`` (in place) to the ``2π`` window centred on their range, continuous ones to ``(-π, π]``."""
        if self._any_unbounded:
            u = self.unbounded
            q[u] = np.pi - (np.pi - q[u]) % _TWO_PI
        if self._any_revolute:
            q -= _TWO_PI * np.floor((q - self._window_low) * self._window_turns)
        return q

    def _clip(self, q: np.ndarray) -> bool:
        """Project ``q`` into the limits in place; ``True`` if a joint was clipped to a limit.

        Continuous joints are wrapped to ``(-π, π]``; a revolute joint whose range spans a
        full turn is shifted by ∓2π when it leaves its range; the others are clipped.
        """
        if self._any_unbounded:
            u = self.unbounded
            q[u] = np.pi - (np.pi - q[u]) % _TWO_PI
        lo, hi = self.lower, self.upper
        if not ((q < lo).any() or (q > hi).any()):
            return False
        if self._any_full_turn:
            w = self.full_turn
            q[w & (q > hi)] -= _TWO_PI
            q[w & (q < lo)] += _TWO_PI
        np.minimum(np.maximum(q, lo, out=q), hi, out=q)
        return bool(((q <= lo) | (q >= hi)).any())

    def nearest_equivalent(self, q: np.ndarray, q_ref: np.ndarray) -> np.ndarray:
        """``q`` ``(nq,)`` or ``(N, nq)`` with each bounded revolute angle at its 2π equivalent within the
        limits nearest ``q_ref`` (same shape, or ``(nq,)``): the same pose."""
        if not self._any_revolute:
            return q
        turns = self._window_turns > 0.0
        k = _TWO_PI * np.arange(-2.0, 3.0).reshape((5,) + (1,) * q.ndim)
        options = q + _TWO_PI * np.round((q_ref - q) / _TWO_PI) + k  # (5, ..., nq)
        inside = (options >= self.lower) & (options <= self.upper)
        cost = np.where(inside, np.abs(options - q_ref), np.inf)
        best = np.argmin(cost, axis=0)[None]
        pick = np.take_along_axis(options, best, 0)[0]
        ok = turns & np.isfinite(np.take_along_axis(cost, best, 0)[0])
        return np.where(ok, pick, q)

