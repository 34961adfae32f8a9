"""Reachability maps: index values, FK of every stored solution, serial vs Dask bit for bit, tool-down sets."""

from __future__ import annotations

import numpy as np
import pytest

from pinarms import robots
from pinarms.errors import InvalidInput, ModelError, UnreachableTarget
from pinarms.robots.reach.orientations import so3_orientations, tool_down_orientations
from pinarms.robots.reach.reachability import ReachabilityRequest, reachability_map

#: The scheduler's HTTP endpoint (health and metrics; no dashboard) on a free loopback port, not on
#: the fixed 8787 that every other LocalCluster of a parallel run tries first.
LOOPBACK_HTTP = {"dashboard_address": "127.0.0.1:0"}

SHOULDER = np.array([0.0, 0.0, 0.157])  # AUBO-i3: origin of the first joint [m]


@pytest.fixture(scope="module")
def aubo():
    return robots.load("aubo_i3")


@pytest.fixture(scope="module")
def aubo_map(aubo):
    return reachability_map(ReachabilityRequest(aubo, 0.1, 30))


def test_a_voxel_out_of_reach_has_index_zero_and_the_comfortable_centre_a_high_one(aubo, aubo_map):
    m = aubo_map
    # 0.85 m from the shoulder: inside the grid (the guaranteed bound is 0.938 m) but beyond the arm
    far = SHOULDER + [0.85, 0.0, 0.0]
    assert m.rows_of(far[None])[0] >= 0, "the voxel was computed (not just outside the grid)"
    assert m.index_at(far[None])[0] == 0.0
    with pytest.raises(UnreachableTarget, match="out of reach"):  # no orientation at all: the position itself
        aubo.ik(far, position_only=True)
    # 0.3 m in front of the shoulder: the arm takes almost any orientation there
    centre = np.array([[0.3, 0.0, 0.2]])
    assert m.index_at(centre)[0] >= 0.8
    # the index falls to 0 with the distance from the shoulder
    r = np.linalg.norm(m.centres() - SHOULDER, axis=1)
    assert m.index[r < 0.45].mean() > 0.7
    assert m.index[r > 0.8].max() == 0.0
    assert m.open_faces == 0


def test_every_stored_solution_reaches_its_pose_by_forward_kinematics(aubo, aubo_map):
    m = aubo_map
    s = m.solutions
    assert len(s) == m.n_reached > 1000
    T = aubo.fk(s.q)
    np.testing.assert_allclose(T[:, :3, 3], m.centres(s.voxel), atol=1e-9)
    np.testing.assert_allclose(T[:, :3, :3], m.orientations.rotations[s.orientation], atol=1e-9)
    assert np.all(aubo.within_limits(s.q))
    rows = np.searchsorted(m.voxels, s.voxel)
    assert np.all(m.reached[rows, s.orientation])
    # the stored manipulability is |det J| of the stored solution, and the voxel's best is their maximum
    np.testing.assert_allclose(s.manipulability, np.abs(np.linalg.det(aubo.jacobian(s.q))), rtol=1e-12)
    best = np.full(m.n_voxels, -np.inf)
    np.maximum.at(best, rows, s.manipulability)
    np.testing.assert_array_equal(np.where(np.isfinite(best), best, np.nan), m.best_manipulability)


def test_the_stored_solution_is_the_most_dexterous_branch(aubo, aubo_map):
    m = aubo_map
    s = m.solutions
    rng = np.random.default_rng(3)
    for k in rng.choice(len(s), size=20, replace=False):
        all_q = aubo.ik_all(m.pose(int(np.searchsorted(m.voxels, s.voxel[k])), int(s.orientation[k])))
        w = np.abs(np.linalg.det(aubo.jacobian(all_q)))
        assert all_q.shape[0] >= 1
        assert s.manipulability[k] >= w.max() * (1 - 1e-9)


def test_poses_marked_unreached_have_no_numerical_solution_either(aubo, aubo_map):
    m = aubo_map
    rows, cols = np.nonzero(~m.reached & (m.index > 0.3)[:, None])
    rng = np.random.default_rng(5)
    for k in rng.choice(rows.size, size=6, replace=False):
        T = m.pose(int(rows[k]), int(cols[k]))
        with pytest.raises(UnreachableTarget):
            aubo.ik(T, max_restarts=15, seed=1)


def test_serial_and_local_cluster_maps_are_bit_identical(aubo):
    distributed = pytest.importorskip("distributed")
    serial = reachability_map(ReachabilityRequest(aubo, 0.15, 10, chunk_voxels=100))
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                                  dashboard_address=None,
                                  scheduler_kwargs=LOOPBACK_HTTP) as cluster, distributed.Client(cluster) as client:
        dask_map = reachability_map(ReachabilityRequest(aubo, 0.15, 10, chunk_voxels=100), scheduler=client)
    assert serial.n_voxels > 500 and serial.n_reached > 1000
    assert serial.identical(dask_map)
    assert dask_map.parameters["scheduler"] != "serial"


def test_numerical_map_of_a_redundant_arm_is_checked_by_forward_kinematics():
    panda = robots.load("panda")
    assert not panda.has_analytic_ik
    oset = so3_orientations(4)
    m = reachability_map(ReachabilityRequest(panda, 0.25, oset, restarts=1, samples=20_000))
    assert m.solver == "numerical"
    assert m.n_reached > 50
    s = m.solutions
    T = panda.fk(s.q)
    np.testing.assert_allclose(T[:, :3, 3], m.centres(s.voxel), atol=1e-9)
    np.testing.assert_allclose(T[:, :3, :3], oset.rotations[s.orientation], atol=1e-9)
    assert np.all(panda.within_limits(s.q))


def test_forcing_numerical_ik_on_a_closed_form_arm_agrees_on_most_poses(aubo):
    oset = so3_orientations(4)
    a = reachability_map(ReachabilityRequest(aubo, 0.25, oset))
    n = reachability_map(ReachabilityRequest(aubo, 0.25, oset, ik="numerical", restarts=2))
    assert np.array_equal(a.voxels, n.voxels)
    assert not np.any(n.reached & ~a.reached), "a numerical solution where every closed-form branch fails"
    assert n.n_reached >= 0.9 * a.n_reached


def test_tool_down_map_of_a_scara_reaches_only_straight_down():
    scara = robots.load("scara_mushroom")
    m = reachability_map(ReachabilityRequest(scara, 0.1, 5, tool_down=np.radians(15)))
    np.testing.assert_allclose(m.orientations.tool_axis, [0, 0, -1])  # its tool frame has z up
    assert m.index.max() == pytest.approx(1 / 5)  # only the cone's centre direction
    assert np.all(m.reached[:, m.orientations.group != 0] == 0)
    assert m.reached[:, m.orientations.group == 0].any()


def test_tool_down_map_of_the_aubo_counts_a_direction_when_any_roll_reaches_it(aubo):
    m = reachability_map(ReachabilityRequest(aubo, 0.15, 6, tool_down=np.radians(15), roll_steps=4))
    o = m.orientations
    assert o.roll_free and o.size == 24 and o.n_groups == 6
    per_direction = m.reached.reshape(m.n_voxels, 6, 4).any(axis=2)
    np.testing.assert_array_equal(m.index, per_direction.mean(axis=1))
    down = o.rotations @ o.tool_axis
    assert np.all(np.degrees(np.arccos(-down[:, 2])) <= 15 + 1e-9)


def test_lookups_agree_with_the_stored_bits(aubo_map):
    m = aubo_map
    row = int(np.flatnonzero((m.index > 0) & (m.index < 1))[0])
    T = np.stack([m.pose(row, k) for k in range(m.n_orientations)])
    np.testing.assert_array_equal(m.reaches(T), m.reached[row])
    vm = m.voxel_map(0.5)
    q = vm.query(m.centres(m.voxels[[row]]))
    assert q.reachable[0] == (m.index[row] > 0.5)


def test_orientation_sets_are_spread_evenly():
    s = so3_orientations(50).spread(probes=5000)
    rng = np.random.default_rng(0)
    q = rng.normal(size=(50, 4))
    # a random set of the same size leaves bigger holes and nearly coincident members
    from pinarms.robots.reach.orientations import OrientationSet, _quat_to_matrix

    R = _quat_to_matrix(q / np.linalg.norm(q, axis=1, keepdims=True))
    r = OrientationSet("so3", R, np.arange(50), 50, False, np.array([0, 0, 1.0]), R[:, :, 2].copy(), {}).spread(5000)
    assert s.covering_radius < 0.85 * r.covering_radius
    assert s.min_separation > 2 * r.min_separation
    d = tool_down_orientations(np.radians(15), 16, 8)
    assert d.spread().covering_radius < np.radians(8)


@pytest.mark.parametrize(
    "kwargs, error, match",
    [
        ({"resolution": 0.0}, InvalidInput, "resolution"),
        ({"resolution": 0.0005}, InvalidInput, "larger resolution"),
        ({"ik": "magic"}, InvalidInput, "ik must be"),
        ({"manipulability": "volume"}, InvalidInput, "manipulability"),
        ({"orientations": 0}, InvalidInput, "orientations"),
        ({"tool_down": 2.0}, InvalidInput, "π/2"),
        ({"collision": object()}, InvalidInput, "in_collision"),
    ],
)
def test_bad_arguments_raise_named_errors(aubo, kwargs, error, match):
    args = {"resolution": 0.2, **kwargs}
    with pytest.raises(error, match=match):
        reachability_map(ReachabilityRequest(aubo, **args))


def test_analytic_ik_on_an_arm_without_a_closed_form_is_a_model_error():
    with pytest.raises(ModelError, match="no closed-form"):
        reachability_map(ReachabilityRequest(robots.load("panda"), 0.3, 2, ik="analytic"))
