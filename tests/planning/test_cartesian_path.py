"""Joint-space images of straight tool lines: tolerance, one branch, named errors where the arm cannot follow."""

from __future__ import annotations

import numpy as np
import pytest

from pinarms import robots
from pinarms.planning import (CartesianPath, JointLimitOnPath, PathError, SingularityOnPath, UnreachableOnPath,
                              cartesian_path, joint_spline)
from pinarms.robots.reach.layout import default_orientation


def pose(R, p):
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = p
    return T


def dense(path: CartesianPath, per_interval: int = 10) -> np.ndarray:
    """Arc lengths 10x denser than the knots the path was built from (every knot included)."""
    b = path.breaks
    inner = b[:-1, None] + np.diff(b)[:, None] * np.arange(per_interval) / per_interval
    return np.append(inner.reshape(-1), b[-1])


def distance_to_segment(p, a, b):
    ab = b - a
    t = np.clip((p - a) @ ab / (ab @ ab), 0.0, 1.0)
    return np.linalg.norm(p - (a + t[:, None] * ab), axis=1)


@pytest.fixture(scope="module")
def aubo():
    return robots.load("aubo_i3")


@pytest.fixture(scope="module")
def lift(aubo):
    R = default_orientation(aubo)
    P = np.stack([pose(R, [0.35, 0.20, 0.0]), pose(R, [0.35, 0.20, 0.30])])
    return P, cartesian_path(aubo, P)


def test_straight_lift_stays_within_tolerance_of_the_line(aubo, lift):
    P, path = lift
    assert path.tolerance == 1e-4
    s = dense(path)
    assert s.size == 10 * (path.breaks.size - 1) + 1
    T = aubo.fk(path(s))  # FK at 10x the knot density
    off_line = distance_to_segment(T[:, :3, 3], P[0, :3, 3], P[1, :3, 3])
    assert off_line.max() < 1e-4
    pos, rot = path.deviation(s)
    assert pos.max() < 1e-4 and rot.max() < 1e-4 / path.tool_path.weight
    assert np.abs(T[:, :3, :3] - P[0, :3, :3]).max() < 1e-3  # the tool keeps its orientation
    # knots are exact IK solutions, ends at the poses
    Tk = aubo.fk(path.q_knots)
    assert np.linalg.norm(Tk[:, :3, 3] - path.tool_path.position(path.breaks), axis=1).max() < 1e-9
    assert np.abs(Tk[[0, -1]] - P).max() < 1e-9
    assert path.branch is not None and path.sigma_min.min() >= 1e-4


def test_a_tighter_tolerance_adds_knots_where_needed(aubo, lift):
    P, loose = lift
    tight = cartesian_path(aubo, P, tolerance=1e-7, q_start=loose.q_knots[0])
    assert tight.breaks.size > loose.breaks.size
    s = dense(tight)
    assert tight.deviation(s)[0].max() < 1e-7
    assert np.abs(tight(s) - loose(s)).max() < 1e-3  # same branch, same joint path


def test_blended_corners_stay_within_tolerance_and_joint_tangent_is_continuous():
    ur5 = robots.load("ur5")
    R = default_orientation(ur5)
    P = np.stack([pose(R, p) for p in ([0.4, 0.2, 0.1], [0.4, 0.2, 0.3], [0.2, 0.45, 0.3], [0.2, 0.45, 0.1])])
    path = cartesian_path(ur5, P, blend=0.05)
    assert path.stops.size == 0
    s = dense(path)
    assert path.deviation(s)[0].max() < 1e-4
    inner = path.breaks[1:-1]
    _, dq_l, _ = path.sample(inner, "left")
    _, dq_r, _ = path.sample(inner, "right")
    assert np.abs(dq_l - dq_r).max() < 1e-6  # C1 in s: the arm passes the corners without stopping
    # without blends the corners are stops
    sharp = cartesian_path(ur5, P, q_start=path.q_knots[0])
    assert np.allclose(sharp.stops, sharp.tool_path.via_s[1:-1])


@pytest.mark.parametrize("name, points", [
    ("scara_mushroom", ([0.30, 0.25, 0.06], [0.30, 0.25, 0.16], [0.10, 0.35, 0.16])),
    ("gantry_flower", ([0.30, 0.20, 0.05], [0.30, 0.20, 0.25], [0.90, 0.40, 0.25])),
    ("panda", ([0.45, 0.10, 0.20], [0.45, 0.10, 0.40], [0.30, 0.35, 0.40])),
])
def test_other_arm_families(name, points):
    arm = robots.load(name)
    R = default_orientation(arm)
    P = np.stack([pose(R, p) for p in points])
    path = cartesian_path(arm, P, blend=0.03)
    s = dense(path)
    pos, rot = path.deviation(s)
    assert pos.max() < 1e-4
    assert arm.within_limits(path(s)).all()
    assert (path.branch is None) == (not arm.has_analytic_ik)


def test_a_path_through_a_singularity_is_named_where(aubo):
    q_singular = np.array([0.3, -0.2, 1.4, 0.4, 0.0, 0.1])  # wrist1 and wrist3 axes aligned
    T = aubo.fk(q_singular)
    d = np.array([0.05, 0.03, -0.04])
    A, B = T.copy(), T.copy()
    A[:3, 3] -= d
    B[:3, 3] += d
    with pytest.raises(SingularityOnPath) as info:
        cartesian_path(aubo, np.stack([A, B]), q_start=q_singular)
    err = info.value
    at = np.linalg.norm(d)  # the singular pose is the middle of the line
    assert at - 0.01 < err.s < at  # stops before it, within 1 cm
    assert np.abs(err.pose[:3, 3] - (A[:3, 3] + (err.s / (2 * at)) * 2 * d)).max() < 1e-9
    assert "singular" in err.reason and f"s = {err.s:.6g} m" in str(err)
    assert isinstance(err, PathError) and err.q.shape == (6,)


def test_a_path_out_of_reach_is_named_where(aubo, lift):
    P, path = lift
    top = P[1].copy()
    top[2, 3] = 0.9
    with pytest.raises(UnreachableOnPath) as info:
        cartesian_path(aubo, np.stack([P[0], top]), q_start=path.q_knots[0])
    err = info.value
    assert "out of reach" in err.reason
    assert 0.35 < err.s < 0.45
    assert aubo.ik_failure_reason(err.pose) is None or "out of reach" in aubo.ik_failure_reason(
        pose(err.pose[:3, :3], err.pose[:3, 3] + [0, 0, 1e-3]))


def test_a_joint_limit_on_the_way_is_named():
    scara = robots.load("scara_mushroom")  # tcp z = 0.19 - j3, j3 in [0, 0.15] m
    R = default_orientation(scara)
    with pytest.raises(JointLimitOnPath) as info:
        cartesian_path(scara, np.stack([pose(R, [0.30, 0.25, 0.06]), pose(R, [0.30, 0.25, 0.25])]))
    err = info.value
    assert "j3" in err.reason and "lower limit" in err.reason
    top = 0.19 - 0.06  # the stroke ends 0.13 m up the line
    assert abs(err.s - top) < 1e-4
    assert np.abs(err.pose[:3, 3] - [0.30, 0.25, 0.06 + err.s]).max() < 1e-9


def test_a_workspace_boundary_on_the_way_is_named():
    koji = robots.load("koji_turner")
    q0 = np.array([0.3, 0.2, 0.0, 0.1])
    T0 = koji.fk(q0)
    T1 = T0.copy()
    T1[2, 3] += 0.4  # the hanging arm cannot lift its hand 0.4 m straight up from there
    with pytest.raises(UnreachableOnPath) as info:
        cartesian_path(koji, np.stack([T0, T1]), q_start=q0)
    assert 0.0 < info.value.s < 0.1
    assert "out of reach" in koji.ik_failure_reason(pose(T0[:3, :3], T0[:3, 3] + [0, 0, info.value.s + 0.01]))


def test_joint_spline_through_waypoints():
    Q = np.array([[0.0, 0.0], [1.0, 0.5], [1.5, 1.5], [2.0, 1.0]])
    path = joint_spline(Q)
    chord = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(Q, axis=0), axis=1))])
    assert np.allclose(path.breaks, chord)
    assert np.abs(path(chord) - Q).max() < 1e-12
    q, dq, ddq = path.sample(np.linspace(0, path.length, 7))
    assert q.shape == dq.shape == ddq.shape == (7, 2)
    line = joint_spline(Q[:2])
    assert np.abs(line.sample(0.3)[1] - (Q[1] - Q[0]) / chord[1]).max() < 1e-15


def test_knot_fit_checks_its_shapes_and_deviation():
    """The knot facts a CartesianPath is built from travel as one checked KnotFit."""
    from pinarms.planning.cartesian_path import KnotFit
    from pinarms.planning.errors import TrajectoryError

    fit = KnotFit(q_knots=np.zeros((3, 6)), sigma_min=np.ones(3), branch=None, max_deviation=(1e-5, 0))
    assert fit.max_deviation == (1e-5, 0.0) and not fit.q_knots.flags.writeable and not fit.sigma_min.flags.writeable
    with pytest.raises(TrajectoryError, match="KnotFit: q_knots must be"):
        KnotFit(q_knots=np.zeros((3, 6)), sigma_min=np.ones(2), branch=None, max_deviation=(0.0, 0.0))
    with pytest.raises(TrajectoryError, match="KnotFit: max_deviation"):
        KnotFit(q_knots=np.zeros((3, 6)), sigma_min=np.ones(3), branch=None, max_deviation=(float("nan"), 0.0))
