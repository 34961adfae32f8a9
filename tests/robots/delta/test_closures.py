"""The loop-closures file: the shipped one, Pinocchio's constraint models from it, hostile files."""

from __future__ import annotations

import os

import numpy as np
import pytest

from pinarms.robots.delta import (MAX_CLOSURES, MAX_CLOSURES_BYTES, ClosuresFileError, ClosureSet, LoopClosure,
                                  NotADelta, closures_to_xml, constraint_models, delta_from_files, delta_info,
                                  parse_closures, read_closures, write_closures)
from pinarms.robots.delta.build import build_delta, stale_deltas

GOOD = '<loop_closures robot="r" version="1"><closure name="a" type="point" frame1="f1" frame2="f2"/></loop_closures>'


def test_shipped_files_are_fresh_builds_of_the_xacro():
    assert stale_deltas() == []
    files = build_delta("delta_flexpicker")
    assert sorted(p.name for p in files) == ["delta_flexpicker.closures.xml", "delta_flexpicker.urdf"]


def test_shipped_closures_give_three_ball_joint_constraints(delta):
    cs = read_closures(delta_info("delta_flexpicker").closures_path)
    assert cs.robot == "delta_flexpicker"
    assert [(c.name, c.frame1, c.frame2, c.kind) for c in cs.closures] == [
        (f"leg{i}", f"leg{i}_ball", f"platform_ball{i}", "point") for i in (1, 2, 3)]
    models = constraint_models(delta.model, cs)
    assert [m.name for m in models] == ["leg1", "leg2", "leg3"]
    assert [c.n_equations for c in cs.closures] == [3, 3, 3]
    assert delta.constraint_jacobian(delta.home()).shape == (9, delta.model.nv)


def test_the_closures_hold_on_the_closed_form_configuration(delta):
    q = delta.configuration(np.array([[0.1, 0.4, 0.7], [0.9, -0.3, 0.2]]))
    assert np.abs(delta.closure_residuals(q)).max() < 1e-12
    q[0, delta.platform_q[2]] += 1e-3          # move the platform 1 mm: every leg's closure opens
    assert delta.closure_residuals(q)[0].min() > 5e-4


def test_write_then_read_round_trip(tmp_path):
    cs = ClosureSet("r", (LoopClosure("a", "f1", "f2"), LoopClosure("b", "f3", "f4", "frame")))
    path = write_closures(tmp_path / "r.closures.xml", cs, comment="x -- y")
    assert read_closures(path) == cs
    assert parse_closures(closures_to_xml(cs)) == cs


@pytest.mark.parametrize("text, words", [
    ('<!DOCTYPE x [<!ENTITY a "b">]>' + GOOD, "DOCTYPE"),
    ("<loop_closures", "well-formed"),
    (GOOD.replace("loop_closures", "robot"), "expected <loop_closures>"),
    (GOOD.replace('version="1"', 'version="2"'), "version"),
    (GOOD.replace('type="point"', 'type="hinge"'), "'hinge'"),
    (GOOD.replace('frame2="f2"', 'frame2="f1"'), "to itself"),
    (GOOD.replace('name="a"', 'name="a" colour="red"'), "unknown attribute"),
    (GOOD.replace('name="a"', 'name=""'), "closure name"),
    (GOOD.replace('frame1="f1"', 'frame1="' + "f" * 201 + '"'), "frame1"),
    (GOOD.replace("</loop_closures>", '<closure name="a" frame1="x" frame2="y"/></loop_closures>'), "twice"),
    (GOOD.replace("</loop_closures>", "<joint/></loop_closures>"), "<joint>"),
    ('<loop_closures robot="r" version="1"/>', "no <closure>"),
])
def test_bad_closures_text_is_a_named_error(text, words):
    with pytest.raises(ClosuresFileError, match=None) as info:
        parse_closures(text, source="bad.closures.xml")
    assert words in str(info.value) and "bad.closures.xml" in str(info.value)


def test_too_many_closures_are_refused():
    body = "".join(f'<closure name="c{i}" frame1="a{i}" frame2="b{i}"/>' for i in range(MAX_CLOSURES + 1))
    with pytest.raises(ClosuresFileError, match=f"at most {MAX_CLOSURES}"):
        parse_closures(f'<loop_closures robot="r" version="1">{body}</loop_closures>')


def test_oversized_fifo_and_missing_files_are_refused_unread(tmp_path):
    big = tmp_path / "big.closures.xml"
    big.write_text(GOOD + " " * MAX_CLOSURES_BYTES)
    with pytest.raises(ClosuresFileError, match="limit"):
        read_closures(big)
    fifo = tmp_path / "fifo.closures.xml"
    os.mkfifo(fifo)
    with pytest.raises(ClosuresFileError, match="fifo.closures.xml"):
        read_closures(fifo)
    with pytest.raises(ClosuresFileError, match="missing.closures.xml"):
        read_closures(tmp_path / "missing.closures.xml")


def test_closures_of_another_robot_or_unknown_frames_are_refused(tmp_path):
    entry = delta_info("delta_flexpicker")
    other = write_closures(tmp_path / "o.closures.xml", ClosureSet("scara", (LoopClosure("a", "leg1_ball", "tcp"),)))
    with pytest.raises(ClosuresFileError, match="closes robot 'scara'"):
        delta_from_files(entry.urdf_path, other, acceleration=100.0)
    ghost = write_closures(tmp_path / "g.closures.xml",
                           ClosureSet("delta_flexpicker", (LoopClosure("a", "leg1_ball", "ghost_frame"),)))
    with pytest.raises(ClosuresFileError, match="ghost_frame"):
        delta_from_files(entry.urdf_path, ghost, acceleration=100.0)
    same_body = write_closures(tmp_path / "s.closures.xml",
                               ClosureSet("delta_flexpicker", (LoopClosure("a", "leg1_ball", "leg1_forearm"),)))
    with pytest.raises(ClosuresFileError, match="same body"):
        delta_from_files(entry.urdf_path, same_body, acceleration=100.0)


def test_a_tree_that_is_not_the_family_is_not_a_delta(tmp_path):
    urdf = tmp_path / "arm.urdf"
    urdf.write_text('<robot name="arm"><link name="a"/><link name="b"/><joint name="j" type="revolute">'
                    '<parent link="a"/><child link="b"/><axis xyz="0 0 1"/>'
                    '<limit lower="-1" upper="1" velocity="1" effort="1"/></joint></robot>')
    closures = write_closures(tmp_path / "arm.closures.xml", ClosureSet("arm", (LoopClosure("c", "a", "b"),)))
    with pytest.raises(NotADelta, match="leg1"):
        delta_from_files(urdf, closures, acceleration=100.0)


def test_build_check_reports_fresh_files(capsys):
    from pinarms.robots.delta.build import main

    assert main(["--check"]) == 0
    assert capsys.readouterr().out == ""


def test_unknown_delta_and_bad_payload_are_named_errors(delta):
    from pinarms.errors import RobotNotFound
    from pinarms.robots.delta import DeltaInputError, load_delta

    with pytest.raises(RobotNotFound, match="shipped deltas: delta_flexpicker"):
        load_delta("flexpicker")
    with pytest.raises(DeltaInputError, match="payload mass"):
        delta.with_payload(-1.0)
    with pytest.raises(DeltaInputError, match="acceleration"):
        delta_from_files(delta_info("delta_flexpicker").urdf_path, delta_info("delta_flexpicker").closures_path,
                         acceleration=0.0)


def test_a_urdf_with_a_doctype_is_refused_before_pinocchio(tmp_path):
    entry = delta_info("delta_flexpicker")
    text = entry.urdf_path.read_text(encoding="utf-8")
    hostile = tmp_path / "delta_flexpicker.urdf"
    hostile.write_text(text.replace("<robot ", '<!DOCTYPE robot [<!ENTITY x "y">]>\n<robot ', 1), encoding="utf-8")
    from pinarms.errors import ModelError

    with pytest.raises(ModelError, match="DOCTYPE"):
        delta_from_files(hostile, entry.closures_path, acceleration=100.0)
