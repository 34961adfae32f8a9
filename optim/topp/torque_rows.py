"""The joint torque rows of several samplings of a path from one batched inverse dynamics call.

:class:`pinarms.planning.torque.JointTorqueConstraint` gives at each sample ``a = M(q) q'``,
``b = M(q) q'' + C(q, q') q'`` and the bounds ``±L − g(q)`` from three RNEA evaluations:
``g = τ(q, 0, 0)``, ``a = τ(q, 0, q') − g``, ``b = τ(q, q', q'') − g``. :func:`torque_rows`
evaluates the same three for every point of every sampling in **one** call of Pinocchio's
batched RNEA (each column computed on its own: the same numbers, bit for bit, as three calls
per sampling), which saves the fixed cost of a call (about 0.1 ms here) several times per
refinement round of the timing.
"""

from __future__ import annotations

from typing import Any, Sequence

import numpy as np

from pinarms.planning.path_constraints import PathConstraint, PathRows, PathSamples
from pinarms.planning.torque import JointTorqueConstraint

__all__ = ["batched", "torque_rows", "rows_of_samplings"]


def batched(constraint: PathConstraint) -> bool:
    """Whether :func:`torque_rows` computes ``constraint``'s rows (a :class:`JointTorqueConstraint` itself,
    not a subclass, with its robot given: its limits are resolved once)."""
    return type(constraint) is JointTorqueConstraint and constraint.robot is not None


def torque_rows(constraint: JointTorqueConstraint, samplings: Sequence[PathSamples]) -> list[PathRows]:
    """The rows of ``constraint`` at every sampling (module docstring): what ``constraint.rows`` gives for each."""
    arm, L = constraint.robot, np.asarray(constraint.limit, dtype=float)
    c = slice(None) if constraint.columns is None else constraint.columns
    parts = [(smp.q[:, c], smp.dq[:, c], smp.ddq[:, c]) for smp in samplings]
    sizes = [p[0].shape[0] for p in parts]
    n = int(arm.nq)
    if any(p[0].shape[1] != n for p in parts) or sum(sizes) == 0:  # what the constraint says of it
        return [constraint.rows(smp) for smp in samplings]
    q = np.concatenate([p[0] for p in parts])
    dq = np.concatenate([p[1] for p in parts])
    ddq = np.concatenate([p[2] for p in parts])
    zero = np.zeros_like(q)
    N = q.shape[0]
    tau = np.asarray(arm.inverse_dynamics(np.concatenate([q, q, q]), np.concatenate([zero, zero, dq]),
                                          np.concatenate([zero, dq, ddq])), dtype=float).reshape(3 * N, n)
    g, a, b = tau[:N], tau[N:2 * N] - tau[:N], tau[2 * N:] - tau[:N]
    labels = tuple(f"torque of joint {j + 1}" for j in range(n))
    out, start = [], 0
    for size in sizes:
        k = slice(start, start + size)
        out.append(PathRows(a[k], b[k], -L - g[k], L - g[k], labels))
        start += size
    return out


def rows_of_samplings(constraints: Sequence[PathConstraint], samplings: Sequence[PathSamples]) -> list[PathRows]:
    """The rows of all ``constraints`` side by side at each of ``samplings``; the joint torque rows batched."""
    per: list[list[PathRows]] = [[] for _ in samplings]
    for con in constraints:
        rows = torque_rows(con, samplings) if batched(con) else [con.rows(smp) for smp in samplings]
        for acc, r in zip(per, rows):
            acc.append(r)
    return [PathRows.concatenate(p) for p in per]
