"""Closed-form IK families recognised from the kinematic structure, never from names, and proven at load."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from pinarms import robots
from pinarms.errors import ModelError
from pinarms.robots.ik import FAMILY_OF, analytic_solver, attach_analytic_ik, recognise
from pinarms.robots.ik.solver import PROOF_SAMPLES
from pinarms.robots.registry import builtin_urdf_path, match_builtin

DATA = Path(__file__).parent / "data"
TOL = 1e-9  # [m, rad] a returned solution meets its target (FK_TOL)


def _variant(text: str, *, scale: float = 1.0, rename: str = "", edit=None) -> str:
    """A URDF with every joint origin scaled, every joint renamed ``rename + name`` and an optional edit."""
    root = ET.fromstring(text)
    for j in root.iter("joint"):
        origin = j.find("origin")
        if origin is not None and origin.get("xyz"):
            origin.set("xyz", " ".join(repr(scale * float(v)) for v in origin.get("xyz").split()))
        j.set("name", rename + j.get("name"))
        mimic = j.find("mimic")
        if mimic is not None:
            mimic.set("joint", rename + mimic.get("joint"))
    if edit is not None:
        edit({j.get("name"): j for j in root.iter("joint")})
    return ET.tostring(root, encoding="unicode")


def _round_trip(robot, n: int = 40, seed: int = 7) -> None:
    """FK → ik_all: every solution meets the pose within 1e-9 and one equals the configuration."""
    q = robot.random_q(n, seed=seed)
    T = robot.fk(q)
    sols = robot.ik_all(T, q_ref=q)
    for k in range(n):
        assert sols[k].shape[0] >= 1
        err = robot.fk(sols[k]) - T[k]
        assert np.abs(err).max() <= 10 * TOL
        assert np.abs(sols[k][0] - q[k]).max() <= 1e-6


def _text(name: str) -> str:
    return builtin_urdf_path(name).read_text(encoding="utf-8")


# ------------------------------------------------------------- the registry's arms
@pytest.mark.parametrize("name", robots.names())
def test_every_registry_arm_gets_the_family_it_had_by_name(name):
    robot = robots.load(name)
    assert robot.ik_family == FAMILY_OF.get(name)  # koji_turner_rail (redundant) and panda (7 DoF): None
    assert robot.has_analytic_ik == (robot.ik_family is not None)


@pytest.mark.parametrize("name", ["scara_mushroom", "aubo_i3", "gantry_flower", "koji_turner", "ur5"])
def test_recognised_solver_gives_the_same_solutions_as_the_named_one(name):
    robot = robots.load(name)
    named = analytic_solver(robot, FAMILY_OF[name])
    T = robot.fk(robot.random_q(30, seed=3))
    for got, want in zip(robot.ik_all(T), named.solve(T)):
        np.testing.assert_array_equal(got, want)


def test_panda_has_no_family_and_says_its_joints_fit_none():
    panda = robots.load("panda")
    assert recognise(panda).family is None and recognise(panda).rejected == {}
    with pytest.raises(ModelError, match="not those of any of them"):
        panda.ik_all(panda.fk(panda.neutral))


# ------------------------------------------------------------------- users' arms
def test_users_600mm_scara_named_j1_to_j4_gets_its_own_closed_form_and_keeps_its_name():
    arm = robots.from_urdf(DATA / "user_scara.urdf")
    assert arm.name == "user_scara600" and arm.ik_family == "scara"
    assert match_builtin(arm) is None  # j1..j4 like the built-in SCARA, but not that arm
    _round_trip(arm)
    # its own lengths: fully stretched the tcp is 0.35 + 0.25 m from the first axis
    assert arm.fk(np.zeros(4))[0, 3] == pytest.approx(0.60, abs=1e-12)


def test_users_six_axis_arm_is_ur_type_from_urdf_text_too():
    text = (DATA / "user_6r.urdf").read_text(encoding="utf-8")
    arm = robots.from_urdf_text(text)
    assert arm.name == "user_6r" and arm.ik_family == "ur_type"
    _round_trip(arm)


def test_from_xacro_recognises_the_family(tmp_path):
    text = (DATA / "user_scara.urdf").read_text(encoding="utf-8")
    text = text.replace('<robot name="user_scara600">', '<robot name="user_scara600" xmlns:xacro="http://www.ros.org/wiki/xacro">')
    (tmp_path / "scara.urdf.xacro").write_text(text, encoding="utf-8")
    arm = robots.from_xacro(tmp_path / "scara.urdf.xacro")
    assert arm.ik_family == "scara" and arm.name == "user_scara600"


@pytest.mark.parametrize(
    "name, family, scale",
    [("scara_mushroom", "scara", 2.4), ("aubo_i3", "ur_type", 1.3), ("gantry_flower", "gantry", 0.5),
     ("koji_turner", "koji", 1.7)],
)
def test_scaled_and_renamed_variants_of_the_built_ins_are_recognised(name, family, scale):
    arm = robots.from_urdf_text(_variant(_text(name), scale=scale, rename="axis_"), name="variant")
    assert arm.ik_family == family and arm.name == "variant"
    assert match_builtin(arm) is None
    assert match_builtin(robots.from_urdf_text(_variant(_text(name), rename="axis_"))) == name  # names play no part
    _round_trip(arm, n=24)


def test_changing_the_tcp_proves_the_closed_form_again_for_the_new_frame():
    arm = robots.from_urdf(DATA / "user_scara.urdf")
    before = arm._analytic_ik
    arm.tcp_frame = "link4"  # the hand flange, 60 mm above the tcp
    assert arm.ik_family == "scara" and arm._analytic_ik is not before
    _round_trip(arm, n=16)
    arm.tcp_frame = "link2"  # j3 and j4 no longer move it: no family, numerical IK
    assert arm.ik_family is None
    arm.tcp_frame = "tcp"
    assert arm.ik_family == "scara"


# ------------------------------------------------------------------- near-misses
def _tilt_j2(joints):
    joints["j2"].find("axis").set("xyz", "0 0.01 1")


def _offset_a6(joints):
    joints["a6"].find("origin").set("xyz", "0.01 0 -0.1")  # axes 5 and 6 pass 10 mm apart


def _shift_a3(joints):
    joints["a3"].find("axis").set("xyz", "0 1 0.02")  # axis 3 no longer parallel to axes 2 and 4


@pytest.mark.parametrize(
    "file, edit, refused",
    [("user_scara.urdf", _tilt_j2, "scara"), ("user_6r.urdf", _offset_a6, "ur_type"),
     ("user_6r.urdf", _shift_a3, "ur_type")],
)
def test_near_misses_are_not_recognised_and_numerical_ik_is_used(file, edit, refused):
    arm = robots.from_urdf_text(_variant((DATA / file).read_text(encoding="utf-8"), edit=edit))
    assert arm.ik_family is None and not arm.has_analytic_ik
    assert refused in arm._ik_rejected
    with pytest.raises(ModelError, match="no analytic IK"):
        arm.ik_all(arm.fk(arm.neutral))
    q = arm.random_q(1, seed=5)[0]
    target = arm.fk(q)
    sol = arm.ik(target, q_seed=q + 0.05)  # numerical
    assert np.abs(arm.fk(sol) - target).max() <= 1e-8


def test_the_load_time_proof_refuses_a_closed_form_that_misses():
    arm = robots.from_urdf(DATA / "user_scara.urdf")
    solver = analytic_solver(arm, "scara")
    solver.home_inv = solver.home_inv @ np.diag([1.0, 1.0, 1.0, 1.0]) + np.array(
        [[0, 0, 0, 0.002], [0, 0, 0, 0], [0, 0, 0, 0], [0, 0, 0, 0]])  # the tcp 2 mm off
    with pytest.raises(ModelError, match="does not reproduce"):
        solver._self_check()
    assert PROOF_SAMPLES >= 24


def test_an_explicit_family_that_does_not_fit_raises():
    arm = robots.from_urdf(DATA / "user_scara.urdf")
    with pytest.raises(ModelError):
        attach_analytic_ik(arm, "ur_type")


def test_huge_joint_ranges_cost_nothing_at_load_and_equivalents_are_bounded():
    from pinarms.errors import InvalidInput

    text = (DATA / "user_scara.urdf").read_text(encoding="utf-8").replace('lower="-2.6" upper="2.6"',
                                                                          'lower="-1e9" upper="1e9"')
    arm = robots.from_urdf_text(text)  # 3e8 equivalents of j1: never enumerated
    assert arm.ik_family == "scara"
    q = np.array([1.0e3, 2.0, 0.1, -1.0])
    sols = arm.ik_all(arm.fk(q), q_ref=q)
    assert np.abs(sols[0] - q).max() < 1e-6
    with pytest.raises(InvalidInput, match="equivalents"):
        arm.ik_all(arm.fk(q), equivalents=True)
