"""Checks of a URDF before and after Pinocchio parses it (the registry runs them on every URDF it loads).

- :func:`refuse_dtd`: no DOCTYPE and no entity declarations (URDF has none; Pinocchio's
  parser would not expand them);
- :func:`check_tree`: the links and joints form one tree (Pinocchio crashes the process on a
  loop);
- :func:`check_limits`: the model's position limits have lower ≤ upper within
  ±:data:`MAX_POSITION_LIMIT`, its speed and effort limits are magnitudes up to
  :data:`MAX_SPEED_LIMIT` and :data:`MAX_EFFORT_LIMIT` (or "none given"), and every link's
  mass is finite and ≥ 0 with a finite inertia;
- :func:`check_inertials`: every ``<mass value>`` is a finite number ≥ 0 (urdfdom drops an
  inertial whose mass is ``nan`` or ``inf`` with a message on stderr and loads the link massless).

Each raises :class:`~pinarms.errors.ModelError` naming the file (``source``) and the problem.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
import xml.parsers.expat

import numpy as np
import pinocchio as pin

from pinarms.errors import ModelError

__all__ = ["refuse_dtd", "check_tree", "check_limits", "check_inertials", "MAX_POSITION_LIMIT", "MAX_SPEED_LIMIT", "MAX_EFFORT_LIMIT"]

#: Largest magnitude of a position limit [rad or m]. A URDF writes ±1e9 for "practically none"
#: (1.6e8 turns; a double still resolves 1.2e-7 there); beyond, spans overflow (1e308 − (−1e308)
#: is inf) and samples, equivalents and distances in joint space stop being numbers.
MAX_POSITION_LIMIT = 1e9
#: Largest velocity limit [rad/s or m/s] and effort limit [N·m or N] a URDF may give (as large
#: as "none"); Pinocchio's +inf for a joint without ``<limit>`` stays "none given".
MAX_SPEED_LIMIT = 1e9
MAX_EFFORT_LIMIT = 1e9


def check_tree(root: ET.Element, source: str) -> None:
    """ModelError unless the links and joints form one tree (Pinocchio 4.1 crashes the process on a loop).

    Names unique, every joint between two defined links, every link the child of at most
    one joint, one root, every link reachable from it.
    """
    links = [ln.get("name") for ln in root.findall("link")]
    seen: set = set()
    for name in links:
        if not name:
            raise ModelError(f"{source}: a <link> has no name")
        if name in seen:
            raise ModelError(f"{source}: link {name!r} is defined twice")
        seen.add(name)
    parent_of: dict[str, str] = {}
    children: dict[str, list[str]] = {name: [] for name in links}
    joint_names: set = set()
    for j in root.findall("joint"):
        jname = j.get("name")
        if not jname:
            raise ModelError(f"{source}: a <joint> has no name")
        if jname in joint_names:
            raise ModelError(f"{source}: joint {jname!r} is defined twice")
        joint_names.add(jname)
        ends = []
        for tag in ("parent", "child"):
            el = j.find(tag)
            link = None if el is None else el.get("link")
            if link is None:
                raise ModelError(f"{source}: joint {jname!r} has no <{tag} link=...>")
            if link not in children:
                raise ModelError(f"{source}: joint {jname!r} names {tag} link {link!r}, which is not defined")
            ends.append(link)
        parent, child = ends
        if child in parent_of:
            raise ModelError(f"{source}: link {child!r} is the child of two joints ({parent_of[child]!r} and "
                             f"{jname!r}); a URDF is a tree (close loops with constraints, not joints)")
        parent_of[child] = jname
        children[parent].append(child)
    roots = [name for name in links if name not in parent_of]
    if len(roots) != 1:
        what = "no root link (the joints form a loop)" if not roots else f"several root links {roots}"
        raise ModelError(f"{source}: {what}; a URDF is one tree")
    reached, stack = set(), [roots[0]]
    while stack:
        link = stack.pop()
        if link in reached:
            continue
        reached.add(link)
        stack.extend(children[link])
    if len(reached) != len(links):
        lost = [name for name in links if name not in reached]
        raise ModelError(f"{source}: links {lost} are not connected to the root {roots[0]!r} (a loop); a URDF is one tree")


def refuse_dtd(text: str, source: str) -> None:
    """ModelError when the XML declares a DOCTYPE or entities (expat reads the prolog only)."""

    def refuse(*_: object) -> None:
        raise ModelError(
            f"{source} declares a DOCTYPE or XML entities; URDF uses neither and Pinocchio's parser does not expand "
            f"them (entity expansion is refused): expand them first, e.g. with xacro"
        )

    parser = xml.parsers.expat.ParserCreate()
    parser.StartDoctypeDeclHandler = refuse
    parser.EntityDeclHandler = refuse
    parser.StartElementHandler = _stop_at_root
    try:
        parser.Parse(text, True)
    except (xml.parsers.expat.ExpatError, _RootReached):
        pass  # malformed XML is reported by the parse that follows; the root element ends the prolog


class _RootReached(Exception):
    """Raised by the prolog scan at the first element."""


def _stop_at_root(*_: object) -> None:
    raise _RootReached


def check_limits(model: pin.Model, source: str) -> None:
    """ModelError for a limit or a link mass that makes no sense (module doc), naming the joint or link."""
    for i in range(1, model.njoints):
        j = model.joints[i]
        if j.nq == 0 or "Mimic" in j.shortname():
            continue
        name = model.names[i]
        lo = model.lowerPositionLimit[j.idx_q: j.idx_q + j.nq]
        hi = model.upperPositionLimit[j.idx_q: j.idx_q + j.nq]
        if np.any(lo > hi):
            raise ModelError(f"{source}: joint {name!r} has lower limit {lo.tolist()} above its upper limit "
                             f"{hi.tolist()}; swap them")
        bounded = j.nq == j.nv == 1 and "RUB" not in j.shortname()  # revolute or prismatic with a range
        if bounded and not (np.all(np.abs(lo) <= MAX_POSITION_LIMIT) and np.all(np.abs(hi) <= MAX_POSITION_LIMIT)):
            raise ModelError(f"{source}: joint {name!r} has a position limit beyond ±{MAX_POSITION_LIMIT:g} "
                             f"([{lo.tolist()}, {hi.tolist()}]); give its real range (a continuous joint has none)")
        v = model.velocityLimit[j.idx_v: j.idx_v + j.nv]
        e = model.effortLimit[j.idx_v: j.idx_v + j.nv]
        if np.any(v < 0) or np.any(e < 0):
            raise ModelError(f"{source}: joint {name!r} has a negative velocity or effort limit "
                             f"({v.tolist()}, {e.tolist()}); limits are magnitudes")
        for key, values, cap in (("velocity", v, MAX_SPEED_LIMIT), ("effort", e, MAX_EFFORT_LIMIT)):
            if np.any((values > cap) & np.isfinite(values)) or np.any(np.isnan(values)):
                raise ModelError(f"{source}: joint {name!r} has a {key} limit {values.tolist()} beyond {cap:g} "
                                 "(SI units); give the arm's real limit")
    _check_masses(model, source)


def _check_masses(model: pin.Model, source: str) -> None:
    for i in range(1, model.njoints):
        inertia = model.inertias[i]
        mass = float(inertia.mass)
        if not (np.isfinite(mass) and mass >= 0.0) or not np.all(np.isfinite(inertia.inertia)) \
                or not np.all(np.isfinite(inertia.lever)):
            links = [f.name for f in model.frames if f.type == pin.FrameType.BODY and f.parentJoint == i]
            where = f"link {links[0]!r}" if len(links) == 1 else f"the links of joint {model.names[i]!r} ({links})"
            raise ModelError(f"{source}: {where} has mass {mass!r} kg or a non-finite inertia; an <inertial> needs "
                             "a finite mass >= 0 and a finite inertia")


def check_inertials(root: ET.Element, source: str) -> None:
    """ModelError unless every link's ``<inertial><mass value>`` is a finite number >= 0 [kg]."""
    for link in root.findall("link"):
        for mass in link.findall("inertial/mass"):
            text = mass.get("value", "")
            try:
                value = float(text)
            except ValueError:
                value = float("nan")
            if not (np.isfinite(value) and value >= 0.0):
                raise ModelError(f"{source}: link {link.get('name')!r} has mass {text!r} kg; an <inertial> needs a "
                                 "finite mass >= 0")
