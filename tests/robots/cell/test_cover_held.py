"""A moving mesh held by its slices' cylinders beside its spheres (robots.cell.mesh_cover.mesh_parts,
robots.cell.box_kernel): every piece of every UR5 mesh inside a cylinder and its sphere, the bounds against
static boxes below coal's exact distance, and the cover never clearing a state coal finds closer than the margin."""

from __future__ import annotations

import coal
import numpy as np
import pytest
from pinarms.optim.motion import MotionChecker, load_scene
from pinarms.robots.cell.box_kernel import held_low, _toward_gap
from pinarms.robots.cell.cover_kernel import _fk
from pinarms.robots.cell.cover import MESH_SPHERES, link_cover, pair_arrays
from pinarms.robots.cell.mesh_cover import (
    mesh_arrays,
    mesh_parts,
    mesh_spheres,
    split_triangles,
)

from tests.robots.cell.random_shapes import cylinder_and_box

TOL = 1e-12  # m: containment up to floating-point rounding


def _ur5_moving_meshes() -> list:
    objs = load_scene("ur5_shelf").collision_model.geometryObjects
    return [o for o in objs if int(o.parentJoint) > 0 and mesh_arrays(o.geometry) is not None]


def test_every_piece_lies_in_one_cylinder_and_its_sphere():
    objs = _ur5_moving_meshes()
    assert len(objs) >= 5
    for obj in objs:
        V, T = mesh_arrays(obj.geometry)
        centres, radii, a, b, rad, sphere = mesh_parts(V, T, MESH_SPHERES)
        np.testing.assert_array_equal(centres, mesh_spheres(V, T, MESH_SPHERES)[0])  # the same spheres
        assert a.shape == b.shape == (rad.size, 3) and sphere.shape == rad.shape and set(sphere) == set(range(radii.size))
        S, _ = split_triangles(V[T])
        X = S.reshape(-1, 3)
        held = np.zeros((S.shape[0], rad.size), dtype=bool)
        for k in range(rad.size):
            u = b[k] - a[k]
            L = np.linalg.norm(u)
            u = u / L if L > 0.0 else np.zeros(3)
            t = (X - a[k]) @ u
            radial = np.linalg.norm((X - a[k]) - t[:, None] * u, axis=1)
            in_cyl = (t >= -TOL) & (t <= L + TOL) & (radial <= rad[k] + TOL)
            in_sph = np.linalg.norm(X - centres[sphere[k]], axis=1) <= radii[sphere[k]] + TOL
            held[:, k] = (in_cyl & in_sph).reshape(-1, 3).all(axis=1)
        assert held.any(axis=1).all(), obj.name  # each piece: its three vertices in one cylinder and its sphere


def test_the_projection_toward_the_nearest_box_point_is_a_lower_bound_of_coal():
    rng = np.random.default_rng(3)
    tight = 0
    for _ in range(400):
        r, h, half, Rb, pb, Rc, pc = cylinder_and_box(rng, 0.0)
        SA, SB = (pc - h * Rc[:, 2])[None], (pc + h * Rc[:, 2])[None]
        gap = _toward_gap(SA, SB, 0, r, Rb[None], pb[None], half[None], 0)
        d = coal.distance(coal.Cylinder(r, max(2 * h, 1e-9)), coal.Transform3s(Rc, pc), coal.Box(*(2 * half)),
                          coal.Transform3s(Rb, pb), coal.DistanceRequest(), coal.DistanceResult())
        assert gap <= max(d, 0.0) + 1e-9
        tight += int(d > 0.0 and gap > d - 1e-3)
    assert tight > 20  # a disc near a corner or an edge: within 1 mm
    # a cylinder beside a box's edge, its axis along the edge: exact, 42 mm (the box's axes alone: 15 mm)
    x = 0.1 + 0.05 / np.sqrt(2.0) + 0.03
    gap = _toward_gap(np.array([[x, x, -0.05]]), np.array([[x, x, 0.05]]), 0, 0.05, np.eye(3)[None], np.zeros((1, 3)),
                      np.full((1, 3), 0.1), 0)
    assert gap == pytest.approx(np.hypot(x - 0.1, x - 0.1) - 0.05, abs=1e-12)


def _coal_distance(cell, cover, a, b, q):
    objs = cell.collision_model.geometryObjects
    nj = cover.fk[0].shape[0]
    R, p = np.empty((nj, 3, 3)), np.empty((nj, 3))
    _fk(np.ascontiguousarray(q, dtype=float), *cover.fk, R, p)
    T = []
    for g in (a, b):
        o, j = objs[g], int(objs[g].parentJoint)
        T.append(coal.Transform3s(R[j] @ o.placement.rotation, R[j] @ o.placement.translation + p[j]))
    return coal.distance(objs[a].geometry, T[0], objs[b].geometry, T[1], coal.DistanceRequest(), coal.DistanceResult())


@pytest.mark.parametrize(("scene", "fixture"), [("ur5_shelf", "pedestal_0"), ("ur5_table_box", "table_0")])
def test_arm_box_bounds_stay_below_coal_and_the_screen_clears_nothing_closer(scene, fixture):
    cell = load_scene(scene)
    cover = link_cover(cell)
    names = [o.name for o in cell.collision_model.geometryObjects]
    ua, fx = names.index("ur5_upper_arm_link_0"), names.index(fixture)
    assert cover.segments[5][ua] == 2 and cover.exact[fx] == 1  # held by its slices' cylinders, against a box
    ch = MotionChecker(cell, ["ur5"])
    Q = ch.full(cell.random_q(400, seed=21)[:, ch.cols])
    bound = cover.excess(Q, cover.prepare(np.array([ua]), np.array([fx])), np.zeros(1))
    d = np.array([_coal_distance(cell, cover, ua, fx, q) for q in Q])
    assert np.all(bound <= np.maximum(d, 0.0) + 1e-9)
    near = (d > 0.0) & (d < 0.03)
    assert near.sum() > 20 and np.mean(bound[near] > 0.5 * d[near]) > 0.5  # near contact: tight, not empty
    # the whole screen: none proven that coal finds closer than the margin, on states near contact too
    pairs = cover.prepare(*pair_arrays(ch.pairs))
    proven = cover.screen(Q, pairs, ch.pair_margin)
    collides = ch.coal_collides(Q, "margin")
    assert collides.sum() > 50 and proven.sum() > 50
    assert not np.any(proven & collides)
    np.testing.assert_array_equal(cover.pair_screen(Q, pairs, ch.pair_margin).all(axis=1), proven)
    excess = cover.excess(Q, pairs, ch.pair_margin)
    assert np.all(excess[proven] > 0.0) and not np.any(excess[~proven] > 0.0)


def test_held_low_answers_early_and_passes_over_far_cylinders():
    cell = load_scene("ur5_shelf")
    cover = link_cover(cell)
    names = [o.name for o in cell.collision_model.geometryObjects]
    ua, fx = names.index("ur5_upper_arm_link_0"), names.index("pedestal_0")
    work = cover.work(cover.prepare(np.array([ua]), np.array([fx])))
    R, p, W, SA, SB, _ = work
    sjoint, sa, sb, srad, sstart, _, spart = cover.segments
    for q in cell.random_q(50, seed=4):
        _fk(np.ascontiguousarray(q, dtype=float), *cover.fk, R, p)
        W[:] = np.einsum("sab,sb->sa", R[cover.joint], cover.center) + p[cover.joint]
        SA[:] = np.einsum("sab,sb->sa", R[sjoint], sa) + p[sjoint]
        SB[:] = np.einsum("sab,sb->sa", R[sjoint], sb) + p[sjoint]
        args = ((W, cover.radius, SA, SB, srad, sstart, spart), ua, (cover.frame_R, cover.frame_p, cover.size), fx)
        full = held_low(*args, -np.inf, np.inf)
        for t in (full - 1e-3, full + 1e-3):
            assert (held_low(*args, t, t) > t) == (full > t)  # the screen's question, answered early
            cut = held_low(*args, -np.inf, t)  # the excess: the bound where it is at most the cut, else above it
            assert cut == full if full <= t else cut > t
