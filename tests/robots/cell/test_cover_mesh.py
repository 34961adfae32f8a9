"""The mesh covers (robots.cell.mesh_cover, robots.cell.cover): every triangle of every mesh inside its
cover — the pieces tile the triangles, each piece's three vertices lie in one sphere; a static mesh's
box or cylinder and a moving mesh's cylinder hold every vertex — on the UR5's, the Panda's (its mesh
description) and the AUBO food station's meshes; and the cover's distances stay below coal's."""

from __future__ import annotations

import os

import coal
import numpy as np
import pinocchio as pin
import pytest

from pinarms.optim.motion import MotionChecker, load_scene
from pinarms.optim.motion.arm_macros import example_packages
from pinarms.robots import load_cell
from pinarms.robots.cell.cover import MESH_SPHERES, geometry_segments, geometry_spheres, link_cover, pair_arrays
from pinarms.robots.cell.mesh_cover import mesh_arrays, mesh_spheres, split_triangles, static_primitive

TOL = 1e-12  # m: containment up to floating-point rounding


def _panda_meshes() -> list:
    share = example_packages()["example-robot-data"]
    urdf = os.path.join(share, "robots/panda_description/urdf/panda.urdf")
    model = pin.buildModelFromUrdf(urdf)
    geom = pin.buildGeomFromUrdf(model, urdf, pin.COLLISION, package_dirs=[os.path.dirname(share)])
    return list(geom.geometryObjects)


@pytest.fixture(scope="module")
def meshes():
    out = {}
    for source, objs in (("ur5", load_scene("ur5_shelf").collision_model.geometryObjects),
                         ("aubo_food_station", load_cell("aubo_food_station").collision_model.geometryObjects),
                         ("panda", _panda_meshes())):
        for obj in objs:
            if mesh_arrays(obj.geometry) is not None:
                out[f"{source}:{obj.name}"] = obj
    assert any(k.startswith("ur5:") for k in out) and any(k.startswith("panda:") for k in out)
    assert any(k.startswith("aubo_food_station:") for k in out)
    return out


def _area(P: np.ndarray) -> np.ndarray:
    return 0.5 * np.linalg.norm(np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0]), axis=1)


def test_the_pieces_tile_each_triangle():
    rng = np.random.default_rng(3)
    P = rng.normal(size=(40, 3, 3)) * np.array([0.3, 0.02, 0.05])  # long slivers among them
    S, src = split_triangles(P, 0.01)
    assert S.shape[0] > 10 * P.shape[0]
    assert np.linalg.norm(S[:, [1, 2, 0]] - S, axis=2).max() <= 0.01 + 1e-15
    np.testing.assert_allclose(np.bincount(src, _area(S), P.shape[0]), _area(P), rtol=1e-9)
    # every piece's vertex lies in its source triangle (barycentric coordinates in [0, 1], the plane kept)
    A, B, C = (P[src, k] for k in range(3))
    M = np.stack([B - A, C - A], axis=2)  # (K, 3, 2)
    for k in range(3):
        uv = np.array([np.linalg.lstsq(M[i], S[i, k] - A[i], rcond=None)[0] for i in range(0, S.shape[0], 7)])
        assert uv.min() >= -1e-9 and uv.sum(axis=1).max() <= 1.0 + 1e-9
        np.testing.assert_allclose(A[::7] + np.einsum("nij,nj->ni", M[::7], uv), S[::7, k], atol=1e-12)
    with pytest.raises(ValueError, match="edge must be > 0"):
        split_triangles(P, 0.0)


def test_every_piece_of_every_mesh_lies_in_one_sphere(meshes):
    for name, obj in meshes.items():
        V, T = mesh_arrays(obj.geometry)
        C, r = geometry_spheres(obj)  # the cover the cell uses, in the parent joint's frame
        assert 1 <= r.size <= MESH_SPHERES, name
        M = obj.placement
        S = split_triangles(V[T])[0] @ np.asarray(M.rotation).T + np.asarray(M.translation)
        held = np.zeros(S.shape[0], dtype=bool)
        for c, radius in zip(C, r):  # a piece is held when its three vertices lie in one sphere
            held |= np.linalg.norm(S - c, axis=2).max(axis=1) <= radius + TOL
        assert held.all(), f"{name}: {int((~held).sum())} piece(s) in no sphere"


def test_the_mesh_cover_is_tighter_than_its_bounding_sphere(meshes):
    obj = meshes["ur5:ur5_upper_arm_link_0"]
    V, T = mesh_arrays(obj.geometry)
    C, r = mesh_spheres(V, T, MESH_SPHERES)
    half = 0.5 * (V.max(axis=0) - V.min(axis=0))
    # the arm tube is 50 mm in radius, the joint housings 60 mm: no sphere near the link's half length
    assert r.max() < 0.08 < float(np.linalg.norm(half))
    with pytest.raises(ValueError, match="count must be at least 1"):
        mesh_spheres(V, T, 0)


def _inside_box(X, R, p, half):
    L = (X - p) @ R
    return (np.abs(L) <= half + TOL).all(axis=1)


def _inside_cylinder(X, a, b, radius):
    u = (b - a) / np.linalg.norm(b - a)
    t = (X - a) @ u
    radial = np.linalg.norm((X - a) - t[:, None] * u, axis=1)
    return (t >= -TOL) & (t <= np.linalg.norm(b - a) + TOL) & (radial <= radius + TOL)


def test_static_and_moving_mesh_primitives_hold_every_vertex(meshes):
    kinds = set()
    for name, obj in meshes.items():
        V, _ = mesh_arrays(obj.geometry)
        kind, R, c, size = static_primitive(V)
        kinds.add(kind)
        if kind == "Box":
            assert _inside_box(V, R, c, size).all(), name
        else:
            assert np.isclose(np.linalg.det(R), 1.0) and size[2] == 0.0
            assert _inside_cylinder(V, c - size[1] * R[:, 2], c + size[1] * R[:, 2], size[0]).all(), name
        a, b, rad = geometry_segments(obj)
        if a.shape[0] == 1 and np.linalg.norm(b - a) > 0.0:  # a moving mesh held by its cylinder
            M = obj.placement
            W = V @ np.asarray(M.rotation).T + np.asarray(M.translation)
            assert int(obj.parentJoint) != 0 and _inside_cylinder(W, a[0], b[0], rad[0]).all(), name
    assert kinds == {"Box", "Cylinder"}
    # the UR5's base (fixed in the world) is screened exactly as its cylinder, holding every vertex
    cell = load_scene("ur5_shelf")
    cover = link_cover(cell)
    g = int(cell.collision_model.getGeometryId("ur5_base_link_0"))
    obj = cell.collision_model.geometryObjects[g]
    assert cover.exact[g] == 2
    V, _ = mesh_arrays(obj.geometry)
    W = V @ np.asarray(obj.placement.rotation).T + np.asarray(obj.placement.translation)
    R, p, (radius, half, _) = cover.frame_R[g], cover.frame_p[g], cover.size[g]
    assert _inside_cylinder(W, p - half * R[:, 2], p + half * R[:, 2], radius).all()


def test_ur5_cover_distances_stay_below_coal_and_prove_some_states():
    cell = load_scene("ur5_shelf")
    checker = MotionChecker(cell, ["ur5"], margin=0.01)
    cover = checker.cover
    Q = checker.full(cell.random_q(40, seed=5)[:, checker.cols])
    model, gm = cell.model, cell.collision_model
    data, gd = model.createData(), pin.GeometryData(gm)
    bounds = np.column_stack([cover.excess(Q, cover.prepare(*pair_arrays([p])), np.zeros(1)) for p in checker.pairs])
    qp = cell.robot.q_to_pinocchio(Q)
    for i in range(Q.shape[0]):
        pin.updateGeometryPlacements(model, data, gm, gd, qp[i])
        for k, p in enumerate(checker.pairs):
            Ma, Mb = gd.oMg[p.index_a], gd.oMg[p.index_b]
            d = coal.distance(gm.geometryObjects[p.index_a].geometry, coal.Transform3s(Ma.rotation, Ma.translation),
                              gm.geometryObjects[p.index_b].geometry, coal.Transform3s(Mb.rotation, Mb.translation),
                              coal.DistanceRequest(), coal.DistanceResult())
            assert bounds[i, k] <= max(d, 0.0) + 1e-9, (i, p.geometry_a, p.geometry_b, bounds[i, k], d)
    clear = ~checker.coal_collides(Q, "margin")
    proven = cover.screen(Q, checker._cover_pairs, checker.pair_margin)
    assert not (proven & ~clear).any()
    assert proven.sum() >= 1  # the mesh cover proves clear states (the old slice cover proved none)
