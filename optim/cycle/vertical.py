"""The cycle's vertical lines, measured, and the rest between its moves: what every way of planning a cycle
(joint space, straight approach, around obstacles in :mod:`pinarms.optim.motion.transfer`) shares.

A cycle lifts from pick, lowers to place, lifts from place and lowers to pick (:data:`.spec.LINE_NAMES`);
its waypoints' first two and last two poses hold the vertical segments' ends. Lengths in m, times in s,
world frame.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from pinarms.optim.cycle.spec import LINE_SAMPLES
from pinarms.optim.timing.segments import TimingResult
from pinarms.planning import Trajectory

if TYPE_CHECKING:
    from pinarms.robots import Robot

__all__ = ["at_rest", "segment_distance", "vertical_segments", "line_deviation"]


def at_rest(q: np.ndarray, seconds: float) -> Trajectory:
    """The arm at rest at ``q`` (nq,) for ``seconds``."""
    return Trajectory([0.0, seconds], np.asarray(q, dtype=float)[None, None, :])


def segment_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance [m] of points ``p`` (..., 3) from the segments ``a``–``b`` (..., 3; broadcast against ``p``)."""
    ab = b - a
    s = np.clip(np.sum((p - a) * ab, axis=-1) / np.sum(ab * ab, axis=-1), 0.0, 1.0)
    return np.linalg.norm(p - (a + s[..., None] * ab), axis=-1)


def vertical_segments(poses: np.ndarray) -> np.ndarray:
    """(4, 2, 3) ends [m] of the vertical segments of waypoints ``poses`` (k, 4, 4), in :data:`.spec.LINE_NAMES` order."""
    P = poses[:, :3, 3]
    return np.array([[P[0], P[1]], [P[-2], P[-1]], [P[-1], P[-2]], [P[1], P[0]]])


def line_deviation(robot: Robot, moves: tuple[TimingResult, TimingResult], ends: np.ndarray) -> np.ndarray:
    """(4,) largest tcp distance [m] from the vertical segments ``ends`` (:func:`vertical_segments`) over the
    first and last segment of each of the two ``moves``, all samples in one batched FK."""
    samples = []
    for move in moves:
        t = move.knot_times
        for k in (0, len(t) - 2):  # first and last segment of each move
            samples.append(move.trajectory.sample(np.linspace(t[k], t[k + 1], LINE_SAMPLES))[0])
    q = np.concatenate(samples)
    p = np.asarray(robot.fk(q))[:, :3, 3].reshape(4, LINE_SAMPLES, 3)
    a = ends[:, 0][:, None]
    b = ends[:, 1][:, None]
    return segment_distance(p, a, b).max(axis=1)
