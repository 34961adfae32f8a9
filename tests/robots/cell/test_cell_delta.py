"""A delta in a cell: its joint vector, its bodies from the closed form, clearance and continuous checks.

The reference is independent of the cell's delta code: the delta's passive joints solved by
Pinocchio's projection onto its closed-chain constraints (``DeltaRobot.project``), its bodies built
here from the model's frames (motor, elbow, rod ball centres, platform, tcp), and plain coal
distances over every pair but those joined by design; the tree's pairs (the SCARA, the fixtures)
by the all-pairs reference of ``_cells``.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import coal
import numpy as np
import pinocchio as pin
import pytest

from pinarms.errors import CellError
from pinarms.planning import quintic_bspline
from pinarms.robots.cell import load_cell
from pinarms.robots.cell.delta_motion import delta_speed
from pinarms.robots.delta import forward_position, inverse_position
from pinarms.robots.delta.collision import PART_RADII, PLATFORM_THICKNESS

from _cells import Reference

ROOT = Path(__file__).resolve().parents[3]
BASE_XYZ = np.array([0.0, 0.0, 2.3])
BIN_THETA = np.array([0.3, 0.3, 0.3])

CELL = """name = "delta_belt"

[[arm]]
name = "picker"
delta = "delta_flexpicker"
xyz = [0.0, 0.0, 2.3]
states = {{ up = [0.0, 0.0, 0.0, 0.0] }}
hold = "up"

[[arm]]
name = "scara"
urdf = "scara_mushroom.urdf"
xyz = [0.0, 1.0, 0.8]

[[fixture]]
name = "belt"
box = [2.0, 0.6, 0.05]
xyz = [0.0, 0.0, 0.775]

[[fixture]]
name = "bin"
box = [0.12, 0.12, 0.1]
xyz = [{x}, {y}, {z}]
"""


@pytest.fixture(scope="module")
def cell(tmp_path_factory):
    from pinarms.robots.delta import load_delta

    folder = tmp_path_factory.mktemp("delta_cell")
    shutil.copy(ROOT / "urdf" / "scara_mushroom.urdf", folder)
    # the bin where the platform is at BIN_THETA: 40 mm below the platform's centre
    p = forward_position(load_delta("delta_flexpicker").geometry, BIN_THETA) + BASE_XYZ
    (folder / "cell.toml").write_text(CELL.format(x=p[0], y=p[1], z=p[2] - 0.04), encoding="utf-8")
    return load_cell(folder / "cell.toml")


def _segment(a: np.ndarray, b: np.ndarray, radius: float) -> tuple[object, np.ndarray]:
    """A capsule from a to b and its pose (z along a -> b), built here."""
    z = (b - a) / np.linalg.norm(b - a)
    x = np.cross([0.0, 0.0, 1.0] if abs(z[2]) < 0.9 else [1.0, 0.0, 0.0], z)
    x /= np.linalg.norm(x)
    T = np.eye(4)
    T[:3, :3] = np.column_stack([x, np.cross(z, x), z])
    T[:3, 3] = (a + b) / 2
    return coal.Capsule(radius, float(np.linalg.norm(b - a))), T


def _reference_bodies(delta, theta: np.ndarray) -> dict[str, tuple[object, np.ndarray]]:
    """The delta's bodies in the world, from Pinocchio's closed-chain model (passive joints by projection)."""
    model = delta.model
    q = delta.project(theta)
    assert np.abs(delta.closure_residuals(q)).max() < 1e-9
    data = model.createData()
    pin.framesForwardKinematics(model, data, q)
    frame = lambda name: data.oMf[model.getFrameId(name)].translation + BASE_XYZ  # noqa: E731
    joint = lambda name: data.oMi[model.getJointId(name)].translation + BASE_XYZ  # noqa: E731
    R = delta.geometry.base_radius
    base = np.eye(4)
    base[:3, 3] = BASE_XYZ + [0.0, 0.0, 0.06]
    out = {"base": (coal.Box(2.4 * R, 2.4 * R, 0.04), base)}
    for i in (1, 2, 3):
        out[f"upper_arm_{i}"] = _segment(joint(f"leg{i}_motor"), joint(f"leg{i}_elbow_fold"), PART_RADII["upper_arm"])
        for r in "ab":
            out[f"rod_{i}{r}"] = _segment(frame(f"leg{i}_rod_top_{r}"), frame(f"platform_ball{i}_{r}"), PART_RADII["rod"])
    plate = np.eye(4)
    plate[:3, 3] = frame("platform_link")
    g = delta.geometry
    out["platform"] = (coal.Cylinder(g.platform_radius + g.rod_spacing / 2, PLATFORM_THICKNESS), plate)
    out["tool"] = _segment(frame("platform_link"), frame("tcp"), PART_RADII["tool"])
    return out


def _joined(delta) -> set[frozenset[str]]:
    """Body pairs joined by design, written here: motor, upper balls, lower balls, tool; neighbouring legs'
    rods whose lower balls (frames of the model at any configuration) are closer than two rod radii."""
    out = {frozenset(("platform", "tool"))}
    for i in (1, 2, 3):
        out.add(frozenset(("base", f"upper_arm_{i}")))
        for r in "ab":
            out |= {frozenset((f"upper_arm_{i}", f"rod_{i}{r}")), frozenset((f"rod_{i}{r}", "platform"))}
    data = delta.model.createData()
    pin.framesForwardKinematics(delta.model, data, delta.home())
    ball = lambda name: data.oMf[delta.model.getFrameId(name)].translation  # noqa: E731
    for i in (1, 2, 3):
        for j in (1, 2, 3):
            for ra, rb in (("a", "b"), ("b", "a")):
                if i != j and np.linalg.norm(ball(f"platform_ball{i}_{ra}") - ball(f"platform_ball{j}_{rb}")) < 2 * PART_RADII["rod"]:
                    out.add(frozenset((f"rod_{i}{ra}", f"rod_{j}{rb}")))
    return out


def _tf(T: np.ndarray) -> coal.Transform3s:
    return coal.Transform3s(T[:3, :3].copy(), T[:3, 3].copy())


def _reference_distances(cell, q: np.ndarray) -> dict[frozenset[str], float]:
    """``{pair of bodies: distance}`` over every pair of the delta's bodies with each other and with every tree
    geometry (but those joined by design, and the base with what does not move), and the tree's own pairs."""
    picker = cell.deltas[0].delta
    bodies = _reference_bodies(picker, q[:3])
    joined = _joined(picker)
    gm = cell.collision_model
    gd = pin.GeometryData(gm)
    data = cell.model.createData()
    pin.updateGeometryPlacements(cell.model, data, gm, gd, cell.robot.q_to_pinocchio(q))
    out: dict[frozenset[str], float] = {}
    names = list(bodies)
    for k, a in enumerate(names):
        for b in names[k + 1:]:
            if frozenset((a, b)) not in joined:
                out[frozenset((f"picker_{a}", f"picker_{b}"))] = coal.distance(
                    bodies[a][0], _tf(bodies[a][1]), bodies[b][0], _tf(bodies[b][1]), coal.DistanceRequest(),
                    coal.DistanceResult())
        for g, obj in enumerate(gm.geometryObjects):
            if a == "base" and obj.parentJoint == 0:
                continue
            d = coal.distance(bodies[a][0], _tf(bodies[a][1]), obj.geometry, _tf(gd.oMg[g].homogeneous),
                              coal.DistanceRequest(), coal.DistanceResult())
            key = frozenset((f"picker_{a}", cell.model.frames[obj.parentFrame].name))
            out[key] = min(d, out.get(key, np.inf))
    out[frozenset(("tree",))] = float(Reference(cell).distances(q).min())
    return out


def test_delta_block_is_its_motor_angles(cell):
    arm = cell.arm("picker")
    assert arm.robot.joint_names == ("leg1_motor", "leg2_motor", "leg3_motor", "tool")
    d = cell.deltas[0]
    assert (d.q_slice.start, d.q_slice.stop) == (arm.q_slice.start, arm.q_slice.stop) and cell.nq == 8
    assert not any(g.name.startswith("picker_") for g in cell.collision_model.geometryObjects)   # no tree posed
    q = cell.q_from_arms({"picker": [0.2, -0.1, 0.4, 1.0]})
    theta = np.array([0.2, -0.1, 0.4])
    tcp = d.delta.tcp_position(d.delta.project(theta)) + BASE_XYZ     # Pinocchio's closed chain
    assert np.allclose(d.tcp_to_world(q), tcp, atol=1e-9)


def test_clearance_equals_plain_pinocchio_and_coal_over_every_pair(cell):
    rng = np.random.default_rng(7)
    Q = cell.random_q(6, seed=rng)
    Q[0] = cell.hold
    Q[1, :3] = BIN_THETA
    got = cell.clearance(Q)
    for i, q in enumerate(Q):
        ref = _reference_distances(cell, q)
        best = min(ref.values())
        assert abs(got.distance[i] - best) <= 1e-6, (i, got.distance[i], best)
        pair = frozenset(got.pair_of(i).bodies)
        assert abs(ref.get(pair, ref[frozenset(("tree",))]) - best) <= 1e-6     # the pair named has that distance


def test_colliding_fixture_found_and_clear_one_reported_with_its_minimum(cell):
    q_hit = cell.q_from_arms({"picker": [*BIN_THETA, 0.0]})
    hits = cell.collisions(q_hit)
    bodies = hits.bodies_at(0)
    assert ("picker_tool", "bin") in bodies and cell.in_collision(q_hit)
    assert cell.clearance(q_hit).distance < 0.0
    fixtures_only = cell.with_pairs("arm-fixture")
    q_clear = cell.hold
    assert not fixtures_only.in_collision(q_clear)
    got = fixtures_only.clearance(q_clear)
    # the true minimum over every moving body and every fixture, by plain coal: the delta's bodies from the
    # closed chain, the SCARA's links from Pinocchio's placements, the fixtures from their shapes
    moving = list(_reference_bodies(cell.deltas[0].delta, q_clear[:3]).values())
    gm, data = cell.collision_model, cell.model.createData()
    gd = pin.GeometryData(gm)
    pin.updateGeometryPlacements(cell.model, data, gm, gd, cell.robot.q_to_pinocchio(q_clear))
    moving += [(obj.geometry, gd.oMg[g].homogeneous) for g, obj in enumerate(gm.geometryObjects) if obj.parentJoint]
    boxes = [(coal.Box(*s.size), s.shape_to_world) for f in cell.fixtures for s in f.shapes]
    ref = min(coal.distance(shape, _tf(T), box, _tf(B), coal.DistanceRequest(), coal.DistanceResult())
              for shape, T in moving for box, B in boxes)
    assert got.distance > 0.0 and abs(got.distance - ref) < 1e-6
    assert got.pair_of().body_a.startswith("picker_") and got.pair_of().body_b in ("belt", "bin")


def _platform_move(cell, p0, p1, duration: float = 0.5):
    """A minimum-jerk straight platform move (base frame) as the delta's joint trajectory (quintic spline)."""
    s = np.linspace(0.0, 1.0, 41)
    tau = 10 * s ** 3 - 15 * s ** 4 + 6 * s ** 5
    p = np.asarray(p0) + tau[:, None] * (np.asarray(p1) - np.asarray(p0))
    theta = inverse_position(cell.deltas[0].delta.geometry, p)
    return quintic_bspline(duration * s, np.hstack([theta, np.zeros((s.size, 1))]))


def test_motion_through_the_bin_touches_it_first_where_dense_sampling_does(cell):
    p_bin = forward_position(cell.deltas[0].delta.geometry, BIN_THETA)
    traj = _platform_move(cell, p_bin + [-0.3, 0.0, 0.0], p_bin + [0.3, 0.0, 0.0])
    check = cell.with_pairs("external").check_motion({"picker": traj}, margin=0.01)
    assert not check.collision_free and check.first_contact is not None
    assert set(check.first_contact.pair.bodies) <= {"picker_tool", "picker_platform", "bin"} | {
        f"picker_rod_{i}{r}" for i in (1, 2, 3) for r in "ab"} and "bin" in check.first_contact.pair.bodies
    t = np.linspace(0.0, 0.5, 801)
    dense = cell.with_pairs("external").clearance(cell.q_from_arms({"picker": traj.sample(t)[0]})).distance
    t_first = t[np.argmax(dense <= 0.0)]
    assert t_first - 0.5 / 800 <= check.first_contact.time <= t_first + 1e-6


def test_motion_above_the_bin_is_proven_clear_with_its_true_minimum(cell):
    p_bin = forward_position(cell.deltas[0].delta.geometry, BIN_THETA)
    traj = _platform_move(cell, p_bin + [-0.3, 0.0, 0.12], p_bin + [0.3, 0.0, 0.12])
    external = cell.with_pairs("external")
    check = external.check_motion({"picker": traj}, margin=0.01, clearance=0.02)
    assert check.collision_free and check.clear
    t = np.linspace(0.0, 0.5, 801)
    dense = external.clearance(external.q_from_arms({"picker": traj.sample(t)[0]}))
    assert check.lower_bound <= dense.distance.min() <= check.min_clearance + 1e-9
    assert check.min_clearance - dense.distance.min() <= check.margin
    assert "bin" in check.min_clearance_pair.bodies
    # a required clearance above the true minimum is not proven
    assert not external.check_motion({"picker": traj}, margin=0.01, clearance=dense.distance.min() + 0.01).clear


def test_speed_bound_holds_on_the_motion(cell):
    d = cell.deltas[0]
    p_bin = forward_position(d.delta.geometry, BIN_THETA)
    traj = _platform_move(cell, p_bin + [-0.3, 0.1, 0.1], p_bin + [0.3, -0.1, 0.0], duration=0.4)
    t = np.linspace(0.0, 0.4, 4001)
    theta = traj.sample(t)[0][:, :3]
    v, h = delta_speed(d.delta, theta, traj.peaks().velocity[:3])
    poses = d.poses(theta)
    spheres, _, body = d.spheres
    points = np.einsum("nsij,sj->nsi", poses[:, body][..., :3, :3], spheres) + poses[:, body][..., :3, 3]
    speed = np.linalg.norm(np.diff(points, axis=0), axis=2).max(axis=1) / np.diff(t)
    assert np.all(speed <= v[:-1]) and np.all(np.diff(t) <= h[:-1]) or np.all(speed <= v[:-1])
    assert speed.max() > 0.2 * v.min()       # the bound is not vacuous


def test_description_errors_name_the_delta(tmp_path):
    for body, words in (('[[arm]]\nname = "d"\ndelta = "delta_flexpicker"\nurdf = "x.urdf"\n', "exactly one"),
                        ('[[arm]]\nname = "d"\ndelta = "delta_flexpicker"\ntcp = "platform"\n', "tcp"),
                        ('[[arm]]\nname = "d"\ndelta = "no_such_delta"\n', "shipped deltas")):
        (tmp_path / "c.toml").write_text(body, encoding="utf-8")
        with pytest.raises(CellError, match=words):
            load_cell(tmp_path / "c.toml")


def test_cli_show_and_check_name_the_delta_and_the_fixture(cell, tmp_path):
    from click.testing import CliRunner

    from pinarms.cli import cli

    q = ",".join(str(v) for v in [*BIN_THETA, 0.0, 0.0, 0.0, 0.0, 0.0])
    shown = CliRunner().invoke(cli, ["cell", "show", cell.source])
    assert shown.exit_code == 0 and "delta delta_flexpicker" in shown.output
    checked = CliRunner().invoke(cli, ["cell", "check", cell.source, "--q", q])
    assert checked.exit_code == 0 and "picker_tool – bin" in checked.output


def test_cell_export_refuses_a_delta_it_would_lose(cell, tmp_path):
    from pinarms.errors import InvalidInput
    from pinarms.export.cell import export_cell

    with pytest.raises(InvalidInput, match="holds a delta"):
        export_cell(cell, tmp_path / "out", mjcf=False)
    assert not (tmp_path / "out").exists()


def test_motion_checker_refuses_what_it_cannot_see(cell):
    from pinarms.errors import InvalidInput
    from pinarms.optim.motion import MotionChecker

    for arms in (["picker"], ["scara"]):   # the delta itself; a serial arm a delta's body may touch
        with pytest.raises(InvalidInput, match="holds a delta"):
            MotionChecker(cell, arms)


def test_a_cycle_in_a_cell_refuses_a_delta_arm_by_name(cell):
    """The cell's tree holds the delta's motors only, so a serial cycle of it would be meaningless: refused."""
    from pinarms import optim
    from pinarms.errors import InvalidInput

    picker = cell.arm("picker")
    spec = optim.PickPlace(pick=np.eye(4), place=np.eye(4), lift=0.05, dwell=0.1)
    with pytest.raises(InvalidInput, match=r"'picker'.*is a delta.*belt run --robot delta_flexpicker"):
        optim.plan_cycle(optim.CycleRequest(picker.robot, spec, cell=optim.CellSettings(cell, arm="picker")))
