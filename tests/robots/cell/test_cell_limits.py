"""Hostile or mistaken cells are refused quickly by name (issue 29 items 5, 6 and check_motion's times)."""

from __future__ import annotations

import os
import time

import numpy as np
import pytest

from pinarms import planning
from pinarms.robots.cell import ArmMotion, load_cell
from pinarms.robots.cell import limits
from pinarms.errors import CellTooLarge, CollisionGeometryError, InvalidInput

from _cells import facing_cell_text, make_cell, post_cell_text, prefixed_scara

SWEEP = planning.multi_quintic([0.0, 1.0], np.array([[-1.0, 0.0, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0]]))


def _fixture(name: str, geometry: str, xyz: str = "1 1 0.2") -> str:
    return (f'<joint name="{name}_mount" type="fixed"><parent link="world"/><child link="{name}"/>'
            f'<origin xyz="{xyz}"/></joint><link name="{name}"><collision><geometry>{geometry}</geometry></collision></link>')


def _cell(*fixtures: str) -> str:
    return f'<robot name="c"><link name="world"/>{prefixed_scara("arm_", (0, 0, 0))}{"".join(fixtures)}</robot>'


# ------------------------------------------------------------------ geometry
@pytest.mark.parametrize("geometry, what", [
    ('<box size="-0.2 -0.2 -0.2"/>', "box size"),
    ('<box size="0 0 0"/>', "box size"),
    ('<box size="0.2 0.2 nan"/>', "box size"),
    ('<box size="0.2 0.2"/>', "box size"),
    ('<cylinder radius="-0.05" length="0.3"/>', "cylinder radius"),
    ('<cylinder radius="0.05" length="-0.3"/>', "cylinder length"),
    ('<sphere radius="0"/>', "sphere radius"),
    ('<sphere radius="inf"/>', "sphere radius"),
])
def test_bad_fixture_geometry_is_refused_naming_the_fixture(geometry, what):
    with pytest.raises(CollisionGeometryError, match=rf"fixture 'crate'.*{what}"):
        make_cell(_cell(_fixture("crate", geometry)), "bad")


@pytest.mark.parametrize("geometry, xyz, what", [
    ('<box size="0.2 0.2 0.2"/>', "1e15 0 0.2", "placed 1e\\+15 m"),
    ('<box size="0.2 0.2 0.2"/>', "0 -2e3 0", "placed 2000 m"),
    ('<sphere radius="1e15"/>', "1 1 0.2", "sphere radius"),
    ('<box size="0.2 5e3 0.2"/>', "1 1 0.2", "box size"),
])
def test_a_fixture_beyond_the_cells_extent_is_refused_naming_it(geometry, xyz, what):
    t0 = time.perf_counter()
    with pytest.raises(CollisionGeometryError, match=rf"fixture 'crate'.*{what}"):
        make_cell(_cell(_fixture("crate", geometry, xyz)), "far")
    assert time.perf_counter() - t0 < 5.0


def test_an_arm_based_beyond_the_cells_extent_is_refused():
    text = f'<robot name="c"><link name="world"/>{prefixed_scara("arm_", (1e15, 0, 0))}</robot>'
    with pytest.raises(CollisionGeometryError, match=r"link 'arm_.*placed 1e\+15 m"):
        make_cell(text, "far")


def test_a_positive_box_where_the_negative_one_was_gives_contact():
    cell = make_cell(_cell(_fixture("crate", '<box size="0.2 0.2 0.2"/>', "0.3 0 0.45")), "box")
    assert cell.in_collision(np.zeros(cell.nq))


# ------------------------------------------------------------------ size caps
@pytest.mark.parametrize("n, match", [(500, "2500 collision geometries; a cell may have at most 600"),
                                      (100, "100 arms; a cell may have at most 16")])
def test_500_arms_are_refused_by_name_quickly(n, match):
    arms = "".join(prefixed_scara(f"a{k}_", (2.0 * k, 0, 0)) for k in range(n))
    start = time.perf_counter()
    with pytest.raises(CellTooLarge, match=match):
        make_cell(f'<robot name="many"><link name="world"/>{arms}</robot>', "many")
    assert time.perf_counter() - start < 5.0


def _boxy_arm(prefix: str, x: float) -> str:
    """A one-joint arm whose link is 30 small boxes (a coarse mesh in primitives)."""
    boxes = "".join(f'<collision><origin xyz="{0.01 * i} 0 0.03"/><geometry><box size="0.02 0.08 0.06"/></geometry>'
                    "</collision>" for i in range(30))
    return (f'<joint name="{prefix}mount" type="fixed"><parent link="world"/><child link="{prefix}base_link"/>'
            f'<origin xyz="{x} 0 0"/></joint><link name="{prefix}base_link"/>'
            f'<joint name="{prefix}j1" type="revolute"><parent link="{prefix}base_link"/><child link="{prefix}arm"/>'
            '<axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>'
            f'<link name="{prefix}arm">{boxes}</link>')


def test_too_many_pairs_to_check_are_refused_before_the_sampling():
    arms = "".join(_boxy_arm(f"a{k}_", 0.3 * k) for k in range(8))  # 240 boxes, every arm within reach of the next
    start = time.perf_counter()
    with pytest.raises(CellTooLarge, match=f"pairs of collision geometries to check .* at most {limits.MAX_GEOMETRY_PAIRS}"):
        make_cell(f'<robot name="dense"><link name="world"/>{arms}</robot>', "dense")
    assert time.perf_counter() - start < 5.0


def test_20000_fixtures_are_refused_by_name_in_under_5_s():
    boxes = "".join(_fixture(f"f{k}", '<box size="0.1 0.1 0.1"/>', f"{k % 100} {5 + k // 100} 0") for k in range(20000))
    start = time.perf_counter()
    with pytest.raises(CellTooLarge, match="at most"):
        make_cell(_cell(boxes), "crowd")
    assert time.perf_counter() - start < 5.0


def test_a_1_gb_sparse_cell_file_is_refused_without_reading_it(tmp_path):
    path = tmp_path / "huge.urdf"
    with open(path, "wb") as fh:
        fh.truncate(2**30)
    start = time.perf_counter()
    with pytest.raises(CellTooLarge, match=f"{2**30} bytes; the limit is {limits.MAX_CELL_FILE_BYTES}"):
        load_cell(path)
    assert time.perf_counter() - start < 1.0
    xacro = tmp_path / "huge.urdf.xacro"
    os.rename(path, xacro)
    with pytest.raises(CellTooLarge, match="cell file"):
        load_cell(xacro)


def test_a_1_gb_sparse_mesh_is_refused_without_reading_it(tmp_path):
    with open(tmp_path / "part.stl", "wb") as fh:
        fh.truncate(2**30)
    (tmp_path / "cell.urdf").write_text(_cell(_fixture("part", '<mesh filename="part.stl"/>')), encoding="utf-8")
    start = time.perf_counter()
    with pytest.raises(CellTooLarge, match=f"mesh .*part.stl.* is {2**30} bytes"):
        load_cell(tmp_path / "cell.urdf")
    assert time.perf_counter() - start < 1.0


def test_a_cell_file_that_is_not_utf8_is_a_named_error(tmp_path):
    path = tmp_path / "latin.urdf"
    path.write_bytes(_cell().replace("c", "\u00e7", 1).encode("latin-1"))
    with pytest.raises(Exception, match="not UTF-8"):
        load_cell(path)


def test_the_caps_are_far_above_the_shipped_cells():
    for name in ("mushroom_line", "aubo_food_station"):
        cell = load_cell(name)
        G = len(cell.collision_model.geometryObjects)
        assert len(cell.arms) * 4 <= limits.MAX_ARMS and G * 10 <= limits.MAX_GEOMETRIES
        assert len(cell.fixtures) * 10 <= limits.MAX_FIXTURES


# ------------------------------------------------------------------ check_motion's times
@pytest.fixture(scope="module")
def post():
    return make_cell(post_cell_text(), "post")


@pytest.mark.parametrize("kwargs, match", [
    ({"offset": 1e10}, "offset of arm 'arm' must be a finite time within"),
    ({"offset": float("nan")}, "offset"),
    ({"offset": float("inf")}, "offset"),
    ({"period": 1e10}, "period"),
    ({"period": float("nan")}, "period"),
])
def test_absurd_times_are_refused_at_once(post, kwargs, match):
    start = time.perf_counter()
    with pytest.raises(InvalidInput, match=match):
        post.check_motion([ArmMotion("arm", SWEEP, **kwargs)], margin=0.01)
    assert time.perf_counter() - start < 1.0


@pytest.mark.parametrize("kwargs, match", [
    ({"window": (0.0, float("inf"))}, "window end"),
    ({"window": (float("nan"), 1.0)}, "window start"),
    ({"window": (0.0, 1e10)}, "window end"),
    ({"window": (1.0, 0.0)}, "t_end >= t_start"),
    ({"window": 3.0}, "window"),
    ({"margin": 1e-12}, "samples"),
    ({"margin": 1e9}, "margin"),
    ({"margin": float("nan")}, "margin"),
    ({"clearance": 1e9}, "clearance"),
])
def test_absurd_windows_and_steps_are_refused_at_once(post, kwargs, match):
    start = time.perf_counter()
    with pytest.raises(InvalidInput, match=match):
        post.check_motion([ArmMotion("arm", SWEEP)], **{"margin": 0.01, **kwargs})
    assert time.perf_counter() - start < 2.0


def test_a_late_offset_within_the_limit_still_finds_the_contact_time():
    facing = make_cell(facing_cell_text(), "facing")
    late = 9e5  # [s] within MAX_TIME: the bisection still resolves 1e-6 s
    swing = planning.multi_quintic([0.0, 1.0], np.array([[1.5, 0, 0, 0], [0.0, 0, 0, 0]]))
    early = facing.check_motion([ArmMotion("one", swing)], margin=0.01, hold=np.zeros(facing.nq))
    result = facing.check_motion([ArmMotion("one", swing, offset=late)], margin=0.01, hold=np.zeros(facing.nq))
    assert early.first_contact is not None and result.first_contact is not None
    assert abs(result.first_contact.time - late - early.first_contact.time) < 1e-5


@pytest.mark.parametrize("threads", [0, -1, 10**6, 2.0, True])
def test_batch_threads_are_bounded(post, threads):
    with pytest.raises(InvalidInput, match="threads must be an integer from 1 to 64"):
        post.in_collision(post.random_q(3), threads=threads)


def test_a_trajectory_that_turns_nan_is_a_named_error(post):
    class Broken:
        start_time, end_time = 0.0, 1.0

        def sample(self, t):
            t = np.atleast_1d(np.asarray(t, dtype=float))
            q = np.zeros((t.size, 4))
            q[t > 0.5] = np.nan
            return q if t.size > 1 else q[0], np.zeros_like(q if t.size > 1 else q[0])

    with pytest.raises(InvalidInput, match="non-finite joint values"):
        post.check_motion([ArmMotion("arm", Broken())], margin=0.01)
