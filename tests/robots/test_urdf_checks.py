"""Checks of a URDF around Pinocchio's parse: no DTD, one tree, limits that make sense."""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET

import pytest

from pinarms import robots
from pinarms.errors import ModelError
from pinarms.robots.urdf_checks import check_limits, check_tree, refuse_dtd

TWO_LINKS = """<robot name="r"><link name="a"/><link name="b"/>
<joint name="j" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/>
<limit lower="-1" upper="1" velocity="1" effort="1"/></joint></robot>"""


def test_a_tree_passes_and_a_loop_is_named():
    check_tree(ET.fromstring(TWO_LINKS), "two.urdf")
    loop = TWO_LINKS.replace("</robot>", '<joint name="k" type="fixed"><parent link="b"/><child link="a"/></joint></robot>')
    with pytest.raises(ModelError, match="two.urdf: no root link"):
        check_tree(ET.fromstring(loop), "two.urdf")


def test_a_doctype_is_refused_before_any_parse():
    refuse_dtd(TWO_LINKS, "two.urdf")
    with pytest.raises(ModelError, match="two.urdf declares a DOCTYPE"):
        refuse_dtd('<!DOCTYPE r [<!ENTITY e "x">]>' + TWO_LINKS, "two.urdf")


def test_swapped_limits_are_named():
    robot = robots.from_urdf_text(TWO_LINKS)
    check_limits(robot.model, "two.urdf")
    model = robot.model.copy()
    model.lowerPositionLimit[0], model.upperPositionLimit[0] = 1.0, -1.0
    with pytest.raises(ModelError, match="joint 'j' has lower limit"):
        check_limits(model, "two.urdf")


@pytest.mark.parametrize("mass", ["-1", "nan", "inf"])
def test_a_negative_or_non_finite_link_mass_is_named(mass):
    text = TWO_LINKS.replace('<link name="b"/>', f'<link name="b"><inertial><mass value="{mass}"/>'
                             '<inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>')
    with pytest.raises(ModelError, match="link 'b' has mass"):
        robots.from_urdf_text(text, name="two")


@pytest.mark.parametrize("lower, upper", [("-1e308", "1e308"), ("-1e10", "1"), ("-1", "1e10")])
def test_a_position_limit_beyond_the_bound_is_named(lower, upper):
    from pinarms.robots.urdf_checks import MAX_POSITION_LIMIT

    text = TWO_LINKS.replace('lower="-1" upper="1"', f'lower="{lower}" upper="{upper}"')
    with pytest.raises(ModelError, match=re.escape(f"joint 'j' has a position limit beyond ±{MAX_POSITION_LIMIT:g}")):
        robots.from_urdf_text(text, name="two")


@pytest.mark.parametrize("attr", ['velocity="1e308"', 'effort="1e308"'])
def test_a_speed_or_effort_limit_beyond_the_bound_is_named(attr):
    key = attr.split("=")[0]
    text = TWO_LINKS.replace(f'{key}="1"', attr)
    with pytest.raises(ModelError, match=f"joint 'j' has a {key} limit"):
        robots.from_urdf_text(text, name="two")


@pytest.mark.parametrize("doctype", [
    '<!DOCTYPE robot [<!ENTITY % p SYSTEM "{dtd}"> %p;]>',  # external parameter entity
    '<!DOCTYPE robot SYSTEM "{dtd}">',                        # external DTD
    '<!DOCTYPE robot [<!ENTITY x SYSTEM "{dtd}">]>',          # external general entity
])
def test_a_plain_urdf_with_an_external_doctype_is_refused_by_from_urdf_and_fk(tmp_path, doctype):
    """Issue 35 item 12: a DOCTYPE in a plain .urdf gets the same named error as in a xacro file, no model."""
    from click.testing import CliRunner

    from pinarms.cli import cli

    dtd = tmp_path / "names.dtd"
    dtd.write_text('<!ENTITY name "b">')
    path = tmp_path / "recv.urdf"
    path.write_text('<?xml version="1.0"?>\n' + doctype.format(dtd=dtd.as_uri()) + "\n" + TWO_LINKS)
    with pytest.raises(ModelError, match="recv.urdf declares a DOCTYPE"):
        robots.from_urdf(path)
    result = CliRunner().invoke(cli, ["fk", str(path), "0"])
    assert result.exit_code == 1 and "Traceback" not in result.output
    assert result.stderr.startswith("Error:") and "declares a DOCTYPE" in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1
