"""3-5-3 and other mixed-degree piecewise polynomials (seed 000)."""

from __future__ import annotations

import numpy as np
import pytest

from pinarms import planning
from pinarms.papers import SEED000
from pinarms.planning.errors import ConditionCountError, TrajectoryError

# Seed 000, joint 1 path points (degrees) and segment times (s).
JOINT1_DEG = np.array(SEED000.path_deg)
INITIAL_TIMES = SEED000.initial_times_s
OPTIMISED_TIMES = SEED000.paper_times_s
PAPER_PEAK_DEG_S = SEED000.peak_velocity_deg_s


def knots(durations):
    return np.concatenate([[0.0], np.cumsum(durations)])


def paper_closed_form(theta, t1, t2, t3):
    """Seed 000 eqs. (8)-(10): coefficients a_ij of each segment in normalised time s in [0, 1]."""
    th0, th1, th2, th3 = theta
    a10, a11, a12, a13 = th0, 0.0, 0.0, th1 - th0
    a30, a31, a32, a33 = th2, 3 * th3 - 3 * th2, -3 * th3 + 3 * th2, th3 - th2
    a20 = th1
    a21 = 3 * a13 * t2 / t1
    a22 = 3 * a13 * t2**2 / t1**2
    c1 = th2 - th1 - a21 - a22
    c2 = a31 * t2 / t3 - 2 * a22 - a21
    c3 = a32 * t2**2 / t3**2 - a22
    a23 = 10 * c1 - 4 * c2 + c3
    a24 = -15 * c1 + 7 * c2 - 2 * c3
    a25 = 6 * c1 - 3 * c2 + c3
    return (
        np.array([a10, a11, a12, a13]),
        np.array([a20, a21, a22, a23, a24, a25]),
        np.array([a30, a31, a32, a33]),
    )


@pytest.mark.parametrize("durations", [INITIAL_TIMES, OPTIMISED_TIMES, (0.7, 2.3, 1.1)])
def test_353_matches_seed000_closed_form(durations):
    theta = np.deg2rad(JOINT1_DEG)
    traj = planning.piecewise_polynomial(knots(durations), theta, "3-5-3")
    segs = paper_closed_form(theta, *durations)
    t = knots(durations)
    s = np.linspace(0.0, 1.0, 11)
    for i, a in enumerate(segs):
        h = durations[i]
        q_paper = np.polyval(a[::-1], s)
        v_paper = np.polyval(np.polyder(a[::-1]), s) / h
        acc_paper = np.polyval(np.polyder(a[::-1], 2), s) / h**2
        q, v, acc, _ = traj.sample(t[i] + s * h * (1 - 1e-12))
        np.testing.assert_allclose(q[:, 0], q_paper, atol=1e-12)
        np.testing.assert_allclose(v[:, 0], v_paper, atol=1e-11)
        np.testing.assert_allclose(acc[:, 0], acc_paper, atol=1e-10)
    # The stored real-time coefficients are the paper's divided by h^k.
    a2 = segs[1]
    np.testing.assert_allclose(traj.coefficients[1, :, 0], a2 / durations[1] ** np.arange(6), rtol=1e-10, atol=1e-12)


def test_353_conditions_hold():
    q = np.deg2rad(np.column_stack([JOINT1_DEG, JOINT1_DEG[::-1] * 0.5]))
    t = knots(OPTIMISED_TIMES)
    traj = planning.piecewise_polynomial(t, q, (3, 5, 3))
    eps = 1e-9
    qs, vs, accs, _ = traj.sample(t)
    np.testing.assert_allclose(qs, q, atol=1e-12)
    np.testing.assert_allclose(vs[[0, -1]], 0.0, atol=1e-12)
    np.testing.assert_allclose(accs[[0, -1]], 0.0, atol=1e-10)
    left = traj.sample(t[1:3] - eps)
    right = traj.sample(t[1:3])
    for r in (1, 2):  # velocity and acceleration continuous at the via points
        np.testing.assert_allclose(left[r], right[r], atol=1e-6)
    # The jerk is not continuous for 3-5-3 (that needs higher degrees): a visible step.
    assert np.abs(left[3] - right[3]).max() > 1e-3


def test_434_preset_is_solvable_and_at_rest():
    t = knots((1.0, 1.5, 1.0))
    traj = planning.piecewise_polynomial(t, [0.0, 0.4, 1.2, 1.5], "4-3-4")
    assert traj.degree == 4
    q, v, a, _ = traj.sample(t)
    np.testing.assert_allclose(q[:, 0], [0.0, 0.4, 1.2, 1.5], atol=1e-12)
    np.testing.assert_allclose(v[[0, -1], 0], 0.0, atol=1e-12)
    np.testing.assert_allclose(a[[0, -1], 0], 0.0, atol=1e-12)


def test_555_with_c4_continuity_counts_match():
    # 18 unknowns = 6 positions + 4 end conditions + 2 knots x 4 continuity orders.
    t = knots((1.0, 1.0, 1.0))
    traj = planning.piecewise_polynomial(t, [0.0, 1.0, 0.5, 2.0], (5, 5, 5), continuity=4)
    left = traj.sample(t[1:3] - 1e-7)
    right = traj.sample(t[1:3])
    np.testing.assert_allclose(left[3], right[3], atol=1e-4)  # jerk continuous now


@pytest.mark.parametrize(
    "degrees, message",
    [((5, 5, 5), "18 coefficients but there are 14 conditions"), ((3, 3, 3), "12 coefficients but there are 14")],
)
def test_wrong_condition_count_is_refused_with_the_counts(degrees, message):
    with pytest.raises(ConditionCountError, match=message):
        planning.piecewise_polynomial(knots((1, 1, 1)), [0, 1, 2, 3], degrees)


def test_degrees_must_match_segments():
    with pytest.raises(TrajectoryError, match="need 4 knot times, got 3"):
        planning.piecewise_polynomial([0, 1, 2], [0, 1, 2], "3-5-3")
    with pytest.raises(TrajectoryError, match="not a preset"):
        planning.piecewise_polynomial([0, 1, 2, 3], [0, 1, 2, 3], "cubic")


@pytest.mark.parametrize(
    "durations, expected_deg_s",
    [(INITIAL_TIMES, 28.6386), (OPTIMISED_TIMES, 44.4591)],
)
def test_seed000_peak_velocity_of_joint1(durations, expected_deg_s):
    """Seed 000 reports 54.2 deg/s for the optimised times; the 3-5-3 it defines gives 44.46 deg/s.

    (Documented in docs/planning.md: the paper's figure does not follow from its own
    path points and times; the limit 55 deg/s is respected with a wide margin.)
    """
    traj = planning.piecewise_polynomial(knots(durations), np.deg2rad(JOINT1_DEG), "3-5-3")
    peak = np.rad2deg(traj.peaks().velocity[0])
    print(f"3-5-3 joint 1, times {durations}: peak velocity {peak:.4f} deg/s (paper: {PAPER_PEAK_DEG_S})")
    assert peak == pytest.approx(expected_deg_s, abs=1e-4)
    # Dense sampling agrees with the exact peak (never exceeds it).
    t = np.linspace(0.0, traj.duration, 20001)
    sampled = np.rad2deg(np.abs(traj.sample(t)[1]).max())
    assert sampled <= peak + 1e-9
    assert sampled == pytest.approx(peak, abs=1e-5)


def test_seed000_paper_peak_is_not_reproduced():
    traj = planning.piecewise_polynomial(knots(OPTIMISED_TIMES), np.deg2rad(JOINT1_DEG), "3-5-3")
    peak = np.rad2deg(traj.peaks().velocity[0])
    assert abs(peak - PAPER_PEAK_DEG_S) > 9.0
    # The paper's total and reduction are consistent with each other.
    assert sum(OPTIMISED_TIMES) == pytest.approx(3.607, abs=1e-9)
    assert 1 - sum(OPTIMISED_TIMES) / sum(INITIAL_TIMES) == pytest.approx(0.398, abs=1e-3)  # paper: "39.8 %"
