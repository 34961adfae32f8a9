"""The tool path: straight lines, SLERP orientation, circular blends, weighted arc length."""

from __future__ import annotations

import numpy as np
import pytest

from pinarms.planning import BlendTooLarge, TrajectoryError, tool_path
from pinarms.robots import so3 as _so3


def pose(p, rotvec=(0.0, 0.0, 0.0)):
    T = np.eye(4)
    T[:3, :3] = _so3.exp(np.array(rotvec, dtype=float))
    T[:3, 3] = p
    return T


def angle_between(A, B):
    return _so3.angle(np.swapaxes(A, -1, -2) @ B)


def test_line_ends_are_exact_and_length_is_weighted():
    A, B = pose([0.3, 0.0, 0.1], (0.1, -0.2, 0.3)), pose([0.5, 0.2, 0.4], (0.4, 0.5, -0.6))
    w = 0.1
    tp = tool_path(np.stack([A, B]), weight=w)
    d = np.linalg.norm(B[:3, 3] - A[:3, 3])
    theta = angle_between(A[:3, :3], B[:3, :3])
    assert tp.length == pytest.approx(np.sqrt(d**2 + (w * theta) ** 2), rel=1e-14)
    assert np.array_equal(tp.pose(0.0), A)
    assert np.abs(tp.pose(tp.length) - B).max() <= 1e-15
    # the tcp stays on the segment: position linear in s
    s = np.linspace(0.0, tp.length, 101)
    p = tp.position(s)
    lam = s / tp.length
    assert np.abs(p - ((1 - lam)[:, None] * A[:3, 3] + lam[:, None] * B[:3, 3])).max() < 1e-15


def test_orientation_is_slerp_monotone_at_a_constant_rate():
    A, B = pose([0.3, 0.0, 0.1], (0.0, 0.0, 0.0)), pose([0.3, 0.0, 0.4], (0.3, -1.2, 0.8))
    tp = tool_path(np.stack([A, B]))
    s = np.linspace(0.0, tp.length, 1001)
    R = tp.pose(s)[:, :3, :3]
    from_start = angle_between(A[:3, :3], R)
    theta = angle_between(A[:3, :3], B[:3, :3])
    assert np.all(np.diff(from_start) > 0.0)  # strictly monotone
    assert np.abs(from_start - theta * s / tp.length).max() < 1e-12  # constant angular rate
    axes = _so3.log(np.swapaxes(A[:3, :3], -1, -2) @ R[1:])
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    assert np.abs(axes - axes[-1]).max() < 1e-10  # one rotation axis: the geodesic of SO(3)


def test_unit_speed_and_tangent_continuity_through_blends():
    P = np.stack([pose([0.3, 0.0, 0.1]), pose([0.3, 0.0, 0.3], (0.0, 0.0, 0.5)),
                  pose([0.5, 0.1, 0.3], (0.2, 0.0, 1.0)), pose([0.5, 0.3, 0.1])])
    tp = tool_path(P, blend=0.05)
    assert tp.kinds == ("line", "blend", "line", "blend", "line")
    assert tp.stops.size == 0
    s = np.linspace(0.0, tp.length, 4001)
    _, d1, d2 = tp.evaluate(s)
    speed = np.sqrt(np.sum(d1[:, :3] ** 2, axis=1) + tp.weight**2 * np.sum(d1[:, 3:] ** 2, axis=1))
    assert np.abs(speed - 1.0).max() < 1e-9  # arc-length parameterisation
    for b in tp.breaks[1:-1]:
        left, right = tp.evaluate(b, "left"), tp.evaluate(b, "right")
        assert np.abs(left[0] - right[0]).max() < 1e-14
        assert np.abs(left[1] - right[1]).max() < 1e-8  # continuous tangent (no stop needed)
    # d1 is the derivative of the pose (finite differences away from the breaks)
    h = 1e-6
    s0 = 0.5 * (tp.breaks[1] + tp.breaks[2])  # inside the first blend
    Tp, Tm = tp.pose(s0 + h), tp.pose(s0 - h)
    _, d, _ = tp.evaluate(s0)
    assert np.abs((Tp[:3, 3] - Tm[:3, 3]) / (2 * h) - d[0, :3]).max() < 1e-8
    assert np.abs(_so3.log(Tp[:3, :3] @ Tm[:3, :3].T) / (2 * h) - d[0, 3:]).max() < 1e-7


def test_arc_blend_geometry():
    r = 0.04
    P = np.stack([pose([0.0, 0.0, 0.0]), pose([0.2, 0.0, 0.0]), pose([0.2, 0.2, 0.0])])  # 90° corner
    tp = tool_path(P, blend=r)
    s = np.linspace(0.0, tp.length, 20001)
    p = tp.position(s)
    closest = np.linalg.norm(p - P[1, :3, 3], axis=1).min()
    assert closest == pytest.approx(r * (1.0 / np.cos(np.pi / 4) - 1.0), rel=1e-6)
    assert tp.length == pytest.approx(0.4 - 2 * r + r * np.pi / 2, rel=1e-12)
    arc = (s > tp.breaks[1]) & (s < tp.breaks[2])
    centre = np.array([0.2 - r, r, 0.0])
    assert np.abs(np.linalg.norm(p[arc] - centre, axis=1) - r).max() < 1e-12
    assert tp.via_s[1] == pytest.approx(0.5 * tp.length)


def test_stops_where_asked_at_reversals_and_without_blend():
    P = np.stack([pose([0.0, 0.0, 0.0]), pose([0.2, 0.0, 0.0]), pose([0.2, 0.2, 0.0]), pose([0.2, 0.0, 0.0])])
    no_blend = tool_path(P)
    assert np.allclose(no_blend.stops, [0.2, 0.4])
    asked = tool_path(P, blend=0.02, stops=[1])
    assert asked.stops.size == 2  # via 1 asked, via 2 is a reversal (no arc fits)
    assert asked.kinds.count("blend") == 0
    collinear = tool_path(np.stack([pose([0, 0, 0]), pose([0.1, 0, 0]), pose([0.3, 0, 0])]))
    assert collinear.stops.size == 0 and collinear.length == pytest.approx(0.3)


def test_blend_too_large_names_the_radius_that_fits():
    P = np.stack([pose([0.0, 0.0, 0.0]), pose([0.05, 0.0, 0.0]), pose([0.05, 0.3, 0.0])])
    with pytest.raises(BlendTooLarge, match=r"radius <= 0\.05 m"):
        tool_path(P, blend=0.08)
    assert tool_path(P, blend=0.05).kinds == ("blend", "line")


@pytest.mark.parametrize("poses, match", [
    (np.stack([pose([0, 0, 0]), pose([0, 0, 0])]), "are equal"),
    (np.stack([pose([0, 0, 0]), pose([0.1, 0, 0], (np.pi, 0, 0))]), "half-turn"),
    (np.eye(4)[None], "N >= 2"),
])
def test_bad_poses_are_named(poses, match):
    with pytest.raises(TrajectoryError, match=match):
        tool_path(poses)


def test_bad_blend_weight_and_stops():
    P = np.stack([pose([0, 0, 0]), pose([0.1, 0, 0]), pose([0.1, 0.1, 0])])
    with pytest.raises(TrajectoryError, match="blend"):
        tool_path(P, blend=-0.01)
    with pytest.raises(TrajectoryError, match="weight"):
        tool_path(P, weight=0.0)
    with pytest.raises(TrajectoryError, match="stops"):
        tool_path(P, stops=[2])


def test_blend_corner_is_one_checked_object():
    """A Blend takes its corner as one BlendCorner: the blend distance and an arc's radius are checked."""
    from pinarms.planning.errors import TrajectoryError
    from pinarms.planning.tool_pieces import BlendCorner

    x, y = np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0])
    assert BlendCorner(np.zeros(3), x, y, 0.05, 0.05, True).b == 0.05
    with pytest.raises(TrajectoryError, match="BlendCorner: b must be a positive length"):
        BlendCorner(np.zeros(3), x, y, 0.0, 0.05, True)
    with pytest.raises(TrajectoryError, match="BlendCorner: an arc needs a positive radius"):
        BlendCorner(np.zeros(3), x, y, 0.05, float("nan"), True)
