"""Slices of an arm's seeded joint-sample stream: any samples of ``robot.random_q(n, seed)`` without the others.

The sampled workspace cut into tasks (:func:`pinarms.robots.reach.workspace.sample_workspace`) and
the streamed workspace (:mod:`pinarms.robots.reach.workspace_stream`) draw each task's samples here,
so that their result equals the one-piece run bit for bit, whoever runs the tasks.
Joint values in rad or m.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from pinarms.errors import InvalidInput

if TYPE_CHECKING:  # pragma: no cover
    from pinarms.robots.robot import Robot

__all__ = ["random_q_slice", "generator_at"]


def generator_at(robot: "Robot", seed: int, start: int) -> np.random.Generator:
    """``default_rng(seed)`` advanced past the draws of samples ``0 … start-1`` of ``random_q``."""
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise InvalidInput(f"seed must be an integer >= 0, got {seed!r}")
    bit = np.random.PCG64(int(seed))
    bit.advance(int(start) * robot.nq)
    return np.random.Generator(bit)


def random_q_slice(robot: "Robot", seed: int, start: int, count: int) -> np.ndarray:
    """Samples ``start … start+count-1`` of ``robot.random_q(n, seed)``, without drawing the others.

    ``random_q`` draws ``(n, nq)`` uniforms row by row from ``numpy.random.default_rng(seed)``
    (PCG64, one 64-bit draw per number), so sample ``i`` starts at draw ``i·nq``: the
    generator jumps there (``PCG64.advance``) in a few microseconds.
    """
    for name, v in (("start", start), ("count", count)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < 0:
            raise InvalidInput(f"{name} must be an integer >= 0, got {v!r}")
    return generator_at(robot, seed, start).uniform(robot.lower, robot.upper, size=(int(count), robot.nq))
