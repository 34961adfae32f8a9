"""SRDF (MoveIt's semantic robot description) of an arm or a cell, from pinarms' pair classification.

One planning group per arm (a chain from its base link to its tool link), a one-link group
for the tool and an ``end_effector`` on it, named states (``home``: the caller's, else every
joint at 0 where the limits allow it, else none; and any poses given), and the ``disable_collisions`` list. MoveIt's setup assistant samples
random configurations (10 000 by default) to call a pair "never in collision"; here every
pair comes from :mod:`pinarms.robots.cell.pairs`, where "never" is a proof:

=================  ==========  ==========================================================
pinarms reason     SRDF        why the pair is never checked
=================  ==========  ==========================================================
``out of reach``   Never       proven: the reach ball of one misses the other
``same link``      Adjacent    one link (exported as a link and its collision sub-links)
``adjacent``       Adjacent    links joined by one joint
``rigid``          Default     no joint between them: their distance never changes
``always``         Default     in contact in ≥ 95 % of random configurations (by design)
``constant``       Default     a constant gap (coaxial with every joint between them)
=================  ==========  ==========================================================

The pinarms reason is kept in an XML comment before each element.

SRDF disables collisions between *links*, pinarms classifies *geometries*: a link with
several ``<collision>`` elements can have one geometry checked against a body and another
proven out of reach. The exported URDF therefore gives every collision element its own
link (:func:`pinarms.export.cell.one_collision_per_link`), and the SRDF is written against
those links: after ``pin.removeCollisionPairs(model, geom_model, srdf)`` Pinocchio checks
exactly the pairs pinarms checks at contact (:func:`contact_pairs`).
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from typing import Any, Mapping, TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from pinarms.errors import InvalidInput

if TYPE_CHECKING:
    from pinarms.optim.cycle.spec import CycleResult
    from pinarms.robots.cell.cell import Cell

__all__ = ["SRDF_REASON", "contact_pairs", "srdf_text", "home_notes", "cycle_states"]

#: SRDF ``reason`` of each pinarms reason for not checking a pair.
SRDF_REASON = {
    "out of reach": "Never",
    "same link": "Adjacent",
    "adjacent": "Adjacent",
    "rigid": "Default",
    "coaxial": "Default",
    "declared": "User",
    "constant": "Default",
}

_STATE_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_.-]*$")


def contact_pairs(cell: Cell) -> tuple:
    """The pairs a contact check of ``cell`` looks at (``cell.pairs_for(0.0)``, or ``cell.pairs``)."""
    pairs_for = getattr(cell, "pairs_for", None)
    return tuple(pairs_for(0.0)) if callable(pairs_for) else tuple(cell.pairs)


def geometry_links(cell: Cell) -> dict[str, str]:
    """``{geometry name: exported link}``: the k-th collision of link ``L`` is link ``L_collision_k`` (k ≥ 1)."""
    out: dict[str, str] = {}
    count: dict[str, int] = {}
    for g in cell.collision_model.geometryObjects:
        link = cell.model.frames[g.parentFrame].name
        k = count.get(link, 0)
        count[link] = k + 1
        out[g.name] = link if k == 0 else f"{link}_collision_{k}"
    return out


def cycle_states(cycle: CycleResult) -> dict[str, np.ndarray]:
    """Named poses of a planned cycle (:class:`pinarms.optim.CycleResult`): its waypoints' joints, by label."""
    out: dict[str, np.ndarray] = {}
    for label, q in zip(cycle.names, np.asarray(cycle.q_via)):
        out.setdefault(re.sub(r"[^A-Za-z0-9_]+", "_", str(label)).strip("_"), np.asarray(q, dtype=float))
    return out


def _state_joints(cell: Any, arm: Any, q: Any, state: str) -> list[tuple[str, float]]:
    arr = np.asarray(q, dtype=float)
    if arr.shape != (arm.nq,) or not np.all(np.isfinite(arr)):
        raise InvalidInput(f"state {state!r} of arm {arm.name!r}: expected {arm.nq} finite joint values, got {q!r}")
    lo, hi = arm.robot.position_limits  # continuous joints: any angle, written wrapped to (-π, π] as MoveIt bounds them
    arr = np.where(arm.robot.continuous, np.pi - np.mod(np.pi - arr, 2.0 * np.pi), arr)
    bad = np.flatnonzero((arr < lo - 1e-12) | (arr > hi + 1e-12))
    if bad.size:
        j = int(bad[0])
        raise InvalidInput(f"state {state!r} of arm {arm.name!r}: joint {arm.robot.joint_names[j]} = {float(arr[j])!r} "
                           f"is outside its limits [{float(lo[j])!r}, {float(hi[j])!r}]")
    return [(arm.prefix + name, float(v)) for name, v in zip(arm.robot.joint_names, arr)]


def _zero_outside(arm: Any) -> str | None:
    """Why the all-zero pose of ``arm`` is no home (a joint whose limits exclude 0), or ``None``."""
    lo, hi = arm.robot.lower, arm.robot.upper
    bad = np.flatnonzero((lo > 1e-12) | (hi < -1e-12))
    if not bad.size:
        return None
    j = int(bad[0])
    return (f"joint {arm.prefix}{arm.robot.joint_names[j]} = 0 is outside its limits "
            f"[{float(lo[j])!r}, {float(hi[j])!r}]")


def _states(cell: Any, states: Mapping[str, Mapping[str, ArrayLike]] | None) -> tuple[list[tuple[str, str, list]], list[str]]:
    """``([(state name, group, [(joint, value)])], notes)``: the homes, then the given states.

    A home the caller gives (``home``, or ``ARM_home`` in a cell of several arms), or the cell
    description's own (its ``states``, :func:`_description_states`), is written as given; otherwise the all-zero pose, only where it lies inside the joint limits; an arm
    whose limits exclude 0 gets no home, and a note says why.
    """
    several = len(cell.arms) > 1
    given = {**_description_states(cell, several), **dict(states or {})}
    for name in given:
        if not isinstance(name, str) or not _STATE_NAME.match(name):
            raise InvalidInput(f"state name {name!r} must be an identifier (letters, digits, _ . -)")
    why = {arm.name: _zero_outside(arm) for arm in cell.arms}
    out, notes = [], []
    how = ("give your own: states={{{0!r}: ...}} of export_urdf / export_cell, on the command line --state "
           "{0}=V1,V2,... (--state NAME=ARM:V1,V2,... for an arm of a cell); a home of zeros is never forced")
    if several and "home" not in given:
        if all(w is None for w in why.values()):
            out.append(("home", "cell", [j for arm in cell.arms for j in _state_joints(cell, arm, np.zeros(arm.nq),
                                                                                      "home")]))
        else:
            arm = next(a for a in cell.arms if why[a.name] is not None)
            notes.append(f"no home state 'home' of group 'cell': {why[arm.name]}; {how.format('home')}")
    for arm in cell.arms:
        name = f"{arm.name}_home" if several else "home"
        if name in given:
            continue
        if why[arm.name] is None:
            out.append((name, arm.name, _state_joints(cell, arm, np.zeros(arm.nq), name)))
        else:
            notes.append(f"no home state {name!r} of arm {arm.name!r}: {why[arm.name]}; {how.format(name)}")
    for name, per_arm in given.items():
        if not isinstance(per_arm, Mapping) or not per_arm:
            raise InvalidInput(f"state {name!r} must map arm names to joint values, got {per_arm!r}")
        joints = [j for arm_name, q in per_arm.items() for j in _state_joints(cell, cell.arm(arm_name), q, name)]
        group = next(iter(per_arm)) if len(per_arm) == 1 else "cell"
        if group == "cell" and not several:
            group = cell.arms[0].name
        out.append((name, group, joints))
    return out, notes


def _description_states(cell: Cell, several: bool) -> dict[str, dict[str, Any]]:
    """The named states of the cell description's arms (``arm.states``): ``NAME`` in a cell of one arm,
    ``ARM_NAME`` in a cell of several; a ``home`` among them is the arm's home (states given to the export win)."""
    return {(f"{arm.name}_{name}" if several else name): {arm.name: q}
            for arm in cell.arms for name, q in getattr(arm, "states", {}).items()}


def home_notes(cell: Cell, *, states: Mapping[str, Mapping[str, ArrayLike]] | None = None) -> tuple[str, ...]:
    """Why :func:`srdf_text` writes no home for an arm (its limits exclude the all-zero pose and no home is given)."""
    return tuple(_states(cell, states)[1])


def srdf_text(cell: Cell, *, states: Mapping[str, Mapping[str, ArrayLike]] | None = None) -> str:
    """The SRDF of ``cell`` (a :class:`pinarms.robots.cell.Cell`) against its exported URDF's links.

    Args:
        states: extra named states ``{name: {arm name: q_arm (nq_arm,)}}`` [rad or m]
            (a study's pick and place poses, :func:`cycle_states`), besides the named states of the
            cell description (``arm.states``; a state given here wins). A state named ``home``
            (``ARM_home`` in a cell of several arms) is that arm's home; without it the home
            is the all-zero pose where it lies inside the limits, and none otherwise (an XML
            comment and :func:`home_notes` say why).

    Raises:
        InvalidInput: a state with an unknown arm, a wrong length, a value outside the
            joint limits, or a name that is not an identifier.
    """
    links = geometry_links(cell)
    root = ET.Element("robot", {"name": cell.name})
    root.append(ET.Comment(f" Semantic description of {cell.name} for MoveIt and Pinocchio, written by pinarms "
                           "(pinarms.export). Link names are those of the URDF exported beside it. "))
    for arm in cell.arms:
        spec = next(a for a in cell.spec.arms if a.name == arm.name)
        group = ET.SubElement(root, "group", {"name": arm.name})
        ET.SubElement(group, "chain", {"base_link": spec.base_link, "tip_link": arm.prefix + arm.robot.tcp_frame})
        tool = ET.SubElement(root, "group", {"name": f"{arm.name}_tool"})
        ET.SubElement(tool, "link", {"name": arm.prefix + arm.robot.tcp_frame})
    if len(cell.arms) > 1:
        everything = ET.SubElement(root, "group", {"name": "cell"})
        for arm in cell.arms:
            ET.SubElement(everything, "group", {"name": arm.name})
    entries, notes = _states(cell, states)
    for note in notes:
        root.append(ET.Comment(f" pinarms: {note.replace('--', '- -')} "))
    for name, group, joints in entries:
        element = ET.SubElement(root, "group_state", {"name": name, "group": group})
        for joint, value in joints:
            ET.SubElement(element, "joint", {"name": joint, "value": repr(value)})
    for arm in cell.arms:
        ET.SubElement(root, "end_effector", {"name": f"{arm.name}_tool", "parent_link": arm.prefix + arm.robot.tcp_frame,
                                             "group": f"{arm.name}_tool", "parent_group": arm.name})
    checked = {frozenset((p.geometry_a, p.geometry_b)) for p in contact_pairs(cell)}
    for pair in cell.allowed:
        if frozenset((pair.geometry_a, pair.geometry_b)) in checked:
            continue  # a pair pinarms allows but checks at contact (its proven bound is not above 0)
        if pair.reason not in SRDF_REASON:
            raise InvalidInput(f"cell {cell.name!r}: pair reason {pair.reason!r} has no SRDF reason")
        root.append(ET.Comment(f" pinarms: {pair.reason} ({pair.geometry_a} - {pair.geometry_b}) "))
        ET.SubElement(root, "disable_collisions", {"link1": links[pair.geometry_a], "link2": links[pair.geometry_b],
                                                   "reason": SRDF_REASON[pair.reason]})
    ET.indent(root)
    return '<?xml version="1.0" ?>\n' + ET.tostring(root, encoding="unicode") + "\n"
