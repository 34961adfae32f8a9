"""The sphere cover (robots.cell.cover) and the checker built on it: the cover contains every
collision geometry, and the fast checks never call clear what coal finds closer than the margin."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from pinarms.optim import InvalidSettings
from pinarms.optim.motion import (SCENES, MotionChecker, MotionLimits, MotionOptions, MotionRequest, load_scene,
                                   plan_motion)
from pinarms.optim.motion.coal_batches import CheckRoute
from pinarms.robots import load_cell
from pinarms.robots.cell.cover import geometry_spheres, link_cover, pair_arrays, pairs_for
from pinarms.errors import InvalidInput

MARGIN = 0.01


@pytest.fixture(scope="module")
def cells():
    out = {name: load_scene(name) for name in SCENES}
    for name in ("aubo_food_station", "mushroom_line"):
        out[name] = load_cell(name)
    return out


def _surface_points(obj, n: int = 48) -> np.ndarray:
    """Points of a geometry in its parent joint's frame: every mesh vertex; a primitive's corners,
    edges, rims and poles (where a cover is tightest)."""
    geo = obj.geometry
    kind = type(geo).__name__
    u = np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
    if kind == "Sphere":
        r = float(geo.radius)
        g = np.random.default_rng(0).normal(size=(4 * n, 3))
        P = np.concatenate([r * g / np.linalg.norm(g, axis=1, keepdims=True), r * np.eye(3), -r * np.eye(3)])
    elif kind in ("Cylinder", "Capsule"):
        r, h = float(geo.radius), float(geo.halfLength)
        rim = np.column_stack([r * np.cos(u), r * np.sin(u)])
        zs = np.linspace(-h, h, 9)
        P = np.concatenate([np.column_stack([rim, np.full(n, z)]) for z in zs])
        if kind == "Capsule":
            P = np.concatenate([P, [[0, 0, h + r], [0, 0, -h - r]]])
    elif kind == "Box":
        half = np.asarray(geo.halfSide, dtype=float)
        grid = np.linspace(-1.0, 1.0, 7)
        g = np.stack(np.meshgrid(grid, grid, grid, indexing="ij"), -1).reshape(-1, 3)
        on_face = np.any(np.abs(g) == 1.0, axis=1)
        P = g[on_face] * half
    else:
        P = np.asarray(geo.vertices(), dtype=float).reshape(-1, 3)
        assert P.shape[0] > 0, f"{obj.name}: a mesh without vertices"
    M = obj.placement
    return P @ np.asarray(M.rotation).T + np.asarray(M.translation)


def test_the_cover_contains_every_geometry_of_every_shipped_cell(cells):
    kinds = set()
    for name, cell in cells.items():
        for obj in cell.collision_model.geometryObjects:
            kinds.add(type(obj.geometry).__name__)
            C, r = geometry_spheres(obj)
            P = _surface_points(obj)
            inside = np.linalg.norm(P[:, None, :] - C[None], axis=-1) <= r[None] + 1e-12
            missed = ~inside.any(axis=1)
            assert not missed.any(), f"{name}: {obj.name}: {missed.sum()} point(s) outside the cover"
    # the shipped cells hold spheres, cylinders, boxes and meshes (Panda, UR5, AUBO-i3)
    assert {"Sphere", "Cylinder", "Box"} <= kinds and any("BVH" in k for k in kinds)


@pytest.mark.parametrize("name", ["panda_table_box", "ur5_table_box", "aubo_two_belt"])
def test_batched_sphere_centres_follow_pinocchio(cells, name):
    cell = cells[name]
    cover = link_cover(cell)
    Q = cell.random_q(5, seed=1)
    W = cover.world_centers(Q)
    data = cell.model.createData()
    for i, q in enumerate(Q):
        pin.forwardKinematics(cell.model, data, cell.robot.q_to_pinocchio(q[None])[0])
        for s in range(cover.joint.size):
            M = data.oMi[int(cover.joint[s])]
            expected = M.rotation @ cover.center[s] + M.translation
            np.testing.assert_allclose(W[i, s], expected, atol=1e-12)


@pytest.mark.parametrize("name", list(SCENES))
def test_cover_clear_states_are_clear_for_coal(cells, name):
    """Fast 'clear' ⇒ every pair's exact distance ≥ its margin; the checker's verdicts (cover, then coal
    where inconclusive) equal coal's on every state, at the margin and at a raised screen."""
    cell = cells[name]
    fast = MotionChecker(cell, [SCENES[name].arm], margin=MARGIN)
    exact = MotionChecker(cell, [SCENES[name].arm], margin=MARGIN, route=CheckRoute(cover=False))
    Q = fast.full(cell.random_q(300, seed=7)[:, fast.cols])
    proven = fast.cover.screen(Q, fast._cover_pairs, fast.pair_margin)  # the cover's own verdict
    excess, _, _ = exact.excess(Q[proven])
    assert np.all(excess >= 0.0), f"{name}: the cover called clear a state {-excess.min() * 1e3:.3f} mm too close"
    for which in ("margin", 0):
        np.testing.assert_array_equal(fast.batch_collides(Q, which), exact.batch_collides(Q, which))
    if name.startswith("panda"):  # spheres and cylinders: the cover is used
        assert fast.cover_decides_screens
        assert proven.mean() >= 0.9 * (~exact.batch_collides(Q)).mean()  # and decides most states
    if name == "aubo_two_belt":
        # each shoulder turns 47 mm above its own stand: its spheres overshoot the cylinder's end face by nearly its
        # radius, the gap of the projections on the stand's axes proves it (exact for an upright cylinder)
        assert fast.cover_decides_screens and fast.cover_share >= 0.97
    if name.startswith("ur5"):  # meshes: a loose cover, coal alone
        assert not fast.cover_decides_screens and not fast.covered(Q).any()


@pytest.mark.parametrize("name", ["panda_table_box", "panda_shelf"])
def test_fast_and_exact_edge_proofs_agree(cells, name):
    cell = cells[name]
    fast = MotionChecker(cell, [SCENES[name].arm], margin=MARGIN)
    exact = MotionChecker(cell, [SCENES[name].arm], margin=MARGIN, route=CheckRoute(cover=False))
    X = cell.random_q(200, seed=11)[:, fast.cols]
    X = X[[exact.state_valid(x) for x in X]][:16]
    rng = np.random.default_rng(5)
    edges = [(X[i], X[i] + rng.uniform(0.05, 1.0) * (X[j] - X[i])) for i in range(len(X)) for j in (i - 1, i - 5)]
    verdicts = [(fast.edge_valid(a, b).ok, exact.edge_valid(a, b).ok) for a, b in edges]
    assert all(f == e for f, e in verdicts), verdicts
    assert 0 < sum(f for f, _ in verdicts) < len(verdicts)  # both kinds of edges were tried
    assert fast.counts["coal"] < exact.counts["coal"]


def test_pairs_come_from_the_cells_clearance_choice(cells):
    cell = cells["aubo_two_belt"]
    assert pairs_for(cell, 0.01) == tuple(cell.pairs_for(0.01) if hasattr(cell, "pairs_for") else cell.pairs)
    a, b = pair_arrays(cell.pairs[:3])
    assert a.tolist() == [p.index_a for p in cell.pairs[:3]] and b.tolist() == [p.index_b for p in cell.pairs[:3]]


def test_plan_motion_settings_are_validated_with_their_caps(cells):
    cell = cells["aubo_crate_guard"]
    checker = MotionChecker(cell, ["aubo"], margin=MARGIN)
    qa = cell.neutral[checker.cols]
    for threads in (0, -1, 10**9, 1.5, True):
        with pytest.raises(InvalidSettings, match="threads must be"):
            MotionOptions(threads=threads)
    for grid in (0, 10**9, 2.5):
        with pytest.raises(InvalidSettings, match="grid must be an integer from 1 to 100000"):
            MotionLimits(grid=grid)
    with pytest.raises(InvalidInput, match="the start already is the goal"):
        MotionRequest(cell, "aubo", qa, qa.copy())


def test_the_search_keeps_its_time_limit(cells):
    """Edge proofs give up at the limit (the edge counts as not valid): the search ends near it."""
    from pinarms.optim.motion import MotionStatus, scene_queries

    cell = cells["panda_shelf"]
    queries, hold = scene_queries("panda_shelf", 3, seed=0, margin=MARGIN)
    limit = 0.05
    for k, q in enumerate(queries):
        options = MotionOptions(margin=MARGIN, time_limit=limit, seed=k)
        plan = plan_motion(MotionRequest(cell, "panda", q.start, q.goal, options=options, hold=hold))
        assert plan.status in (MotionStatus.SOLVED, MotionStatus.NO_PATH)
        seconds = plan.seconds["search"]
        assert seconds <= 1.1 * limit + 0.05, f"query {k}: the search took {seconds:.3f} s at a {limit} s limit"
