"""Closed-form IK: every solution within limits, batched, for the four arms and the UR family."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from pinarms import robots
from pinarms.robots.conventions import aubo_joint_to_mdh, aubo_mdh_to_joint
from pinarms.errors import InvalidInput, ModelError
from pinarms.papers import SEED001
from pinarms.robots.ik import FK_TOL, LIMIT_TOL, GantryIK, KojiIK, ScaraIK, URTypeIK, analytic_solver

ANALYTIC = ["scara_mushroom", "gantry_flower", "koji_turner", "aubo_i3", "ur3", "ur5", "ur10"]
MAX_SOLUTIONS = {"scara_mushroom": 2 * 2, "gantry_flower": 1, "koji_turner": 4, "aubo_i3": 8, "ur3": 8 * 64, "ur5": 8 * 64, "ur10": 8 * 64}

# Seed 001, table 2 joint columns (rad), read as the paper's modified D-H angles.
TABLE2_THETA = SEED001.table2_joints


@pytest.fixture(scope="module", params=ANALYTIC)
def arm(request):
    return robots.load(request.param)


def _pose_errors(robot, q, T):
    F = robot.fk(q)
    pos = np.linalg.norm(F[..., :3, 3] - T[..., :3, 3], axis=-1)
    rot = np.linalg.norm(F[..., :3, :3] - T[..., :3, :3], axis=(-2, -1)) / np.sqrt(2.0)
    return pos, rot


def test_each_arm_gets_its_family(arm):
    expected = {"scara_mushroom": ScaraIK, "gantry_flower": GantryIK, "koji_turner": KojiIK}.get(arm.name, URTypeIK)
    assert isinstance(arm._analytic_ik, expected)
    assert arm.has_analytic_ik


def test_round_trip_batch_all_solutions_valid(arm):
    q = arm.random_q(300, seed=11)
    T = arm.fk(q)
    sols = arm.ik_all(T, q_ref=q)
    assert isinstance(sols, list) and len(sols) == 300
    for k, s in enumerate(sols):
        assert 1 <= s.shape[0] <= MAX_SOLUTIONS[arm.name]
        # sorted by distance to q_ref, and the nearest is the configuration itself
        d = np.linalg.norm(s - q[k], axis=1)
        assert np.all(np.diff(d) >= -1e-12)
        assert d[0] < 1e-8
    allq = np.concatenate(sols)
    idx = np.repeat(np.arange(300), [s.shape[0] for s in sols])
    pos, rot = _pose_errors(arm, allq, T[idx])
    assert pos.max() <= FK_TOL and rot.max() <= FK_TOL
    assert np.all(arm.within_limits(allq, tol=LIMIT_TOL))
    # no duplicates within one target
    for s in sols:
        if s.shape[0] > 1:
            gaps = np.abs(s[:, None, :] - s[None, :, :]).max(axis=-1) + np.eye(s.shape[0])
            assert gaps.min() > 1e-8


def test_single_target_returns_array(arm):
    q = arm.random_q(1, seed=3)[0]
    s = arm.ik_all(arm.fk(q))
    assert s.ndim == 2 and s.shape[1] == arm.nq and s.shape[0] >= 1


@settings(max_examples=40, deadline=None)
@given(u=st.lists(st.floats(0.0, 1.0), min_size=6, max_size=6))
def test_property_aubo_round_trip(u):
    arm = _AUBO
    q = arm.lower + np.array(u) * (arm.upper - arm.lower)
    sols = arm.ik_all(arm.fk(q), q_ref=q)
    assert sols.shape[0] >= 1
    assert np.abs(sols[0] - q).max() < 1e-7
    pos, rot = _pose_errors(arm, sols, np.broadcast_to(arm.fk(q), (sols.shape[0], 4, 4)))
    assert pos.max() <= FK_TOL and rot.max() <= FK_TOL


_AUBO = robots.load("aubo_i3")


def test_aubo_solution_counts_match_a_numerical_search():
    """8 branches where all exist; where only 4 reach, an exhaustive numerical search finds 4 too."""
    q8 = np.array([1.94, -0.54, 0.29, -2.8, 1.5, 0.23])
    _, free = _AUBO._analytic_ik.candidates(_AUBO.fk(q8)[None], respect_limits=False)
    assert free.shape[0] == 8
    q4 = np.array([0.3, -0.4, 1.1, 0.5, 0.8, -0.6])
    T = _AUBO.fk(q4)
    _, free = _AUBO._analytic_ik.candidates(T[None], respect_limits=False)
    assert free.shape[0] == 4
    solver = _AUBO.numerical_ik()
    rng = np.random.default_rng(0)
    found = []
    for _ in range(120):
        q, pe, re, _ = solver.attempt(rng.uniform(-np.pi, np.pi, 6), T, False, 1e-10, limits=False)
        if pe < 1e-9 and re < 1e-9:
            w = (q + np.pi) % (2 * np.pi) - np.pi
            if not any(np.abs(w - x).max() < 1e-6 for x in found):
                found.append(w)
    assert len(found) == 4
    for w in found:
        assert np.abs(free - w).max(axis=1).min() < 1e-6


def test_ur5_wide_limits_give_each_branch_once_and_equivalents_on_request():
    ur5 = robots.load("ur5")
    q = np.array([0.3, -1.2, 1.1, -0.5, 0.8, -0.6])  # generic, all |q| < π
    branches = ur5.ik_all(ur5.fk(q))
    assert branches.shape[0] == 8
    assert np.abs(branches - q).max(axis=1).min() < 1e-9  # q itself (within the limits, nearest neutral of its equivalents)
    sols = ur5.ik_all(ur5.fk(q), equivalents=True)
    # 8 branches; joints with range [-2π, 2π] (all but the elbow) each admit 2 equivalents
    assert sols.shape[0] == 8 * 2**5
    wrapped = (sols[:, [0, 1, 3, 4, 5]] + np.pi) % (2 * np.pi) - np.pi
    assert len(np.unique(np.round(np.column_stack([wrapped, sols[:, 2]]), 8), axis=0)) == 8


def test_table2_joint_columns_come_back_from_ik_of_their_fk():
    """Seed 001 table 2 (paper's angles) → manufacturer joint values → FK → IK → same values."""
    q = aubo_mdh_to_joint(TABLE2_THETA)
    assert np.all(_AUBO.within_limits(q))
    sols = _AUBO.ik_all(_AUBO.fk(q), q_ref=q)
    for k in range(4):
        np.testing.assert_allclose(sols[k][0], q[k], atol=1e-9)
        np.testing.assert_allclose(aubo_joint_to_mdh(sols[k][0]), TABLE2_THETA[k], atol=1e-9)
        assert sols[k].shape[0] >= 2  # other branches exist too (shoulder/elbow/wrist)


def test_scara_two_elbow_branches_and_yaw():
    scara = robots.load("scara_mushroom")
    q = np.array([0.6, 0.9, 0.05, 0.4])
    s = scara.ik_all(scara.fk(q), q_ref=q)
    np.testing.assert_allclose(s[0], q, atol=1e-10)
    elbows = np.unique(np.sign(np.round(s[:, 1], 9)))
    assert set(elbows) == {-1.0, 1.0}  # elbow left and right
    np.testing.assert_allclose(s[:, 2], 0.05, atol=1e-12)  # same stroke for every branch


def test_scara_tilted_target_has_no_solution_and_says_why():
    scara = robots.load("scara_mushroom")
    T = scara.fk(np.array([0.6, 0.9, 0.05, 0.4]))
    c, s = np.cos(0.2), np.sin(0.2)
    T[:3, :3] = T[:3, :3] @ np.array([[1, 0, 0], [0, c, -s], [0, s, c]])
    assert scara.ik_all(T).shape == (0, 4)
    assert "orientation" in scara.ik_failure_reason(T)


def test_gantry_unique_solution_and_stroke_limits():
    gantry = robots.load("gantry_flower")
    q = np.array([0.4, 0.3, -0.1])
    s = gantry.ik_all(gantry.fk(q))
    assert s.shape == (1, 3)
    np.testing.assert_allclose(s[0], q, atol=1e-12)
    T = gantry.fk(np.array([1.0, 0.3, -0.1]))
    T[0, 3] += 0.5  # x stroke is 1.2 m: 1.5 m needs x beyond it
    assert gantry.ik_all(T).shape == (0, 3)
    reason = gantry.ik_failure_reason(T)
    assert "limits" in reason and "x = 1.5" in reason


KOJI_PAPER_MATRIX = np.array(  # seed 004 eq. after (6): T for (−90, 25, −30, 90)°, mm → m
    [[1.0, 0.0, 0.0, 1.1973], [0.0, 1.0, 0.0, 0.250], [0.0, 0.0, 1.0, -0.9292], [0.0, 0.0, 0.0, 1.0]]
)


def _koji_paper_branch(koji, T):
    """The candidate with the waist at −90° and the upper arm raised (limits not applied)."""
    free = koji.ik_all(T, respect_limits=False)
    assert not koji.within_limits(free).any()
    deg = np.degrees(free)
    pick = deg[(np.abs(deg[:, 0] + 90.0) < 1e-6) & (deg[:, 1] > 0.0)]
    assert pick.shape[0] == 1
    return pick[0]


def test_koji_paper_example_from_the_printed_position():
    koji = robots.load("koji_turner")
    deg = _koji_paper_branch(koji, KOJI_PAPER_MATRIX)
    assert deg[0] == pytest.approx(-90.0, abs=1e-9)
    assert deg[3] == pytest.approx(90.0, abs=1e-9)
    # the printed position is the FK rounded to 0.1 mm: angles within 0.005° of (25, −30)
    assert deg[1] == pytest.approx(25.0011, abs=1e-4)
    assert deg[2] == pytest.approx(-30.0046, abs=1e-4)
    # the paper's 25.0271° up / 30.0339° down, to the stated 0.03°
    assert deg[1] == pytest.approx(25.0271, abs=0.03)
    assert -deg[2] == pytest.approx(30.0339, abs=0.03)


def test_koji_printed_position_needs_the_shoulder_just_past_25_degrees():
    """25.0011° > the 25° range end: strictly, no solution within limits, and the reason says which joint."""
    koji = robots.load("koji_turner")
    assert koji.ik_all(KOJI_PAPER_MATRIX).shape == (0, 4)
    reason = koji.ik_failure_reason(KOJI_PAPER_MATRIX)
    assert "limits" in reason and "shoulder" in reason
    # the exact FK of the paper's configuration is solved within limits
    q = np.radians([-90.0, 25.0, -30.0, 90.0])
    np.testing.assert_allclose(koji.ik_all(koji.fk(q))[0], q, atol=1e-12)


def test_koji_paper_angles_come_from_x_rounded_to_whole_mm():
    """(1197.0, ·, −929.2) mm gives the paper's 25.0271°, 30.0339° (docs/ik.md)."""
    koji = robots.load("koji_turner")
    T = KOJI_PAPER_MATRIX.copy()
    T[0, 3] = 1.1970
    deg = _koji_paper_branch(koji, T)
    assert deg[1] == pytest.approx(25.0271, abs=2e-4)
    assert -deg[2] == pytest.approx(30.0339, abs=2e-4)


def test_koji_four_candidates_before_the_range_check():
    koji = robots.load("koji_turner")
    arm = koji._analytic_ik.arm_angles(np.array([[1.1973, 0.0, -0.9292]]))
    assert np.all(np.isfinite(arm))
    assert arm.shape == (1, 4, 3)
    np.testing.assert_allclose(np.sort(np.degrees(arm[0, :, 0])), [-90.0, -90.0, 90.0, 90.0], atol=1e-9)


def test_koji_exact_fk_round_trip_of_the_paper_configuration():
    koji = robots.load("koji_turner")
    q = np.radians([-90.0, 25.0, -30.0, 90.0])
    s = koji.ik_all(koji.fk(q))
    np.testing.assert_allclose(s[0], q, atol=1e-12)


def test_ik_all_without_closed_form_raises():
    with pytest.raises(ModelError, match="no analytic IK"):
        robots.load("panda").ik_all(np.eye(4))


@pytest.mark.parametrize(
    "bad",
    [np.zeros((3, 3)), np.full((4, 4), np.nan), np.diag([1.0, 1.0, -1.0, 1.0]), np.diag([2.0, 1.0, 1.0, 1.0])],
)
def test_invalid_targets(bad):
    with pytest.raises(InvalidInput):
        _AUBO.ik_all(bad)


def test_structure_checks_raise_model_error():
    with pytest.raises(ModelError):
        analytic_solver(robots.load("panda"), "ur_type")
    with pytest.raises(ModelError):
        analytic_solver(_AUBO, "koji")
    with pytest.raises(ModelError):
        analytic_solver(robots.load("koji_turner"), "scara")
    with pytest.raises(InvalidInput):
        analytic_solver(_AUBO, "delta")


def test_ur_type_checks_intersecting_wrist_axes():
    """A UR5 whose last two axes do not meet is rejected (structure verified, not assumed)."""
    ur5 = robots.load("ur5")
    text = ur5.urdf_text.replace('name="wrist_3_joint" type="revolute">', 'name="wrist_3_joint" type="revolute">', 1)
    import re

    text = re.sub(
        r'(<joint name="wrist_3_joint".*?<origin rpy="[^"]*" xyz=")([^"]*)(")',
        lambda m: m.group(1) + "0.01 0.0823 0.0" + m.group(3),
        text,
        count=1,
        flags=re.S,
    )
    bent = robots.from_urdf_text(text, tcp="tool0", name="ur5_bent")
    with pytest.raises(ModelError, match="do not intersect"):
        URTypeIK(bent)


def test_aubo_double_root_at_the_joint_limits_is_exact():
    """θ5 = 0 is a double root of the wrist-flip equation; with five joints at their limits
    a 1e-8 rounding error would push the solution out of range: it must come back exactly."""
    q = np.radians([-170.0, -170.0, -170.0, -170.0, 0.0, -170.0])
    sols = _AUBO.ik_all(_AUBO.fk(q), q_ref=q)
    assert np.abs(sols[0] - q).max() < 1e-12


@pytest.mark.parametrize("theta5", [1e-7, -3e-8, 2e-6])
def test_aubo_nearly_double_roots_are_polished_not_dropped(theta5):
    q = np.array([0.4, -0.3, 1.1, 0.2, theta5, -0.7])
    sols = _AUBO.ik_all(_AUBO.fk(q), q_ref=q)
    # near the wrist singularity θ4 − θ6 is ill-conditioned: the FK tolerance allows ~1e-9 / |θ5|
    assert np.abs(sols[0] - q).max() < 1e-5
    pos, rot = _pose_errors(_AUBO, sols, np.broadcast_to(_AUBO.fk(q), (sols.shape[0], 4, 4)))
    assert pos.max() <= FK_TOL and rot.max() <= FK_TOL


def test_empty_batch_of_targets_gives_an_empty_list():
    assert _AUBO.ik_all(np.zeros((0, 4, 4))) == []
    assert _AUBO.fk(np.zeros((0, 6))).shape == (0, 4, 4)


def test_starts_of_one_target_are_the_in_limit_equivalents_nearest_the_reference():
    """Robot.ik's cheap path: raw branches, each joint at its 2π equivalent nearest q_ref within limits."""
    ur5 = robots.load("ur5")
    q = np.array([0.3, -1.2, 1.1, -0.5, 0.8, -0.6])
    T = ur5.fk(q)
    ref = q + np.array([-2 * np.pi + 0.1, 0.0, 0.0, 2 * np.pi - 0.2, 0.0, 0.0])
    starts = ur5._analytic_ik.starts(T, ref)
    assert 1 <= starts.shape[0] <= 8  # one row per branch, not every 2π equivalent (256)
    assert np.all(ur5.within_limits(starts, tol=LIMIT_TOL))
    d = np.linalg.norm(starts - ref, axis=1)
    assert np.all(np.diff(d) >= 0.0)
    expected = q + np.array([-2 * np.pi, 0.0, 0.0, 2 * np.pi, 0.0, 0.0])
    np.testing.assert_allclose(starts[0], expected, atol=1e-9)
    # the same row is the nearest of ik_all's full list
    np.testing.assert_allclose(ur5.ik_all(T, q_ref=ref)[0], starts[0], atol=1e-9)
    # and Robot.ik returns it (refined), within limits
    np.testing.assert_allclose(ur5.ik(T, ref), expected, atol=1e-9)


def test_starts_drop_branches_no_equivalent_brings_within_limits():
    """AUBO-i3 (±170°): a branch needing a joint in (170°, 190°) has no equivalent inside."""
    aubo = _AUBO
    q = np.array([0.3, -0.4, 1.1, 0.5, 0.8, -0.6])
    T = aubo.fk(q)
    _, free = aubo._analytic_ik.candidates(T[None], respect_limits=False)
    starts = aubo._analytic_ik.starts(T, q)
    inside = free[aubo.within_limits(free)]
    assert starts.shape[0] == inside.shape[0]
    np.testing.assert_allclose(np.sort(starts, axis=0), np.sort(inside, axis=0), atol=1e-7)
    koji = robots.load("koji_turner")
    assert koji._analytic_ik.starts(KOJI_PAPER_MATRIX, koji.neutral).shape[0] == 0  # shoulder 25.0011° > 25°


def test_split_by_target_keeps_empty_targets_and_order():
    from pinarms.robots.ik.solver import split_by_target

    q = np.arange(12.0).reshape(4, 3)
    parts = split_by_target(np.array([1, 1, 3, 3]), q, 5)
    assert [p.shape for p in parts] == [(0, 3), (2, 3), (0, 3), (2, 3), (0, 3)]
    np.testing.assert_array_equal(np.concatenate(parts), q)
    assert split_by_target(np.zeros(0, dtype=int), np.zeros((0, 3)), 0) == []


def test_a_position_given_to_ik_all_says_how_to_solve_it():
    koji = robots.load("koji_turner")
    with pytest.raises(InvalidInput, match=r"got shape \(3,\).*position_only=True"):
        koji.ik_all(np.array([1.1973, 0.25, -0.9292]))
    q = koji.ik(np.array([1.1973, 0.25, -0.9292]), position_only=True)
    np.testing.assert_allclose(koji.position(q), [1.1973, 0.25, -0.9292], atol=1e-10)


def test_koji_paper_candidate_lists_are_our_branches_at_x_rounded_to_whole_mm():
    """Seed 004 eq. (8) prints four θ2 and four θ3 (down) candidates; at (1197.0, 250, −929.2) mm
    every one is an angle of our four geometric branches, either as is or shifted by 90°."""
    from pinarms.papers import SEED004

    koji = robots.load("koji_turner")
    T = KOJI_PAPER_MATRIX.copy()
    T[0, 3] = 1.1970
    deg = np.degrees(koji.ik_all(T, respect_limits=False))
    assert deg.shape == (4, 4)
    back = deg[np.abs(deg[:, 0] + 90.0) < 1e-9]  # θ1 = −90°: upper arm raised / lowered
    front = deg[np.abs(deg[:, 0] - 90.0) < 1e-9]  # θ1 = +90°: the arm folded back
    up, down = back[np.argmax(back[:, 1])], back[np.argmin(back[:, 1])]
    ours = {
        # θ2 list: both elbows of the θ1 = −90° branch (magnitudes), then 90° + their forearm angles
        "theta2": [abs(down[1]), up[1], 90.0 - up[2], 90.0 + down[2]],
        # θ3 (down) list: 90° below the folded branch's θ2, 90° + |θ2| of the lowered elbow, both forearms
        "theta3": [front[:, 1].max() - 90.0, 90.0 - down[1], -up[2], -down[2]],
    }
    np.testing.assert_allclose(ours["theta2"], SEED004.ik_theta2_candidates_deg, atol=2e-4)
    np.testing.assert_allclose(ours["theta3"], SEED004.ik_theta3_candidates_deg, atol=2e-4)


# paths that stay clear of every singularity (elbow straight, wrist axes aligned, wrist
# centre on the base axis, SCARA arm straight): a label may change only at one of those
SMOOTH_PATHS = {
    "aubo_i3": ([0.3, -0.4, 1.2, 0.5, 1.0, 0.2], [0.6, -0.1, 1.5, 0.8, 1.3, 0.5]),
    "ur5": ([0.3, -1.4, 1.2, -0.5, 1.0, 0.2], [0.6, -1.1, 1.5, -0.2, 1.3, 0.5]),
    "scara_mushroom": ([0.3, 0.8, 0.05, 0.2], [0.6, 1.1, 0.08, 0.5]),
    "koji_turner": ([0.3, 0.1, -0.2, 0.5], [0.6, 0.3, 0.1, 0.8]),
}


@pytest.mark.parametrize("name", sorted(SMOOTH_PATHS))
def test_branch_label_is_constant_along_a_smooth_path(name):
    """A configuration keeps its branch label while it moves without crossing a singularity."""
    arm = robots.load(name)
    q0, q1 = (np.array(v) for v in SMOOTH_PATHS[name])
    labels = []
    for s in np.linspace(0.0, 1.0, 25):
        q = (1 - s) * q0 + s * q1
        sols, lab = arm.ik_branches(arm.fk(q), q_ref=q)
        assert np.abs(sols[0] - q).max() < 1e-7  # the path's own configuration is found ...
        labels.append(int(lab[0]))  # ... and its label read
    assert len(set(labels)) == 1


def test_branch_label_changes_across_the_elbow_singularity():
    arm = robots.load("aubo_i3")
    q_a = np.array([0.3, -0.4, 0.2, 0.5, 1.0, 0.2])
    q_b = q_a.copy()
    q_b[2] = -0.2  # the elbow passes through straight (θ3 = 0)
    la = arm.ik_branches(arm.fk(q_a), q_ref=q_a)[1][0]
    lb = arm.ik_branches(arm.fk(q_b), q_ref=q_b)[1][0]
    assert la != lb


def test_ik_branches_takes_one_pose():
    arm = robots.load("aubo_i3")
    T = arm.fk(arm.random_q(2, seed=1))
    with pytest.raises(InvalidInput, match="one pose"):
        arm.ik_branches(T)
    with pytest.raises(ModelError, match="no analytic IK"):
        robots.load("panda").ik_branches(np.eye(4))


@pytest.mark.parametrize(
    "q_deg",
    [
        [-85.0, -49.563, 0.0, -114.402, 1.508, -116.562],  # elbow straight (θ3 = 0)
        [141.4, -170.0, 0.0, 75.157, -160.52, 64.194],  # elbow straight, shoulder at its limit
    ],
)
def test_aubo_straight_elbow_comes_back_to_rounding(q_deg):
    """θ3 = 0 is a double root of the planar two-link step: without snapping, rounding in
    the chain (~1e-13) would leave the elbow ~5e-7 rad off."""
    q = np.radians(q_deg)
    sols = _AUBO.ik_all(_AUBO.fk(q), q_ref=q)
    assert np.abs(sols[0] - q).max() < 1e-9


@pytest.mark.parametrize("name", ["ur3", "ur5", "ur10", "aubo_i3"])
def test_ik_all_lists_each_branch_once_every_row_checked_by_fk(name):
    """Distinct branches: no two rows are 2π equivalents, every row meets its pose by FK, within limits."""
    arm = robots.load(name)
    q = arm.random_q(300, seed=21)
    T = arm.fk(q)
    sols = arm.ik_all(T)
    counts = np.array([s.shape[0] for s in sols])
    assert counts.min() >= 1 and counts.max() <= 8
    rows = np.concatenate(sols)
    idx = np.repeat(np.arange(len(sols)), counts)
    F = arm.fk(rows)
    assert np.linalg.norm(F[:, :3, 3] - T[idx, :3, 3], axis=1).max() <= 1e-9
    assert np.linalg.norm(F[:, :3, :3] - T[idx, :3, :3], axis=(1, 2)).max() <= 2e-9
    assert np.all(arm.within_limits(rows))
    for s in sols:  # no repeats, also modulo 2π
        wrapped = np.round((s + np.pi) % (2 * np.pi) - np.pi, 7)
        wrapped[np.isclose(np.abs(wrapped), np.pi)] = np.pi
        assert len(np.unique(wrapped, axis=0)) == s.shape[0]
    # the generating configuration is among the branches (up to 2π)
    for k in range(0, 300, 10):
        d = (sols[k] - q[k] + np.pi) % (2 * np.pi) - np.pi
        assert np.abs(d).max(axis=1).min() < 1e-6


def test_ik_all_branch_equivalent_is_the_one_nearest_q_ref():
    ur5 = robots.load("ur5")
    q = np.array([0.3, -1.2, 1.1, -0.5, 0.8, -0.6])
    ref = q + np.array([-2 * np.pi + 0.1, 0.0, 0.0, 2 * np.pi - 0.2, 0.0, 0.0])
    sols = ur5.ik_all(ur5.fk(q), q_ref=ref)
    assert sols.shape[0] == 8
    np.testing.assert_allclose(sols[0], q + np.array([-2 * np.pi, 0.0, 0.0, 2 * np.pi, 0.0, 0.0]), atol=1e-9)
    every = ur5.ik_all(ur5.fk(q), q_ref=ref, equivalents=True)
    assert every.shape[0] == 256 and np.allclose(every[0], sols[0], atol=1e-12)
