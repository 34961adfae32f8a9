"""Malformed URDF text through robots.from_urdf_text: a ModelError/InvalidInput or a robot that computes.

URDFs are generated from a random tree description (missing links, duplicate names,
loops, mimic joints pointing nowhere or at themselves, NaN/inf/negative/swapped limits,
zero or NaN axes, NaN origins, unknown joint types), then sometimes damaged as text
(truncated, DOCTYPE and entity declarations). A robot that builds must give finite FK,
Jacobians, limits and random configurations.
"""

from __future__ import annotations

import numpy as np
from hypothesis import example, given, settings
from hypothesis import strategies as st

from fuzz_support import EXPLORE, outcome
from pinarms import robots

_num = st.one_of(
    st.floats(-3, 3, allow_nan=False).map(lambda x: f"{x:.4g}"),
    st.sampled_from(["nan", "NaN", "inf", "-inf", "1e308", "-1e308", "0", "", "abc", "1 2", "0x10", "1e-320"]),
)
_vec3 = st.one_of(st.tuples(_num, _num, _num).map(" ".join), _num, st.sampled_from(["0 0 0", "0 0 1", "1 0"]))
_types = st.sampled_from(["revolute", "continuous", "prismatic", "fixed", "revolute", "prismatic", "floating",
                          "planar", "spherical", "screw", ""])


_sane = st.floats(-1, 1).map(lambda x: f"{x:.4g}")
_DEFECTS = ["none", "none", "none", "missing-link", "duplicate-link", "duplicate-joint", "loop", "mimic-missing",
            "mimic-self", "mimic-ok", "nan-limit", "swapped-limits", "zero-axis", "nan-origin", "unknown-type",
            "no-limit", "negative-effort", "entity", "doctype", "truncate", "garbage", "two-roots"]


@st.composite
def chains(draw):
    """A valid serial chain of 1-5 joints, then at most one defect a user could write."""
    n = draw(st.integers(1, 5))
    links = [f"l{i}" for i in range(n + 1)]
    joints = []
    for i in range(n):
        jtype = draw(st.sampled_from(["revolute", "revolute", "prismatic", "continuous", "fixed"]))
        lo = draw(st.floats(-3, 0))
        hi = draw(st.floats(0.01, 3))
        joints.append({"name": f"j{i}", "type": jtype, "parent": links[i], "child": links[i + 1],
                       "xyz": " ".join(draw(_sane) for _ in range(3)), "rpy": " ".join(draw(_sane) for _ in range(3)),
                       "axis": draw(st.sampled_from(["0 0 1", "1 0 0", "0 1 0", "0.6 0.8 0"])),
                       "limit": {"lower": f"{lo:.4g}", "upper": f"{hi:.4g}", "effort": "10", "velocity": "2"},
                       "mimic": None})
    defect = draw(st.sampled_from(_DEFECTS))
    j = draw(st.sampled_from(joints))
    other = draw(st.sampled_from(joints))
    if defect == "missing-link":
        j[draw(st.sampled_from(["parent", "child"]))] = "nowhere"
    elif defect == "duplicate-link":
        links.append(draw(st.sampled_from(links)))
    elif defect == "duplicate-joint":
        joints.append(dict(j))
    elif defect == "loop":
        joints.append(dict(j, name="back", parent=j["child"], child=j["parent"]))
    elif defect == "two-roots":
        links.append("island")
    elif defect.startswith("mimic"):
        target = {"mimic-missing": "nowhere", "mimic-self": j["name"], "mimic-ok": other["name"]}[defect]
        j["mimic"] = {"joint": target, "multiplier": draw(st.sampled_from(["1", "-1", "nan", "0", "1e308"])),
                      "offset": draw(st.sampled_from(["0", "0.1", "inf"]))}
    elif defect == "nan-limit":
        j["limit"][draw(st.sampled_from(["lower", "upper", "effort", "velocity"]))] = draw(
            st.sampled_from(["nan", "inf", "-inf", "1e999"]))
    elif defect == "swapped-limits":
        j["limit"]["lower"], j["limit"]["upper"] = j["limit"]["upper"], j["limit"]["lower"]
    elif defect == "zero-axis":
        j["axis"] = draw(st.sampled_from(["0 0 0", "1e-300 0 0", "nan 0 1", "1 0"]))
    elif defect == "nan-origin":
        j[draw(st.sampled_from(["xyz", "rpy"]))] = draw(st.sampled_from(["nan 0 0", "0 inf 0", "1e308 1e308 1e308"]))
    elif defect == "unknown-type":
        j["type"] = draw(st.sampled_from(["floating", "planar", "spherical", "screw", ""]))
    elif defect == "no-limit":
        j["limit"] = None
    elif defect == "negative-effort":
        j["limit"]["effort"] = "-1"
    body = "".join(f'<link name="{ln}"/>' for ln in links)
    for jj in joints:
        parts = [f'<joint name="{jj["name"]}" type="{jj["type"]}">', f'<parent link="{jj["parent"]}"/>',
                 f'<child link="{jj["child"]}"/>', f'<origin xyz="{jj["xyz"]}" rpy="{jj["rpy"]}"/>',
                 f'<axis xyz="{jj["axis"]}"/>']
        if jj["limit"] is not None:
            parts.append("<limit " + " ".join(f'{k}="{v}"' for k, v in jj["limit"].items()) + "/>")
        if jj["mimic"] is not None:
            parts.append("<mimic " + " ".join(f'{k}="{v}"' for k, v in jj["mimic"].items()) + "/>")
        body += "".join(parts) + "</joint>"
    text = f'<?xml version="1.0"?>\n<robot name="chain">{body}</robot>'
    if defect == "entity":
        text = text.replace("<robot", '<!DOCTYPE robot [<!ENTITY x "l0">]>\n<robot', 1).replace('"l0"/>', '"&x;"/>', 1)
    elif defect == "doctype":
        text = text.replace("<robot", '<!DOCTYPE robot SYSTEM "file:///etc/passwd">\n<robot', 1)
    elif defect == "truncate":
        text = text[: draw(st.integers(0, len(text)))]
    elif defect == "garbage":
        pos = draw(st.integers(0, len(text)))
        text = text[:pos] + draw(st.text(max_size=10)) + text[pos:]
    return text


@st.composite
def random_trees(draw):
    n_links = draw(st.integers(0, 5))
    links = [f"l{i}" for i in range(n_links)]
    if n_links and draw(st.booleans()):
        links.append(draw(st.sampled_from(links)))  # duplicate link name
    names = links + ["missing", "tcp"]
    joints = []
    n_joints = draw(st.integers(0, 6))
    joint_names = [f"j{i}" for i in range(n_joints)]
    for i, jname in enumerate(joint_names):
        if draw(st.integers(0, 9)) == 0 and joint_names:
            jname = draw(st.sampled_from(joint_names))  # duplicate joint name
        if draw(st.integers(0, 3)):
            parent, child = (links[i % len(links)], links[(i + 1) % len(links)]) if links else ("a", "b")
        else:
            parent, child = draw(st.sampled_from(names)), draw(st.sampled_from(names))
        jtype = draw(_types)
        parts = [f'<joint name="{jname}" type="{jtype}">', f'<parent link="{parent}"/>', f'<child link="{child}"/>']
        if draw(st.booleans()):
            parts.append(f'<origin xyz="{draw(_vec3)}" rpy="{draw(_vec3)}"/>')
        if draw(st.integers(0, 3)):
            parts.append(f'<axis xyz="{draw(_vec3)}"/>')
        if draw(st.integers(0, 4)):
            attrs = {k: draw(_num) for k in ("lower", "upper", "effort", "velocity") if draw(st.integers(0, 5))}
            parts.append("<limit " + " ".join(f'{k}="{v}"' for k, v in attrs.items()) + "/>")
        if draw(st.integers(0, 4)) == 0:
            target = draw(st.sampled_from(joint_names + ["nowhere"]))
            parts.append(f'<mimic joint="{target}" multiplier="{draw(_num)}" offset="{draw(_num)}"/>')
        parts.append("</joint>")
        joints.append("".join(parts))
    body = "".join(f'<link name="{ln}"/>' for ln in links) + "".join(joints)
    text = f'<?xml version="1.0"?>\n<robot name="fuzz">{body}</robot>'
    damage = draw(st.sampled_from(["none", "none", "none", "truncate", "entity", "doctype", "garbage"]))
    if damage == "truncate":
        text = text[: draw(st.integers(0, len(text)))]
    elif damage == "entity":
        text = text.replace("<robot", '<!DOCTYPE robot [<!ENTITY x "l0">]>\n<robot', 1)
    elif damage == "doctype":
        text = text.replace("<robot", '<!DOCTYPE robot SYSTEM "file:///etc/passwd">\n<robot', 1)
    elif damage == "garbage":
        pos = draw(st.integers(0, len(text)))
        text = text[:pos] + draw(st.text(max_size=10)) + text[pos:]
    return text


urdf_texts = st.one_of(chains(), chains(), random_trees())


def _check_robot(robot):
    assert robot.nq >= 1
    assert np.all(robot.lower <= robot.upper), (robot.lower, robot.upper)
    for arr in (robot.lower, robot.upper, robot.velocity_limit, robot.effort_limit):
        assert not np.any(np.isnan(arr))
    q = outcome(robot.random_q, 3, seed=0)[0]
    if q is None:  # unbounded limits refuse random sampling by name
        q = robot.neutral[None]
    for fn in (robot.fk, robot.jacobian, robot.position):
        out, err = outcome(fn, q)
        assert err is None, f"{fn.__name__} of a robot that built: {err}"
        assert np.all(np.isfinite(out)), f"{fn.__name__} gave non-finite values"


TWO_LINKS = ('<?xml version="1.0"?><robot name="r"><link name="a"/><link name="b"/>'
             '<joint name="j" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/>'
             '<limit lower="{lo}" upper="{hi}" effort="1" velocity="{v}"/>{extra}</joint></robot>')
LOL = '<!DOCTYPE r [<!ENTITY a "aaaaaaaaaa">' + "".join(
    f'<!ENTITY a{i} "{("&a%d;" % (i - 1) if i > 1 else "&a;") * 10}">' for i in range(1, 10)) + "]>"


@settings(max_examples=250 * EXPLORE)
@given(text=urdf_texts)
@example(text=TWO_LINKS.format(lo="nan", hi="1", v="1", extra=""))
@example(text=TWO_LINKS.format(lo="1", hi="-1", v="1", extra=""))
@example(text=TWO_LINKS.format(lo="-1", hi="1", v="nan", extra=""))
@example(text=TWO_LINKS.format(lo="-1", hi="1", v="-2", extra=""))
@example(text=TWO_LINKS.format(lo="-inf", hi="inf", v="1", extra=""))
@example(text=TWO_LINKS.format(lo="-1", hi="1", v="1", extra='<mimic joint="nowhere"/>'))
@example(text=TWO_LINKS.format(lo="-1", hi="1", v="1", extra='<mimic joint="j"/>'))
@example(text=TWO_LINKS.format(lo="-1", hi="1", v="1", extra='<origin xyz="nan 0 0"/>'))
@example(text=TWO_LINKS.format(lo="-1", hi="1", v="1", extra="").replace('xyz="0 0 1"', 'xyz="0 0 0"'))
@example(text=TWO_LINKS.format(lo="-1", hi="1", v="1", extra="").replace('xyz="0 0 1"', 'xyz="nan 0 1"'))
@example(text=TWO_LINKS.format(lo="-1", hi="1", v="1", extra="").replace("<robot", LOL + "<robot", 1))
@example(text='<robot name="loop"><link name="a"/><link name="b"/>'
              '<joint name="j1" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/>'
              '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint>'
              '<joint name="j2" type="revolute"><parent link="b"/><child link="a"/><axis xyz="0 0 1"/>'
              '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>')
def test_malformed_urdf(text):
    robot, err = outcome(robots.from_urdf_text, text, seconds=10)
    if err is not None:
        assert isinstance(err, (robots.ModelError, robots.InvalidInput)), err
        return
    _check_robot(robot)


@given(value=st.one_of(st.none(), st.integers(), st.binary(max_size=20), st.lists(st.integers(), max_size=3)))
@settings(max_examples=20)
def test_urdf_text_of_the_wrong_type(value):
    _, err = outcome(robots.from_urdf_text, value)
    assert err is not None


LOOP_THAT_CRASHED_PINOCCHIO = (
    '<robot name="c"><link name="a"/><link name="b"/><link name="c"/>'
    '<joint name="j0" type="fixed"><parent link="a"/><child link="b"/></joint>'
    '<joint name="j1" type="revolute"><parent link="b"/><child link="c"/><axis xyz="0 0 1"/>'
    '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint>'
    '<joint name="back" type="revolute"><parent link="c"/><child link="b"/><axis xyz="0 0 1"/>'
    '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>'
)


def test_a_loop_is_refused_before_pinocchio_sees_it():
    """Pinocchio 4.1's buildModelFromXML dies with SIGSEGV on this loop (found by the fuzz suite).

    Run in a child process, so that a regression shows as a failed test, not a dead test run.
    """
    import subprocess
    import sys

    code = ("import sys\nfrom pinarms import robots\n"
            "try:\n    robots.from_urdf_text(sys.argv[1])\n"
            "except robots.ModelError as exc:\n    print('ModelError:', exc)\n")
    proc = subprocess.run([sys.executable, "-c", code, LOOP_THAT_CRASHED_PINOCCHIO], capture_output=True, text=True,
                          timeout=120)
    assert proc.returncode == 0, f"the process died with {proc.returncode}"
    assert "ModelError: <string>: link 'b' is the child of two joints ('j0' and 'back')" in proc.stdout
