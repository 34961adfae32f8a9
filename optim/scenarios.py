"""The papers' timing problems as data (via points, limits, the papers' numbers).

Angles in the papers are degrees; everything here is SI (rad, m, s) unless the name
says otherwise. Used by the tests, ``benchmarks/optim.py`` and ``docs/optim.md``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["PaperScenario", "seed000", "seed001", "seed002", "GANTRY_MOTOR_RAD_PER_M"]

#: Motor-side radians per metre of gantry axis travel (the gantry model's transmission
#: k = 0.01 m/rad, docs/robots/gantry_flower.md): seed 002's limits are motor-side.
GANTRY_MOTOR_RAD_PER_M = 100.0


@dataclass(frozen=True)
class PaperScenario:
    """One paper's timing problem.

    Attributes:
        name: Short label.
        positions: (m+1, n_joints) via points (rad; seed 002: motor-side rad).
        kind: Trajectory family.
        vmax, amax, jmax: Limits per joint (SI; None: not used by the paper).
        initial_durations: The paper's initial segment times (s), if printed.
        paper: The paper's reported numbers (s, or as named).
        trajectory_options: Extra planning options.
    """

    name: str
    positions: np.ndarray
    kind: str
    vmax: np.ndarray
    amax: np.ndarray | None = None
    jmax: np.ndarray | None = None
    initial_durations: np.ndarray | None = None
    paper: dict = field(default_factory=dict)
    trajectory_options: dict = field(default_factory=dict)


def seed000() -> PaperScenario:
    """SCARA joint 1 through 55.5, 69.7, 106.5, 124.5 deg, 3-5-3, |v| <= 55 deg/s."""
    return PaperScenario(
        name="seed000 SCARA joint 1",
        positions=np.radians([55.5, 69.7, 106.5, 124.5])[:, None],
        kind="3-5-3",
        vmax=np.radians([55.0]),
        initial_durations=np.array([2.0, 2.0, 2.0]),
        paper={"durations": [1.086, 1.243, 1.278], "total": 3.607, "reduction_percent": 39.8,
               "peak_velocity_deg_s": 54.2, "initial_total": 6.0},
    )


def seed001(velocity_limit: np.ndarray | None = None) -> PaperScenario:
    """AUBO-i3 P1 -> P2 -> P3 -> P4 (Table 2, rad), three quintics at rest at every point.

    ``velocity_limit`` defaults to 210 deg/s per joint (the paper); pass
    ``robots.load("aubo_i3").velocity_limit`` to use the model's.
    """
    q = np.array([
        [-2.6180, -0.8727, 0.9599, 1.4835, -1.5708, 0.0000],
        [-2.6180, -0.8727, 0.7854, 1.6581, -1.5708, 0.0000],
        [0.7854, 2.2689, 2.1817, 1.6581, -1.5708, -0.7854],
        [0.7854, 2.2689, 2.3562, 1.4835, -1.5708, -0.7854],
    ])
    v = np.full(6, np.radians(210.0)) if velocity_limit is None else np.asarray(velocity_limit, float)
    return PaperScenario(name="seed001 AUBO-i3 P1-P4", positions=q, kind="multi-quintic",
                         vmax=v, initial_durations=np.array([1.0, 2.0, 1.0]),
                         paper={"durations": [1.0, 2.0, 1.0], "total": 4.0})


def seed002() -> PaperScenario:
    """Gantry lift-feed-lower, 11 via points, 10 quintic B-spline segments, motor side.

    The paper prints no via points; this representative path (axis metres: x 0.10 ->
    1.00, y 0.10 -> 0.34, z -0.25 -> 0 -> -0.25, lifting first, lowering last) is
    converted to motor radians with :data:`GANTRY_MOTOR_RAD_PER_M`, so that the paper's
    limits (100 rad/s, 1500 rad/s^2, 20000 rad/s^3, motor side) apply unchanged.
    """
    axis_m = np.array([
        [0.10, 0.10, -0.25], [0.10, 0.10, -0.15], [0.13, 0.11, -0.06], [0.25, 0.14, -0.01],
        [0.40, 0.18, 0.00], [0.55, 0.22, 0.00], [0.70, 0.26, 0.00], [0.85, 0.30, -0.01],
        [0.97, 0.33, -0.06], [1.00, 0.34, -0.15], [1.00, 0.34, -0.25],
    ])
    return PaperScenario(
        name="seed002 gantry lift-feed-lower",
        positions=axis_m * GANTRY_MOTOR_RAD_PER_M,
        kind="quintic-bspline",
        vmax=np.full(3, 100.0), amax=np.full(3, 1500.0), jmax=np.full(3, 20000.0),
        initial_durations=np.array([0.21, 0.15, 0.24, 0.27, 0.19, 0.16, 0.13, 0.23, 0.15, 0.16]),
        paper={"initial_total": 1.89, "per_joint_totals": [1.823, 1.699, 1.726]},
    )
