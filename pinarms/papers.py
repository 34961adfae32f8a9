"""The four papers' published numbers, exactly as printed, in one place (data only).

Each paper is one frozen dataclass instance: :data:`SEED000` (SCARA, enoki-mushroom
packing), :data:`SEED001` (AUBO-i3, food handling), :data:`SEED002` (flower-packing
gantry), :data:`SEED004` (koji-block turner). Field names carry the paper's units
(``*_deg``, ``*_mm``, ``*_rad``, ``*_s``); properties give SI conversions (m, rad) where
pinarms needs them. Every field's comment says where the paper prints it (table, equation
or section number of the paper itself); the README lists the full citations.

Nothing here is fitted, rounded or corrected: where a printed value is a typo or does not
follow from the paper's own model, it is kept as printed and the difference is reported
by the demo's paper-vs-pinarms table and in docs/. Numbers that pinarms chooses itself
(link lengths the papers omit, a representative path where none is printed) live with
the models (``robots/xacro``, ``robots/conventions.py``) or the scenarios
(``optim/scenarios.py``), never here.

>>> from pinarms.papers import SEED000
>>> SEED000.paper_total_s
3.607
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["ScaraPaper", "AuboPaper", "GantryPaper", "KojiPaper", "SEED000", "SEED001", "SEED002", "SEED004",
           "DeltaDatasheet", "IRB360_1600"]

_DEG = math.pi / 180.0
_MM = 1e-3


def _array(rows) -> np.ndarray:
    """A fresh float64 array of the printed rows (callers may modify it freely)."""
    return np.array(rows, dtype=np.float64)


# --------------------------------------------------------------------------- seed 000
@dataclass(frozen=True)
class ScaraPaper:
    """Seed 000: SCARA arm on an enoki-mushroom packing line; 3-5-3 trajectory of joint 1, GA timing."""

    # Table 1 (D-H summary, partly garbled): base height d1, upper arm, forearm.
    base_height_mm: float = 270.0
    upper_arm_mm: float = 250.0
    forearm_mm: float = 200.0
    # Table 2: joint-1 path points, start, via A, via B, end.
    path_deg: tuple[float, ...] = (55.5, 69.7, 106.5, 124.5)
    # Section 2.3, eq. (11): joint-1 velocity constraint max |v| <= 55 deg/s.
    vmax_deg_s: float = 55.0
    # Section 2.3: GA population 50, crossover probability 0.7, mutation probability 0.1
    # (rank-based fitness, stochastic sampling).
    ga_population: int = 50
    ga_crossover_probability: float = 0.7
    ga_mutation_probability: float = 0.1
    # Table 3, "initial value" column: t1, t2, t3 and Tmin.
    initial_times_s: tuple[float, ...] = (2.0, 2.0, 2.0)
    initial_total_s: float = 6.0
    # Table 3, "optimised value" column: t1, t2, t3 and Tmin.
    paper_times_s: tuple[float, ...] = (1.086, 1.243, 1.278)
    paper_total_s: float = 3.607
    # Section 2.3, text on Fig. 5: maximum joint-1 velocity along the optimised trajectory.
    peak_velocity_deg_s: float = 54.2
    # Abstract, section 2.3 and conclusion (3): "total time reduced by 39.8 %".
    reduction_percent: float = 39.8

    @property
    def path_rad(self) -> np.ndarray:
        """Joint-1 path points (rad), shape (4,)."""
        return _array(self.path_deg) * _DEG

    @property
    def vmax_rad_s(self) -> float:
        """Joint-1 velocity limit (rad/s)."""
        return self.vmax_deg_s * _DEG

    @property
    def initial_knot_times_s(self) -> np.ndarray:
        """Knot times (s) of the initial timing: 0, 2, 4, 6."""
        return np.concatenate([[0.0], np.cumsum(self.initial_times_s)])

    @property
    def paper_knot_times_s(self) -> np.ndarray:
        """Knot times (s) of the paper's optimised timing."""
        return np.concatenate([[0.0], np.cumsum(self.paper_times_s)])


# --------------------------------------------------------------------------- seed 001
@dataclass(frozen=True)
class AuboPaper:
    """Seed 001: AUBO-i3 handling food; workspace, table placement, 3-segment quintic vs Table 3."""

    # Section 1: every joint moves within ±170 deg; maximum joint speed 210 deg/s.
    joint_range_deg: float = 170.0
    vmax_deg_s: float = 210.0
    # Section 2.1: the D-H model matches the real robot at θ2 = −90°, θ4 = 90°, other joints 0.
    teach_pose_mdh_deg: tuple[float, ...] = (0.0, -90.0, 0.0, 90.0, 0.0, 0.0)
    # Section 2.2: 5000 random samples per joint; a sphere centred at (0, 0, 160) mm with
    # radius 600 mm; sparse between 500 and 600 mm.
    workspace_samples: int = 5000
    sphere_centre_mm: tuple[float, float, float] = (0.0, 0.0, 160.0)
    sphere_radius_mm: float = 600.0
    sparse_band_mm: tuple[float, float] = (500.0, 600.0)
    # Section 2.2 and abstract: food table at z > 0 mm and 200 mm < r < 500 mm.
    table_z_min_mm: float = 0.0
    table_r_min_mm: float = 200.0
    table_r_max_mm: float = 500.0
    # Section 3.2: P1 at 0 s, P2 at 1 s, P3 at 3 s, P4 at 4 s; at rest at all four points.
    via_times_s: tuple[float, ...] = (0.0, 1.0, 3.0, 4.0)
    # Table 2, joint columns J1..J6 (rad), rows P1 (start), P2 (lift), P3 (lower), P4 (end).
    table2_joints_rad: tuple[tuple[float, ...], ...] = (
        (-2.6180, -0.8727, 0.9599, 1.4835, -1.5708, 0.0000),
        (-2.6180, -0.8727, 0.7854, 1.6581, -1.5708, 0.0000),
        (0.7854, 2.2689, 2.1817, 1.6581, -1.5708, -0.7854),
        (0.7854, 2.2689, 2.3562, 1.4835, -1.5708, -0.7854),
    )
    # Table 2, Cartesian column (mm) exactly as printed: the spacing between x, y, z is lost.
    table2_cartesian_printed: tuple[str, ...] = ("(395347244)", "(395347289)", "(42222289)", "(42222244)")
    # Table 2, P1 and P2 read as (395, 347, 244) and (395, 347, 289) mm; P3 and P4 cannot
    # be split unambiguously and are not read.
    table2_p1_p2_mm: tuple[tuple[float, float, float], ...] = ((395.0, 347.0, 244.0), (395.0, 347.0, 289.0))
    # Section 3.3: joints 1-3 sampled on the robot every 0.2 s.
    table3_interval_s: float = 0.2
    # Table 3: t (s), J1, J2, J3 (rad), measured while the robot ran the planned trajectory.
    table3: tuple[tuple[float, float, float, float], ...] = (
        (0.0, -2.6180, -0.8727, 0.9599), (0.2, -2.6180, -0.8727, 0.9498), (0.4, -2.6180, -0.8727, 0.9045),
        (0.6, -2.6180, -0.8727, 0.8408), (0.8, -2.6180, -0.8727, 0.7955), (1.0, -2.6180, -0.8727, 0.7854),
        (1.2, -2.5889, -0.8458, 0.7974), (1.4, -2.4209, -0.6907, 0.8663), (1.6, -2.0630, -0.3604, 1.0131),
        (1.8, -1.5376, 0.1246, 1.2287), (2.0, -0.9163, 0.6981, 1.4836), (2.2, -0.2950, 1.2716, 1.7386),
        (2.4, 0.2304, 1.7565, 1.9541), (2.6, 0.5883, 2.0867, 2.1011), (2.8, 0.7563, 2.2416, 2.1701),
        (3.0, 0.7854, 2.2681, 2.1822), (3.2, 0.7854, 2.2689, 2.1918), (3.4, 0.7854, 2.2689, 2.2371),
        (3.6, 0.7854, 2.2689, 2.3008), (3.8, 0.7854, 2.2689, 2.3461), (4.0, 0.7854, 2.2689, 2.3562),
    )

    @property
    def table2_joints(self) -> np.ndarray:
        """Table 2 joint columns as the paper's modified D-H angles θ (rad), shape (4, 6)."""
        return _array(self.table2_joints_rad)

    @property
    def table3_t_s(self) -> np.ndarray:
        """Table 3 sample times (s), shape (21,)."""
        return _array(self.table3)[:, 0]

    @property
    def table3_joints_rad(self) -> np.ndarray:
        """Table 3 J1..J3 (rad), shape (21, 3)."""
        return _array(self.table3)[:, 1:]

    @property
    def vmax_rad_s(self) -> float:
        """Maximum joint speed (rad/s), every joint."""
        return self.vmax_deg_s * _DEG

    @property
    def joint_range_rad(self) -> float:
        """Joint range half-width (rad): every joint within ±this."""
        return self.joint_range_deg * _DEG

    @property
    def sphere_centre_m(self) -> np.ndarray:
        """Workspace sphere centre (m) in the base frame."""
        return _array(self.sphere_centre_mm) * _MM


# --------------------------------------------------------------------------- seed 002
@dataclass(frozen=True)
class GantryPaper:
    """Seed 002: three-axis gantry packing flowers; quintic B-spline, improved-GA timing.

    The limits are printed in rad/s, rad/s², rad/s³ for prismatic axes: they are
    motor-side values (``robots.conventions.gantry_motor_to_axis`` converts them).
    The paper prints no via points.
    """

    # Section 2: quintic B-splines (degree k = 5; jerk continuity needs k >= 4).
    bspline_degree: int = 5
    # Table 1: the same limits for joints 1, 2, 3 (motor side).
    vmax_motor_rad_s: float = 100.0
    amax_motor_rad_s2: float = 1500.0
    jmax_motor_rad_s3: float = 20_000.0
    # Section 3.1: shape coefficient of the non-uniform mutation, c = 2.
    mutation_shape_c: float = 2.0
    # Section 4: the lift-feed-lower path split into 10 B-spline segments; precision 0.001 s.
    segments: int = 10
    precision_s: float = 0.001
    # Section 4: initial segment times and their total.
    initial_times_s: tuple[float, ...] = (0.21, 0.15, 0.24, 0.27, 0.19, 0.16, 0.13, 0.23, 0.15, 0.16)
    initial_total_s: float = 1.89
    # Section 4: optimised total per joint, and the time saved against 1.89 s.
    per_joint_totals_s: tuple[float, float, float] = (1.823, 1.699, 1.726)
    per_joint_saved_s: tuple[float, float, float] = (0.067, 0.191, 0.164)
    # Table 2: optimised segment times h1..h10 (s), one row per joint. Rows 1 and 2 sum to
    # the section-4 totals; row 3 sums to 1.759 s, not the printed 1.726 s (kept as printed).
    table2_times_s: tuple[tuple[float, ...], ...] = (
        (0.172, 0.139, 0.281, 0.141, 0.197, 0.213, 0.130, 0.201, 0.193, 0.156),
        (0.174, 0.168, 0.102, 0.256, 0.172, 0.139, 0.143, 0.166, 0.144, 0.235),
        (0.163, 0.213, 0.159, 0.152, 0.173, 0.145, 0.142, 0.171, 0.295, 0.146),
    )
    # Section 4 and abstract: on hardware about 10 % more efficient, 60 grasps per minute.
    efficiency_gain_percent: float = 10.0
    grasps_per_minute: float = 60.0

    @property
    def limits_motor(self) -> tuple[float, float, float]:
        """(v, a, jerk) limits per joint, motor side (rad/s, rad/s², rad/s³)."""
        return self.vmax_motor_rad_s, self.amax_motor_rad_s2, self.jmax_motor_rad_s3

    @property
    def initial_durations_s(self) -> np.ndarray:
        """Initial segment times (s), shape (10,)."""
        return _array(self.initial_times_s)

    @property
    def table2_durations_s(self) -> np.ndarray:
        """Table 2 optimised segment times (s), shape (3, 10)."""
        return _array(self.table2_times_s)


# --------------------------------------------------------------------------- seed 004
@dataclass(frozen=True)
class KojiPaper:
    """Seed 004: suspended koji-block turner (QFMD010) with a parallelogram; FK, IK, simulation.

    Angles are the paper's: θ1 waist, θ2 upper-arm pitch (up), θ3 forearm pitch (its FK
    examples use the absolute angle, negative down), θ4 wrist.
    """

    # Section 1: upper arm 700 mm, forearm 650 mm, waist pivot to top 900 mm (the arm
    # hangs: d1 = −900 mm in Table 2), wrist reach H = 250 mm.
    upper_arm_mm: float = 700.0
    forearm_mm: float = 650.0
    waist_to_top_mm: float = 900.0
    wrist_reach_mm: float = 250.0
    # Table 1: joint ranges (deg) of J1..J4. (Table 2, the D-H table, prints 0 ... +55 for
    # θ3: the project uses Table 1.)
    joint_ranges_deg: tuple[tuple[float, float], ...] = ((-180.0, 180.0), (0.0, 25.0), (-30.0, 25.0), (-180.0, 180.0))
    # Section 2: the three forward-kinematics examples in the paper's order, θ1..θ4 (deg);
    # θ4 of the second is not printed (NaN).
    fk_angles_deg: tuple[tuple[float, float, float, float], ...] = (
        (-19.8, 5.5, -6.6, 19.8),
        (-49.5, 13.625, -16.35, math.nan),
        (-90.0, 25.0, -30.0, 90.0),
    )
    # Section 2: the printed positions (mm) of those examples (the last column of T4).
    fk_positions_mm: tuple[tuple[float, float, float], ...] = (
        (455.1, 1513.3, -970.5),
        (985.7, 1005.1, -918.1),
        (1197.3, 250.0, -929.2),
    )
    # Section 4, reading of Fig. 5: the simulated positions of the same three examples (mm).
    simulation_positions_mm: tuple[tuple[float, float, float], ...] = (
        (455.1, 1514.0, -970.6),
        (985.7, 1105.0, -918.1),
        (1198.0, 250.0, -929.2),
    )
    # Section 3: IK example, the third FK example's printed position (mm), position only.
    ik_target_mm: tuple[float, float, float] = (1197.3, 250.0, -929.2)
    # Section 3: θ1 = atan2(−Px, Py) = −90°, then the candidates of eq. (8) for θ2 and θ3
    # (θ3 here counted downwards, as in eq. (8)).
    ik_theta1_deg: float = -90.0
    ik_theta2_candidates_deg: tuple[float, ...] = (27.8219, 25.0271, 120.0339, 117.2390)
    ik_theta3_candidates_deg: tuple[float, ...] = (64.9729, 117.8219, 30.0339, -27.2390)
    # Section 3: the solution kept within the ranges: θ2 = 25.0271°, θ3 = 30.0339° (down).
    ik_theta2_deg: float = 25.0271
    ik_theta3_down_deg: float = 30.0339
    # Section 3: "the one-decimal position causes 0.1° of error in θ".
    ik_stated_error_deg: float = 0.1
    # Section 4: all four joints move together at these rates for 10 s.
    simulation_rates_deg_s: tuple[float, float, float, float] = (-9.0, 2.5, 3.0, 9.0)
    simulation_duration_s: float = 10.0

    @property
    def lengths_m(self) -> tuple[float, float, float, float]:
        """(a2, a3, d1, H) in metres, d1 negative (the arm hangs below the waist pivot)."""
        return self.upper_arm_mm * _MM, self.forearm_mm * _MM, -self.waist_to_top_mm * _MM, self.wrist_reach_mm * _MM

    @property
    def joint_ranges_rad(self) -> np.ndarray:
        """Table 1 ranges (rad), shape (4, 2): lower, upper."""
        return _array(self.joint_ranges_deg) * _DEG

    @property
    def fk_angles_rad(self) -> np.ndarray:
        """FK example angles (rad), shape (3, 4); NaN where the paper prints none."""
        return _array(self.fk_angles_deg) * _DEG

    @property
    def fk_positions_m(self) -> np.ndarray:
        """Printed FK positions (m), shape (3, 3)."""
        return _array(self.fk_positions_mm) * _MM

    @property
    def ik_target_m(self) -> np.ndarray:
        """IK example target position (m), shape (3,)."""
        return _array(self.ik_target_mm) * _MM

    @property
    def ik_answer_deg(self) -> np.ndarray:
        """The paper's IK answer as (θ1, θ2, θ3) with θ3 the absolute forearm pitch (up positive), deg."""
        return _array([self.ik_theta1_deg, self.ik_theta2_deg, -self.ik_theta3_down_deg])

    @property
    def simulation_rates_rad_s(self) -> np.ndarray:
        """Joint rates of the simulation (rad/s), shape (4,)."""
        return _array(self.simulation_rates_deg_s) * _DEG


SEED000 = ScaraPaper()
SEED001 = AuboPaper()
SEED002 = GantryPaper()
SEED004 = KojiPaper()


@dataclass(frozen=True)
class DeltaDatasheet:
    """A delta's published standard-cycle rates (not a paper: a manufacturer's product specification).

    ABB IRB 360 product specification, document 3HAC079010-001 ("Cycle 1 is a 25 - 305 - 25
    movement, with 90 degrees rotation of axis 4"; 35 ms of air activation at the pick and 35 ms
    at the place included), as quoted in public notes on arm selection: the IRB 360-6/1600 runs
    140, 125 and 100 picks/min at 1.0, 3.0 and 6.0 kg. Its working range, Ø1600 mm, is the
    cylinder pinarms measures on the geometry Williams (2015) prints for the FlexPicker
    (docs/delta.md).
    """

    model: str = "ABB IRB 360-6/1600"
    payloads_kg: tuple[float, ...] = (1.0, 3.0, 6.0)
    picks_per_min: tuple[float, ...] = (140.0, 125.0, 100.0)
    air_activation_s: float = 0.035      # at the pick, and again at the place, inside the cycle time
    axis4_rotation_deg: float = 90.0
    up_mm: float = 25.0
    across_mm: float = 305.0
    down_mm: float = 25.0

    @property
    def cycle_s(self) -> tuple[float, ...]:
        """Seconds per cycle (one pick and one place: there and back), 60 / rate."""
        return tuple(60.0 / r for r in self.picks_per_min)


IRB360_1600 = DeltaDatasheet()
