"""Segment timing under joint-torque limits: dense re-checks, scaling law, keywords, cycles, TOPP-RA."""

from __future__ import annotations

import numpy as np
import pytest

from pinarms import optim, robots
from pinarms.optim import InfeasibleProblem, InvalidLimits, InvalidSettings
from pinarms.optim.torque import TorqueConstraint

#: A food-handling move of the AUBO-i3 (rad): pick, lift, transfer, lower to place.
VIA = np.array([[0.3, -0.4, 1.2, 0.2, 1.57, 0.0],
                [0.3, -0.3, 1.3, 0.3, 1.57, 0.0],
                [-0.9, 0.4, 1.8, 0.5, 1.2, 0.5],
                [-0.9, 0.3, 1.7, 0.4, 1.2, 0.5]])


@pytest.fixture(scope="module")
def aubo():
    return robots.load("aubo_i3")


@pytest.fixture(scope="module")
def kinematic(aubo):
    return optim.minimize_time(optim.TimingRequest(VIA, "multi-quintic", aubo.velocity_limit, 8.0, method="exact"))


@pytest.fixture(scope="module")
def tight_limits(aubo, kinematic):
    """Torque limits that bind: 25 % over the gravity torque along the path with 3 kg, plus 0.5 N·m."""
    loaded = aubo.with_payload(3.0)
    t = np.linspace(0.0, kinematic.total, 2001)
    g = np.abs(loaded.gravity(kinematic.trajectory.sample(t)[0])).max(axis=0)
    return 1.25 * g + 0.5


def _dense_ratio(robot, trajectory, limit, n=100_001):
    t = np.linspace(0.0, trajectory.duration, n)
    return np.abs(trajectory.torques(robot, t)).max(axis=0) / limit


@pytest.mark.parametrize("method", ["exact", "ga"])
def test_torque_limited_timing_is_feasible_densely_and_never_shorter(aubo, kinematic, tight_limits, method):
    res = optim.minimize_time(optim.TimingRequest(VIA, "multi-quintic", aubo.velocity_limit, 8.0, method=method, seed=1,
                              max_generations=40, robot=aubo, payload=3.0, torque_limits=tight_limits))
    loaded = aubo.with_payload(3.0)
    dense = _dense_ratio(loaded, res.trajectory, tight_limits)
    assert np.all(dense <= 1.0 + 1e-9)
    np.testing.assert_allclose(res.torque_ratios, res.torque_peaks.torque / tight_limits)
    assert np.all(res.torque_ratios <= 1.0 + 1e-9)
    reference = kinematic.total if method == "exact" else optim.minimize_time(optim.TimingRequest(
        VIA, "multi-quintic", aubo.velocity_limit, 8.0, method="ga", seed=1, max_generations=40)).total
    assert res.total >= reference * (1.0 - 1e-9)
    assert res.total > reference * 1.01  # the limits bind: a real slow-down, not round-off
    if method == "exact":
        assert res.torque_ratios.max() == pytest.approx(1.0, abs=1e-6)  # tight on the active joint
    assert np.all(res.peaks.velocity <= aubo.velocity_limit * (1.0 + 1e-9))


def test_generous_limits_leave_the_kinematic_optimum(aubo, kinematic):
    res = optim.minimize_time(optim.TimingRequest(VIA, "multi-quintic", aubo.velocity_limit, 8.0, method="exact",
                              robot=aubo, torque_limits=np.full(6, 1e4)))
    assert res.total == pytest.approx(kinematic.total, rel=1e-9)
    assert res.torque_ratios.max() < 0.1


def test_the_scaling_law_equals_a_bisection_on_the_grid(aubo, tight_limits):
    constraint = TorqueConstraint(aubo.with_payload(3.0), tight_limits)
    problem = optim.TimingProblem(VIA, "multi-quintic", aubo.velocity_limit, torque=constraint)
    r = np.array([0.2, 0.5, 0.3])
    times, coefs = problem.coefficients_batch(r[None])
    s_law = float(constraint.minimal_scale(times, coefs)[0])

    def worst(scale):
        t, c = problem.coefficients_batch((scale * r)[None])
        return constraint.piece_ratios(t, c).max()

    lo, hi = 0.1, 20.0
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if worst(mid) > 1.0 else (lo, mid)
    assert s_law == pytest.approx(hi, rel=1e-9)
    assert worst(s_law * 0.999) > 1.0 >= worst(s_law * 1.000001)


def test_an_arm_that_cannot_hold_the_load_is_named(aubo):
    with pytest.raises(InfeasibleProblem, match=r"cannot hold via point 0 still: joint upperArm_joint"):
        optim.minimize_time(optim.TimingRequest(VIA, "multi-quintic", aubo.velocity_limit, method="exact", robot=aubo,
                            payload=3.0, torque_limits=[100.0, 1.0, 100.0, 100.0, 100.0, 100.0]))


def test_torque_keywords_are_checked(aubo):
    with pytest.raises(InvalidSettings, match="robot=arm"):
        optim.TimingRequest(VIA, "multi-quintic", aubo.velocity_limit, torque_limits=True)
    with pytest.raises(InvalidSettings, match="payload changes only the torques"):
        optim.TimingRequest(VIA, "multi-quintic", aubo.velocity_limit, robot=aubo, payload=1.0)
    with pytest.raises(InvalidLimits, match="torque limit"):
        optim.TimingRequest(VIA, "multi-quintic", aubo.velocity_limit, robot=aubo, torque_limits=[1.0, -2.0])
    with pytest.raises(robots.InvalidPayload, match="negative mass"):
        optim.TimingRequest(VIA, "multi-quintic", aubo.velocity_limit, robot=aubo, payload=-1.0, torque_limits=True)
    with pytest.raises(InvalidSettings, match="via points have 2"):
        optim.TimingRequest(VIA[:, :2], "multi-quintic", 1.0, robot=aubo, torque_limits=True)


def test_urdf_without_efforts_asks_for_limits():
    bare = robots.from_urdf_text(
        "<robot name='r'><link name='b'/><link name='a'><inertial><mass value='1'/>"
        "<inertia ixx='0.01' ixy='0' ixz='0' iyy='0.01' iyz='0' izz='0.01'/></inertial></link><link name='tcp'/>"
        "<joint name='j' type='revolute'><parent link='b'/><child link='a'/><axis xyz='0 1 0'/>"
        "<limit lower='-1' upper='1' effort='0' velocity='1'/></joint>"
        "<joint name='t' type='fixed'><parent link='a'/><child link='tcp'/><origin xyz='0.2 0 0'/></joint></robot>")
    with pytest.raises(InvalidLimits, match=r"no effort limit for joint\(s\) \['j'\]"):
        optim.TimingRequest([[0.0], [0.5]], "multi-quintic", 1.0, robot=bare, torque_limits=True)


def test_cycle_carries_the_payload_to_the_place_only(aubo):
    spec = optim.PickPlace([0.35, -0.25, 0.15], [0.05, 0.45, 0.15], lift=0.06, dwell=0.2)
    free = optim.plan_cycle(optim.CycleRequest(aubo, spec))
    q = free.q_via[: len(spec.names)]
    t = np.linspace(0.0, free.moves[0].total, 2001)
    g = np.abs(aubo.with_payload(3.0).gravity(free.moves[0].trajectory.sample(t)[0])).max(axis=0)
    limits = 1.25 * g + 0.5
    cycle = optim.plan_cycle(optim.CycleRequest(aubo, spec, load=optim.CycleLoad(payload=3.0, torque_limits=limits)))
    np.testing.assert_allclose(cycle.q_via[: len(spec.names)], q)
    # loaded there, empty back: the same path reversed takes longer with the load
    assert cycle.move_times[0] > cycle.move_times[1] * 1.01
    assert cycle.move_times[1] >= free.move_times[1] * (1.0 - 1e-9)
    assert cycle.cycle_time > free.cycle_time
    assert cycle.payload.mass == 3.0 and np.all(cycle.torque_ratios <= 1.0 + 1e-9)
    loaded_dense = _dense_ratio(aubo.with_payload(3.0), cycle.moves[0].trajectory, limits, 20_001)
    empty_dense = _dense_ratio(aubo, cycle.moves[1].trajectory, limits, 20_001)
    assert np.all(loaded_dense <= 1.0 + 1e-9) and np.all(empty_dense <= 1.0 + 1e-9)
    assert cycle.as_dict()["payload"]["mass_kg"] == 3.0


# ------------------------------------------------------------------ time-optimal along the path
def _toppra_torque(path, robot, vmax, grid):
    """toppra's own TOPP-RA with its JointTorqueConstraint (inverse dynamics = our RNEA) on ``path``."""
    import toppra
    import toppra.algorithm
    import toppra.constraint
    from pinarms.optim.timing.reference import toppra_path

    L, v = robot.effort_limit, np.asarray(vmax, dtype=float)
    constraints = [toppra.constraint.JointVelocityConstraint(np.column_stack([-v, v])),
                   toppra.constraint.JointTorqueConstraint(
                       lambda q, qd, qdd: robot.inverse_dynamics(q, qd, qdd), np.column_stack([-L, L]),
                       np.zeros(path.n_joints),
                       discretization_scheme=toppra.constraint.DiscretizationType.Interpolation)]
    algo = toppra.algorithm.TOPPRA(constraints, toppra_path(path), gridpoints=grid, parametrizer="ParametrizeConstAccel")
    sd = np.asarray(algo.compute_parameterization(0.0, 0.0)[1], dtype=float)
    return float(np.sum(2.0 * np.diff(grid) / (sd[:-1] + sd[1:])))


@pytest.mark.parametrize("payload", [0.0, 3.0])
def test_toppra_agrees_with_the_exact_time_optimal_scaling_on_one_segment(aubo, payload):
    """One straight joint-space segment under joint speed + torque limits: TOPP-RA (toppra) and pinarms's
    time-optimal path scaling with its JointTorqueConstraint agree within 2 % (seen: 1e-8 on the same grid);
    the polynomial segment timing (minimize_time, exact) is slower, never faster."""
    from pinarms import planning

    loaded = aubo.with_payload(payload)
    path = planning.joint_spline(VIA[[0, 2]], robot=aubo)
    ours = optim.time_optimal(path, [planning.path_constraints.JointVelocityConstraint(aubo.velocity_limit),
                                     planning.JointTorqueConstraint(loaded)], grid=200)
    reference = _toppra_torque(path, loaded, aubo.velocity_limit, np.linspace(0.0, path.length, 201))
    assert ours.duration == pytest.approx(reference, rel=0.02)
    dense = _dense_ratio(loaded, ours.trajectory, aubo.effort_limit, 50_001)
    assert np.all(dense <= 1.0 + 1e-9) and dense.max() > 0.999  # feasible and tight
    poly = optim.minimize_time(optim.TimingRequest(VIA[[0, 2]], "multi-quintic", aubo.velocity_limit, method="exact",
                               robot=aubo, payload=payload, torque_limits=True))
    assert poly.total >= ours.duration
    # the reference on the polynomial's own path (spline of its samples, cut at rests) says the same
    assert optim.toppra_limit(poly.trajectory, aubo.velocity_limit, robot=aubo, payload=payload,
                              torque_limits=True) == pytest.approx(reference, rel=0.02)


def test_torque_path_constraint_refuses_a_load_it_cannot_hold(aubo):
    from pinarms import planning

    path = planning.joint_spline(VIA[[0, 2]], robot=aubo)
    weak = planning.JointTorqueConstraint(aubo.with_payload(3.0), limit=[100.0, 5.0, 100.0, 100.0, 100.0, 100.0])
    with pytest.raises(InfeasibleProblem, match="no admissible speed at s = "):
        optim.time_optimal(path, [weak])


def test_a_path_through_a_pose_the_arm_cannot_hold_is_named(aubo):
    """Both via points can be held, the level arm between them cannot: no timing exists."""
    q0, q1 = np.array([0.0, -1.2, 0.0, 0.0, 0.0, 0.0]), np.array([0.0, -1.9, 0.0, 0.0, 0.0, 0.0])
    loaded = aubo.with_payload(3.0)
    g = np.abs(loaded.gravity(np.array([q0, [0.0, -np.pi / 2, 0.0, 0.0, 0.0, 0.0], q1])))[:, 1]
    limits = aubo.effort_limit.copy()
    limits[1] = 0.5 * (max(g[0], g[2]) + g[1])  # above both ends, below the level pose
    for method in ("exact", "ga"):
        with pytest.raises(InfeasibleProblem, match=r"cannot hold the path still between via points 0 and 1 .* "
                                                    r"joint upperArm_joint needs"):
            optim.minimize_time(optim.TimingRequest(np.array([q0, q1]), "multi-quintic", aubo.velocity_limit, method=method,
                                max_generations=5, robot=aubo, payload=3.0, torque_limits=limits))
