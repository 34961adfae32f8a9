"""Which pairs of one arm's collision geometries :class:`SelfCollision` skips, and why (never a sample alone)."""

from __future__ import annotations

import pickle

import numpy as np

import pytest

from pinarms import robots
from pinarms.errors import ModelError, SelfContactError
from pinarms.robots.pair_rules import PairReason
from pinarms.robots.self_collision import SelfCollision


def _arm(link2_shape: str, declare: str = "") -> str:
    """A two-joint arm on a base plate 1 m wide: link 2 (two joints from the base) carries ``link2_shape``,
    which stays inside the plate at every angle when placed near the origin."""
    return f"""<robot name="plate_arm">
  <link name="base_link"><collision><origin xyz="0 0 0"/><geometry><box size="1 1 0.2"/></geometry></collision></link>
  <link name="link1"><collision><origin xyz="0 0 0.5"/><geometry><box size="0.05 0.05 0.05"/></geometry></collision></link>
  <link name="link2"><collision><geometry>{link2_shape}</geometry></collision></link>
  <link name="tool"/>
  <joint name="j1" type="revolute"><parent link="base_link"/><child link="link1"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" velocity="1" effort="1"/></joint>
  <joint name="j2" type="revolute"><parent link="link1"/><child link="link2"/><origin xyz="0 0 0"/><axis xyz="1 0 0"/>
    <limit lower="-0.3" upper="0.3" velocity="1" effort="1"/></joint>
  <joint name="jt" type="fixed"><parent link="link2"/><child link="tool"/><origin xyz="0 0 0.3"/></joint>
  {declare}
</robot>"""


def _box_arm(declare: str = "") -> robots.Robot:
    text = _arm('<box size="0.04 0.04 0.04"/>', declare).replace(
        '<link name="link2"><collision>', '<link name="link2"><collision><origin xyz="0.1 0.05 0"/>')
    return robots.from_urdf_text(text, tcp="tool")


def test_a_link_through_the_base_in_every_configuration_is_a_named_error_with_its_depth():
    with pytest.raises(SelfContactError) as err:
        SelfCollision(_box_arm())
    text = str(err.value)
    assert "base_link – link2" in text and "100% of 200" in text and "mm deep" in text
    assert "<disable_collisions" in text
    (a, b, share, depth), = err.value.pairs
    assert (a, b) == ("base_link", "link2") and share == 1.0
    assert 0.02 < depth <= 0.12  # the 4 cm cube sits inside the 20 cm plate, 10 cm below its top at most
    again = pickle.loads(pickle.dumps(err.value))
    assert isinstance(again, SelfContactError) and again.pairs == err.value.pairs


def test_the_same_contact_declared_in_the_urdf_is_skipped_with_its_reason():
    sc = SelfCollision(_box_arm('<disable_collisions link1="link2" link2="base_link" reason="mounted in the plate"/>'))
    (pair,) = [p for p in sc.allowed if {p.body_a, p.body_b} == {"base_link", "link2"}]
    assert pair.reason == PairReason.DECLARED and pair.note == "mounted in the plate"
    assert ("base_link_0", "link2_0") not in {tuple(p) for p in sc.pairs}


def test_a_sphere_on_both_joint_axes_is_proven_coaxial_not_sampled():
    sc = SelfCollision(robots.from_urdf_text(_arm('<sphere radius="0.03"/>'), tcp="tool"))
    reasons = {frozenset((p.body_a, p.body_b)): p.reason for p in sc.allowed}
    assert reasons[frozenset(("base_link", "link2"))] == PairReason.COAXIAL
    assert reasons[frozenset(("base_link", "link1"))] == PairReason.ADJACENT
    assert reasons[frozenset(("link1", "link2"))] == PairReason.ADJACENT
    assert sc.n_pairs == 0


def test_a_declaration_naming_an_unknown_link_is_refused_by_name():
    with pytest.raises(ModelError, match="disable_collisions.*'nowhere'"):
        SelfCollision(_box_arm('<disable_collisions link1="link2" link2="nowhere"/>'))


@pytest.mark.parametrize("name", robots.names())
def test_every_shipped_arm_loads_and_gives_each_skipped_pair_a_reason(name):
    arm = robots.load(name)
    sc = SelfCollision(arm)
    G = sc.n_geometries
    assert sc.n_pairs + len(sc.allowed) == G * (G - 1) // 2
    assert all(isinstance(p.reason, PairReason) for p in sc.allowed)
    assert {p.reason for p in sc.allowed} <= {PairReason.SAME_LINK, PairReason.RIGID, PairReason.COAXIAL,
                                              PairReason.ADJACENT, PairReason.DECLARED}
    checked = {frozenset(p) for p in sc.pairs.tolist()}
    assert not checked & {frozenset((p.geometry_a, p.geometry_b)) for p in sc.allowed}


def test_a_pair_in_contact_at_the_neutral_configuration_only_is_checked_not_dropped():
    # link 2's cube, 0.12 m out along y, dips into the plate only while j2 is near 0 (the neutral configuration)
    text = _arm('<box size="0.04 0.04 0.04"/>').replace(
        '<link name="link2"><collision>', '<link name="link2"><collision><origin xyz="0 0.12 0.11"/>')
    arm = robots.from_urdf_text(text, tcp="tool")
    sc = SelfCollision(arm)
    assert {frozenset(p) for p in sc.pairs.tolist()} == {frozenset(("base_link_0", "link2_0"))}
    assert sc.in_collision(arm.neutral) is True
    assert sc.in_collision(np.array([0.0, 0.3])) is False


@pytest.mark.parametrize("name, links", [("gantry_flower", ("x_carriage_link", "z_ram_link")),
                                         ("panda", ("panda_link5", "panda_link7")),
                                         ("panda", ("panda_hand", "panda_link5"))])
def test_the_shipped_contacts_at_neutral_are_declared_with_a_reason(name, links):
    sc = SelfCollision(robots.load(name))
    (pair,) = [p for p in sc.allowed if {p.body_a, p.body_b} == set(links)]
    assert pair.reason == PairReason.DECLARED and len(pair.note) > 20
