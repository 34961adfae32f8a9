"""The compiled IK solver: its chain kinematics against Pinocchio, batch rows against single solves."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from pinarms import robots
from pinarms.robots.ik import NumericalIK
from pinarms.robots.ik import _chain as chain

ARMS = ["scara_mushroom", "gantry_flower", "koji_turner", "koji_turner_rail", "aubo_i3", "ur5", "panda"]


@pytest.mark.parametrize("name", ARMS)
def test_compiled_chain_pose_and_jacobian_match_pinocchio(name):
    """FK and frame Jacobian (base axes at the tcp) of the compiled chain vs Pinocchio, mimic joints included."""
    robot = robots.load(name)
    solver = NumericalIK(robot)
    _, C, _, _, _ = solver._compiled()
    qi, sc, of, rev, LR, Lp, fR, fp = C
    m = qi.shape[0]
    R, p, Z, O, J = np.empty((3, 3)), np.empty(3), np.empty((m, 3)), np.empty((m, 3)), np.empty((6, robot.nq))
    data = robot.model.createData()
    for q in robot.random_q(20, seed=5):
        chain.fk(q, qi, sc, of, rev, LR, Lp, fR, fp, R, p, Z, O)
        chain.jacobian(qi, sc, rev, Z, O, p, J)
        qp = robot._tree.coordinates.to_pin(q)
        pin.forwardKinematics(robot.model, data, qp)
        M = pin.updateFramePlacement(robot.model, data, solver.frame_id)
        J_ref = pin.computeFrameJacobian(robot.model, data, qp, solver.frame_id, pin.LOCAL_WORLD_ALIGNED)
        np.testing.assert_allclose(R, M.rotation, atol=1e-12)
        np.testing.assert_allclose(p, M.translation, atol=1e-12)
        np.testing.assert_allclose(J, J_ref, atol=1e-12)


@pytest.mark.parametrize("name", ["panda", "ur5", "koji_turner"])
def test_batch_row_k_is_the_single_solve_with_seed_plus_k(name):
    robot = robots.load(name)
    T = robot.fk(robot.random_q(60, seed=21))
    Q = robot.ik(T, seed=7)
    for k in range(T.shape[0]):
        np.testing.assert_array_equal(Q[k], robot.ik(T[k], seed=7 + k))
    seeds = robot.random_q(60, seed=22)  # seeded: each row the 2π equivalents nearest its seed, as one by one
    Q = robot.ik(T, seeds, seed=3)
    for k in range(0, T.shape[0], 7):
        np.testing.assert_array_equal(Q[k], robot.ik(T[k], seeds[k], seed=3 + k))


def test_batch_of_panda_targets_all_solved_within_limits():
    """The narrow-limit redundant arm: every target met to 1e-10 within the limits (checked by Pinocchio)."""
    panda = robots.load("panda")
    T = panda.fk(panda.random_q(400, seed=31))
    res = NumericalIK(panda).solve_batch(T, seed=1)
    assert res.success.all()
    assert panda.within_limits(res.q, tol=0.0).all()
    data = panda.model.createData()
    fid = panda.frame_id("tcp")
    for q, Tk in zip(res.q, T):
        pin.forwardKinematics(panda.model, data, q)
        M = pin.updateFramePlacement(panda.model, data, fid)
        assert np.linalg.norm(M.translation - Tk[:3, 3]) <= 1e-10
        assert np.linalg.norm(pin.log3(M.rotation.T @ Tk[:3, :3])) <= 1e-10
    assert res.iterations > 400  # every target took steps (the table start never meets 1e-10)


def test_position_only_batch_and_single_agree():
    koji = robots.load("koji_turner")
    p = koji.position(koji.random_q(30, seed=4))
    Q = koji.ik(p, position_only=True, seed=2)
    assert np.abs(koji.position(Q) - p).max() <= 1e-10
    for k in (0, 13, 29):
        np.testing.assert_array_equal(Q[k], koji.ik(p[k], position_only=True, seed=2 + k))


def test_rotation_error_near_half_a_turn_matches_pinocchio():
    """log3 of the compiled chain (axis from the symmetric part beyond 2.69 rad) against Pinocchio's, up to π."""
    rng = np.random.default_rng(8)
    w = np.empty(3)
    for angle in (1e-9, 0.3, 2.0, 2.7, 3.0, np.pi - 1e-7, np.pi):
        for _ in range(5):
            axis = rng.standard_normal(3)
            axis /= np.linalg.norm(axis)
            Rt, R = pin.exp3(angle * axis), pin.exp3(rng.standard_normal(3) * 0.0)
            theta = chain.log3_of(np.ascontiguousarray(Rt), np.ascontiguousarray(R), w)
            ref = pin.log3(Rt @ R.T)
            assert abs(theta - np.linalg.norm(ref)) <= 1e-9
            if angle < np.pi - 1e-6:  # at π the axis sign is a convention
                np.testing.assert_allclose(w, ref, atol=1e-9)
            np.testing.assert_allclose(pin.exp3(w), Rt @ R.T, atol=1e-9)


def _rows_and_costs(robot, table, Tk):
    """Rows of the 27 cells around the target ``Tk`` and their start costs (position + 0.1 m/rad rotation + penalty)."""
    tq, tp, _, _, cell_start, grid, pen = table
    nx, ny, nz = (int(v) for v in grid[4:])
    pt, Rt = Tk[:3, 3], Tk[:3, :3]
    c = np.clip(np.floor((pt - grid[:3]) * grid[3]).astype(int), 0, [nx - 1, ny - 1, nz - 1])
    rows = [
        k
        for ix in range(max(c[0] - 1, 0), min(c[0] + 2, nx))
        for iy in range(max(c[1] - 1, 0), min(c[1] + 2, ny))
        for iz in range(max(c[2] - 1, 0), min(c[2] + 2, nz))
        for k in range(cell_start[(ix * ny + iy) * nz + iz], cell_start[(ix * ny + iy) * nz + iz + 1])
    ]
    R = robot.fk(tq[rows])[:, :3, :3]  # the rows' rotations (the table holds them as quaternions)
    cost = np.linalg.norm(tp[rows] - pt, axis=1) + 0.1 * np.linalg.norm(R - Rt, axis=(1, 2)) + pen[rows]
    return rows, cost


@pytest.mark.parametrize("name", ["panda", "ur5", "aubo_i3"])
def test_grid_start_is_the_nearest_row_of_the_neighbouring_cells(name):
    robot = robots.load(name)
    solver = NumericalIK(robot)
    _, _, _, _, table = solver._compiled()
    tq, tp, _, tQ, _, _, pen = table
    for k in np.flatnonzero(pen == 0.0)[[0, 777, -1]]:  # a row's own pose (no limit penalty): that row (cost 0)
        Rt = np.ascontiguousarray(robot.fk(tq[k])[:3, :3])
        assert chain.grid_index(table, Rt, np.ascontiguousarray(tp[k]), False) == k
        w, x, y, z = chain._quaternion(Rt)  # the row's quaternion, up to its sign
        assert abs(abs(np.dot([w, x, y, z], tQ[k])) - 1.0) <= 1e-12
    for Tk in robot.fk(robot.random_q(40, seed=61)):  # random targets: the smallest cost among the 27 cells' rows
        pt, Rt = np.ascontiguousarray(Tk[:3, 3]), np.ascontiguousarray(Tk[:3, :3])
        rows, cost = _rows_and_costs(robot, table, Tk)
        k = chain.grid_index(table, Rt, pt, False)
        assert k in rows
        assert abs(cost[rows.index(k)] - cost.min()) <= 1e-12
        near = chain.grid_neighbours(table, Rt, pt, False, 12)  # the 12 cheapest of them, in cost order
        expected = np.array(rows)[np.argsort(cost, kind="stable")[:12]]
        np.testing.assert_allclose(cost[[rows.index(r) for r in near]], cost[[rows.index(r) for r in expected]],
                                   atol=1e-12)
        assert near[0] == k


def test_start_table_ranks_poses_near_a_joint_limit_lower():
    """The limit penalty: 0.2 m at a limit, 0 from 0.6 rad inside (AUBO-i3, ±170°); none for the UR5, whose
    ranges all span a full turn (±2π, the elbow ±π: left by a 2π shift, never stopped at a limit)."""
    aubo = NumericalIK(robots.load("aubo_i3"))
    q = np.zeros((4, 6))
    q[1, 2] = aubo.upper[2]  # at a limit
    q[2, 4] = aubo.lower[4] + 0.3  # halfway into the margin
    q[3, 0] = aubo.upper[0] - 0.6  # at the margin's edge
    np.testing.assert_allclose(aubo._limit_penalty(q), [0.0, 0.2, 0.1, 0.0], atol=1e-12)
    ur5 = NumericalIK(robots.load("ur5"))
    np.testing.assert_array_equal(ur5._limit_penalty(np.stack([ur5.upper, ur5.lower])), 0.0)


def test_restarts_of_an_isolated_arm_are_apart_from_every_start_tried():
    """AUBO-i3 (6 joints, isolated solutions): restarts from stored poses 1.5 rad apart; panda (redundant): any."""
    from pinarms.robots.ik import _kernel as kernel

    aubo = NumericalIK(robots.load("aubo_i3"))
    L = aubo._compiled()[2]
    tried = np.zeros((2, 6))
    tried[1, 3] = 2.0
    a = np.zeros(6)
    a[5] = 1.49
    assert not kernel._apart(a, tried, 2, L, 1.5)  # 1.49 rad from the first start
    a[5] = -np.pi + 0.01  # 3.13 rad from both (modulo 2π)
    assert kernel._apart(a, tried, 2, L, 1.5)
    a[:] = 0.0
    a[3] = 2.0 - 2.0 * np.pi  # the second start itself, a turn away
    assert not kernel._apart(a, tried, 2, L, 1.5)
    assert kernel._diverse_restarts(L, 6, False) == 1.5
    panda = NumericalIK(robots.load("panda"))
    assert kernel._diverse_restarts(panda._compiled()[2], 7, False) == 0.0


# iterations per target of the former compiled solver (256-pose start table, Gram matrix and Jacobian at
# every trial step) on these seeded batches: the faster solver must need no more, at the same accuracy
_FORMER_ITERATIONS = {"panda": 17.25, "ur5": 9.415, "aubo_i3": 15.495}  # now 8.6, 6.9, 7.5


@pytest.mark.parametrize("name", sorted(_FORMER_ITERATIONS))
def test_seeded_batch_as_accurate_as_before_in_fewer_iterations(name):
    """Every target of a seeded batch met to 1e-10 (checked by Pinocchio) within the limits, as before."""
    robot = robots.load(name)
    T = robot.fk(robot.random_q(200, seed=51))
    res = NumericalIK(robot).solve_batch(T, seed=4)
    assert res.success.all()
    assert robot.within_limits(res.q, tol=0.0).all()
    data = robot.model.createData()
    fid = robot.frame_id("tcp")
    for q, Tk in zip(res.q, T):
        pin.forwardKinematics(robot.model, data, q)
        M = pin.updateFramePlacement(robot.model, data, fid)
        assert np.linalg.norm(M.translation - Tk[:3, 3]) <= 1e-10
        assert np.linalg.norm(pin.log3(M.rotation.T @ Tk[:3, :3])) <= 1e-10
    assert res.iterations / 200 <= _FORMER_ITERATIONS[name]


def test_a_changed_kernel_source_drops_every_kernel_cache(tmp_path):
    """numba keys a cache on its own file only: a change of any kernel module drops the caches of all three."""
    import os
    from pathlib import Path

    from pinarms import compiled

    here = Path(chain.__file__).parent
    for name in chain.KERNEL_MODULES:
        (tmp_path / name).write_bytes((here / name).read_bytes())
    cache = tmp_path / "__pycache__"
    cache.mkdir()
    stale = [cache / "_kernel.descend-198.py311.nbi", cache / "_chain.fk-92.py311.1.nbc"]
    other = cache / "numerical.cpython-311.pyc"
    def earlier(f):  # a file of an earlier process (one written by this process is kept: pinarms.compiled)
        f.write_bytes(b"x")
        os.utime(f, (compiled.STARTED - 60.0, compiled.STARTED - 60.0))

    for f in stale + [other]:
        earlier(f)
    chain.drop_stale_caches(tmp_path)  # no digest yet: dropped
    assert not any(f.exists() for f in stale) and other.exists()
    earlier(stale[0])
    chain.drop_stale_caches(tmp_path)  # same sources: kept
    assert stale[0].exists()
    (tmp_path / "_chain.py").write_text((here / "_chain.py").read_text() + "\n# changed\n")
    chain.drop_stale_caches(tmp_path)  # a sibling changed: the _kernel cache goes too
    assert not stale[0].exists() and other.exists()


def test_start_table_is_shared_by_arms_of_the_same_kinematics_and_limits():
    """The 32 768-row table is made once per chain and limits in a process (read only), not per robot."""
    a, b = NumericalIK(robots.load("aubo_i3")), NumericalIK(robots.load("aubo_i3"))
    assert a._compiled()[4] is b._compiled()[4]
    narrow = robots.load("aubo_i3")
    narrow.upper = np.minimum(narrow.upper, 2.0)  # other limits: a table of their own
    narrow_table = NumericalIK(narrow)._compiled()[4]
    assert narrow_table is not a._compiled()[4]
    assert (narrow_table[0] <= 2.0).all() and (a._compiled()[4][0] > 2.0).any()
    assert a._compiled()[4][0].shape == (32768, 6)


def test_start_cost_quaternion_gives_the_frobenius_distance_on_every_branch():
    """Shepperd's four branches (trace largest, or one diagonal term): ‖A − B‖_F² = 8 (1 − (q_A·q_B)²)."""
    rng = np.random.default_rng(3)
    rotations = [pin.exp3(rng.standard_normal(3)) for _ in range(20)]
    rotations += [pin.exp3(np.pi * 0.999 * np.eye(3)[i]) for i in range(3)] + [np.eye(3)]
    quats = [np.array(chain._quaternion(np.ascontiguousarray(R))) for R in rotations]
    for R, qa in zip(rotations, quats):
        assert abs(np.linalg.norm(qa) - 1.0) <= 1e-12
        for S, qb in zip(rotations, quats):
            assert abs(8.0 * (1.0 - qa.dot(qb) ** 2) - np.linalg.norm(R - S) ** 2) <= 1e-12
