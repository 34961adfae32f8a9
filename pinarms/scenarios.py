"""The papers' timing problems as data (via points, limits, the papers' numbers).

Angles in the papers are degrees; everything here is SI (rad, m, s) unless the name
says otherwise. The published numbers come from :mod:`pinarms.papers`; the one thing
this module adds is seed 002's representative lift-feed-lower path
(:data:`GANTRY_PATH_AXIS_M`), because the paper prints none. Used by the demo, the tests,
``benchmarks/optim.py`` and ``docs/optim.md``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from pinarms.robots.conventions import GANTRY_TRANSMISSION_M_PER_RAD
from pinarms.papers import SEED000, SEED001, SEED002

__all__ = ["PaperScenario", "seed000", "seed001", "seed002", "GANTRY_PATH_AXIS_M", "gantry_path_motor_rad",
           "GANTRY_MOTOR_RAD_PER_M"]

#: Motor-side radians per metre of gantry axis travel: 1 / the gantry model's transmission
#: (:data:`pinarms.robots.conventions.GANTRY_TRANSMISSION_M_PER_RAD`); seed 002's limits are motor-side.
GANTRY_MOTOR_RAD_PER_M: float = 1.0 / GANTRY_TRANSMISSION_M_PER_RAD

#: pinarms's representative lift-feed-lower path of the flower gantry (seed 002 prints no
#: via points): 11 via points = 10 B-spline segments, axis metres (x, y, z) inside the
#: model's travel. It clamps at (0.10, 0.10, -0.25), lifts 0.25 m while starting to feed,
#: feeds 0.90 m in x and 0.24 m in y at the top, and lowers 0.25 m onto (1.00, 0.34, -0.25).
#: Not the paper's path; read-only.
GANTRY_PATH_AXIS_M: np.ndarray = np.array([
    [0.10, 0.10, -0.25], [0.10, 0.10, -0.15], [0.13, 0.11, -0.06], [0.25, 0.14, -0.01],
    [0.40, 0.18, 0.00], [0.55, 0.22, 0.00], [0.70, 0.26, 0.00], [0.85, 0.30, -0.01],
    [0.97, 0.33, -0.06], [1.00, 0.34, -0.15], [1.00, 0.34, -0.25],
])
GANTRY_PATH_AXIS_M.setflags(write=False)


def gantry_path_motor_rad() -> np.ndarray:
    """:data:`GANTRY_PATH_AXIS_M` in motor radians, (11, 3), a fresh array.

    Axis metres / :data:`pinarms.robots.conventions.GANTRY_TRANSMISSION_M_PER_RAD`, so that the
    paper's motor-side limits (100 rad/s, 1500 rad/s^2, 20000 rad/s^3) apply unchanged.
    """
    return GANTRY_PATH_AXIS_M / GANTRY_TRANSMISSION_M_PER_RAD


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
        positions=SEED000.path_rad[:, None],
        kind="3-5-3",
        vmax=np.array([SEED000.vmax_rad_s]),
        initial_durations=np.array(SEED000.initial_times_s),
        paper={"durations": list(SEED000.paper_times_s), "total": SEED000.paper_total_s,
               "reduction_percent": SEED000.reduction_percent,
               "peak_velocity_deg_s": SEED000.peak_velocity_deg_s, "initial_total": SEED000.initial_total_s},
    )


def seed001(velocity_limit: np.ndarray | None = None) -> PaperScenario:
    """AUBO-i3 P1 -> P2 -> P3 -> P4 (Table 2, rad), three quintics at rest at every point.

    ``velocity_limit`` defaults to 210 deg/s per joint (the paper); pass
    ``robots.load("aubo_i3").velocity_limit`` to use the model's.
    """
    q = SEED001.table2_joints
    v = np.full(6, SEED001.vmax_rad_s) if velocity_limit is None else np.asarray(velocity_limit, float)
    durations = np.diff(SEED001.via_times_s)
    return PaperScenario(name="seed001 AUBO-i3 P1-P4", positions=q, kind="multi-quintic",
                         vmax=v, initial_durations=durations,
                         paper={"durations": list(durations), "total": SEED001.via_times_s[-1]})


def seed002() -> PaperScenario:
    """Gantry lift-feed-lower, 11 via points, 10 quintic B-spline segments, motor side.

    The paper prints no via points; :data:`GANTRY_PATH_AXIS_M` (axis metres: x 0.10 ->
    1.00, y 0.10 -> 0.34, z -0.25 -> 0 -> -0.25, lifting first, lowering last) is converted
    to motor radians (:func:`gantry_path_motor_rad`), so that the paper's limits
    (100 rad/s, 1500 rad/s^2, 20000 rad/s^3, motor side) apply unchanged.
    """
    v, a, j = SEED002.limits_motor
    return PaperScenario(
        name="seed002 gantry lift-feed-lower",
        positions=gantry_path_motor_rad(),
        kind="quintic-bspline",
        vmax=np.full(3, v), amax=np.full(3, a), jmax=np.full(3, j),
        initial_durations=SEED002.initial_durations_s,
        paper={"initial_total": SEED002.initial_total_s, "per_joint_totals": list(SEED002.per_joint_totals_s)},
    )
