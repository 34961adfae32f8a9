"""Which pairs of collision geometries a cell checks, and which it never checks (and why).

Like an SRDF's ``disable_collisions`` list, computed once when the cell is loaded. A pair
of geometries is **not checked** (an :class:`AllowedPair`) for one of these reasons:

``same link``
    both belong to one link (its primitives overlap by construction);
``rigid``
    no joint lies between them (two fixtures, a fixture and an arm's base, the parts of one
    link group): their distance never changes, so a contact between them is part of the
    design, not of a motion;
``adjacent``
    their links are joined by one joint (``<mimic>`` joints count as part of the joint they
    follow, so a parallelogram's links are adjacent to their neighbours), or one is the
    arm's own base and the other is carried by the arm's first joint;
``out of reach``
    proven never to touch, by one of two proofs. *Reach*: every point of a moving geometry
    stays within a ball around the origin of its arm's first joint (radius: the joint offsets
    along the chain, the prismatic strokes and the geometry's own bounding sphere, by the
    triangle inequality), and that ball does not reach the other geometry's bounding box (a
    fixture) or ball (another arm). *Axial gap* (:attr:`AllowedPair.note` :data:`AXIAL_GAP`,
    :mod:`pinarms.robots.pair_proofs`): every joint between the two that neither shape turns about its
    own axis of symmetry is revolute about one common line, so each shape's projection onto
    that line never changes, and the two projections (computed from the shapes: box corners,
    cylinder end discs, mesh vertices, ...) are apart (the SCARA's upper arm turning above its
    pedestal). The pair keeps :attr:`AllowedPair.distance_bound`, a proven lower bound
    of its distance in every configuration: the axial gap, or the largest of the ball gap, coal's exact distance
    from the ball to a fixture's own shape, and coal's distance between the solid cylinder
    an arm's revolute first joint sweeps the geometry through and the fixture (or the other
    arm's cylinder), see :mod:`.reach`.
    Such a pair is dropped only from checks whose clearance or margin is below that bound:
    :meth:`Cell.pairs_for` brings it back for any larger one, and :meth:`Cell.clearance`
    computes it whenever its bound is below the smallest distance found;
``declared``
    named in the cell file (``<disable_collisions link1= link2= reason=/>``, or a
    description's ``[[disable_collisions]]``): the user's statement that the two links touch
    by design; :attr:`AllowedPair.note` keeps the reason given;
``coaxial``
    in contact in (almost) every sampled configuration, and proven to be: one of the two turns
    only about its own axis of symmetry relative to the other (a sphere centred on every joint
    axis between them, a cylinder, capsule or cone along it, :mod:`pinarms.robots.coaxial`), so it fills the
    same space at every angle and their distance never changes (the Panda's link-1 capsule
    standing on its table, the SCARA's shoulder hub);
``constant``
    proven apart by one distance in every configuration (:func:`pinarms.robots.pair_proofs.invariant_pair`):
    walking the joints between the two, each is one about which the shape on its moving side
    is symmetric (a sphere centred on its axis, a cylinder, capsule or cone along it), taken from
    either end, so no joint moves one shape relative to the other (the AUBO base and its upper
    arm's housing, 3 mm apart). coal measures the distance once, at the neutral configuration;
    it is the pair's :attr:`AllowedPair.distance_bound` (less 1e-9 m), and like an ``out of reach``
    pair it is checked again at any clearance or margin above it (:data:`BOUNDED`).

**Proven or assumed.** ``same link``, ``rigid``, ``coaxial``, ``out of reach`` and ``constant``
are proven from the structure and the shapes. ``adjacent`` is the usual assumption of SRDF files (two
links joined by a joint are designed to touch at it), taken only from the structure, never
from a sample; for a pair in contact in (almost) every sample, a shape turning about its own
axis counts as part of the link it is fixed to (:mod:`pinarms.robots.coaxial`: the Panda's link-3 sphere at
joint 2 is adjacent to link 1). ``declared`` is the user's word. The sample only selects the
pairs that must be explained (in contact in at least :data:`ALWAYS_SHARE` of them); it never
skips one: a pair found at one distance in every sample but covered by no proof (a quill
sliding beside a drive housing) is checked.

**No pair is dropped because a sample found it in contact.** A pair the rules above leave
(``coaxial`` and ``adjacent`` through a turning shape included) and that is in contact in at least :data:`ALWAYS_SHARE` of the :data:`ALWAYS_SAMPLES` seeded
configurations (a table slab through a SCARA's links, a fixture around the arm, two arms
through each other, two links of one arm whose shapes overlap) is a
:class:`~pinarms.errors.PlacementError` naming each pair of links, the share and the deepest
penetration: move the fixture or the arm, or declare the pair if the contact is by design.
A pair in contact less often is checked like any other (a check reports its contacts).

Unlike the sampled "never in collision" of setup assistants, a pair is only dropped as
"never" when it is proven (``out of reach``, ``constant``): a sample can miss a rare contact, a bound cannot.
Every other pair is a :class:`CollisionPair` and is checked. Pairs allowed by design
(:data:`BY_DESIGN`: every reason but ``out of reach`` and ``constant``) are never checked at any
clearance: they touch by construction, or keep a contact no motion changes.
"""

from __future__ import annotations

from dataclasses import dataclass

import coal
import numpy as np
import pinocchio as pin

from pinarms.robots.coaxial import still_frames
from pinarms.errors import PlacementError
from pinarms.robots.pair_proofs import SAFETY, axial_gap, invariant_pair, neutral_distance
from pinarms.robots.pair_rules import (ALWAYS_SHARE, AllowedPair, PairReason, by_design, contact_rows, effective_joint,
                          structural_reason)
from pinarms.robots.cell.pair_samples import SAMPLES, sample_pairs
from pinarms.robots.cell.reach import root_cylinders, tighter_bound

from pinarms.robots.cell.cell_model import CellModel

__all__ = ["CollisionPair", "AllowedPair", "PairReason", "classify_pairs", "reach_pairs", "ALWAYS_SHARE",
           "ALWAYS_SAMPLES", "BY_DESIGN", "BOUNDED", "AXIAL_GAP"]


#: Reasons of the pairs allowed by design: never checked, at any clearance.
BY_DESIGN = tuple(r for r in PairReason if r not in (PairReason.OUT_OF_REACH, PairReason.CONSTANT))

#: :attr:`AllowedPair.note` of an ``"out of reach"`` pair proven by its gap along the common joint axis.
AXIAL_GAP = "axial gap"

#: Reasons of the pairs skipped only while their proven distance bound is above the clearance asked.
BOUNDED = (PairReason.OUT_OF_REACH, PairReason.CONSTANT)

#: Random configurations sampled for the :data:`ALWAYS_SHARE` rule and for ``constant`` (:mod:`.pair_samples`).
ALWAYS_SAMPLES = SAMPLES


@dataclass(frozen=True)
class CollisionPair:
    """A checked pair of collision geometries.

    Attributes:
        index_a, index_b: geometry indices in :attr:`Cell.collision_model`.
        geometry_a, geometry_b: geometry names (``"<link>_<k>"``).
        body_a, body_b: link names (an arm's body first).
        owner_a, owner_b: arm or fixture names.
        kind: ``"self"`` (one arm), ``"arm-arm"`` or ``"arm-fixture"``.
    """

    index_a: int
    index_b: int
    geometry_a: str
    geometry_b: str
    body_a: str
    body_b: str
    owner_a: str
    owner_b: str
    kind: str

    @property
    def bodies(self) -> tuple[str, str]:
        """``(body_a, body_b)``."""
        return (self.body_a, self.body_b)

    def __str__(self) -> str:
        return f"{self.body_a} – {self.body_b}"


def _root_joint(model: pin.Model, j: int) -> int:
    while j > 0 and model.parents[j] > 0:
        j = model.parents[j]
    return j


def _local_sphere(geometry) -> tuple[np.ndarray, float, np.ndarray]:
    """Centre and radius of the bounding sphere, and half extents of the local AABB."""
    geometry.computeLocalAABB()
    lo, hi = np.asarray(geometry.aabb_local.min_), np.asarray(geometry.aabb_local.max_)
    center, half = (lo + hi) / 2.0, (hi - lo) / 2.0
    return center, float(np.linalg.norm(half)), half


def classify_pairs(cell: "CellModel", seed: int = 0) -> tuple[tuple[CollisionPair, ...], tuple[AllowedPair, ...]]:
    """Split every pair of the cell's collision geometries into checked and allowed pairs.

    The rules by design, the declared pairs and the proof of reach first (:func:`pinarms.robots.pair_rules.by_design`,
    :func:`_reach_gaps`), then the seeded sampling of the pairs left (:func:`_sampled_contacts`);
    the checked pairs come back arm-fixture first, then arm-arm, then self.

    Raises:
        PlacementError: pairs left in contact in at least :data:`ALWAYS_SHARE` of the samples.
    """
    model, gm = cell.model, cell.collision_model
    objs = list(gm.geometryObjects)
    G = len(objs)
    link, owner, is_arm = _owners(cell)
    joint = [int(g.parentJoint) for g in objs]
    eff = [effective_joint(model, j) for j in joint]
    declared = _declared(cell)

    # reach balls of moving geometries, boxes of static ones (world frame, neutral configuration)
    data = model.createData()
    gd = pin.GeometryData(gm)
    pin.updateGeometryPlacements(model, data, gm, gd, pin.neutral(model))
    still = [tuple(effective_joint(model, j) for j in frames) for frames in still_frames(model, data, objs)]
    spheres = [_local_sphere(g.geometry) for g in objs]
    box_R, box_c, box_half = _neutral_boxes(gd, spheres)
    ball_center, ball_radius = _reach_balls(model, data, objs, joint, spheres)
    gaps = _reach_gaps(np.array(joint), ball_center, ball_radius, box_R, box_c, box_half, owner)
    cylinders = root_cylinders(model, data, objs, joint, ball_radius)

    def placement(k: int) -> coal.Transform3s:
        return coal.Transform3s(gd.oMg[k].rotation, gd.oMg[k].translation)
    checked: list[tuple[int, int]] = []
    allowed: list[AllowedPair] = []

    def allow(a: int, b: int, reason: PairReason, bound: float = float("inf"), note: str = "") -> None:
        allowed.append(AllowedPair(objs[a].name, objs[b].name, link[a], link[b], reason, float(bound), a, b, note))

    plain = [(e,) for e in eff]
    for a in range(G):
        for b in range(a + 1, G):
            found = structural_reason(model, a, b, link, owner, eff, plain, declared)
            if found is not None:
                allow(a, b, found[0], note=found[1])
            elif gaps[a, b] > 0.0:  # proven apart: kept as such (it comes back at a larger clearance)
                allow(a, b, PairReason.OUT_OF_REACH, tighter_bound(gaps[a, b], a, b, objs, joint, ball_center,
                                                                   ball_radius, placement, cylinders))
            else:
                proven = _proven_gap(model, data, objs, gd, a, b)
                if proven is None:
                    checked.append((a, b))
                else:
                    allow(a, b, *proven)

    from pinarms.robots.cell.limits import check_pairs

    check_pairs(len(checked), cell.source)  # before the sampling below, whose cost grows with it
    keep, through = [], []
    for (a, b), (share, depth) in zip(checked, _sampled_contacts(cell, objs, data, checked, seed)):
        if share >= ALWAYS_SHARE:  # in contact whatever the joints do: explained by the shapes, or an error
            reason = by_design(model, a, b, link, owner, eff, still)
            if reason is None:
                through.append((a, b, share, depth))
            else:
                allow(a, b, reason)
        else:
            keep.append((a, b))
    if through:
        raise _placement_error(cell, objs, link, owner, is_arm, through)

    pairs = [_pair(a, b, objs, link, owner, is_arm) for a, b in keep]
    order = {"arm-fixture": 0, "arm-arm": 1, "self": 2}
    pairs.sort(key=lambda p: (order[p.kind], min(p.index_a, p.index_b), max(p.index_a, p.index_b)))
    return tuple(pairs), tuple(allowed)


def _proven_gap(model: pin.Model, data: pin.Data, objs: list, gd: pin.GeometryData, a: int,
               b: int) -> tuple[PairReason, float, str] | None:
    """``("constant", distance)`` for a pair proven apart at one distance in every configuration, ``("out of reach",
    gap)`` for one proven apart along the common axis of every joint between them (:mod:`pinarms.robots.pair_proofs`; the
    neutral ``data`` and ``gd``), else ``None`` (the pair is checked). A bound is kept only when it is > 0."""
    if invariant_pair(model, data, objs[a], objs[b]):
        d = neutral_distance(objs[a].geometry, gd.oMg[a], objs[b].geometry, gd.oMg[b]) - SAFETY
        return (PairReason.CONSTANT, d, "") if d > 0.0 else None  # in contact: the sampled rule below explains it
    gap = axial_gap(model, data, objs[a], gd.oMg[a], objs[b], gd.oMg[b])
    return (PairReason.OUT_OF_REACH, gap, AXIAL_GAP) if gap > 0.0 else None


def _declared(cell: "CellModel") -> dict[frozenset, str]:
    """The pairs of links the cell file declares in contact by design (names checked by :func:`.description.describe`),
    with the reason given."""
    return {frozenset((a, b)): note for a, b, note in cell.spec.declared}


def _placement_error(cell: "CellModel", objs: list, link: list[str], owner: list[str], is_arm: list[bool],
                     through: list[tuple[int, int, float, float]]) -> PlacementError:
    """The :class:`PlacementError` of the geometry pairs ``through`` ``(a, b, share, depth)``, by pair of links."""
    rows, shown = contact_rows([(*_pair(a, b, objs, link, owner, is_arm).bodies, share, depth)
                                for a, b, share, depth in through], ALWAYS_SAMPLES)
    return PlacementError(
        f"{cell.source}: placed through a moving link, in collision in (almost) every configuration: {shown}. "
        "Move the fixture (or the arm's base) clear of the arm, or, if the contact is by design, declare the pair "
        'in the cell file: <disable_collisions link1="A" link2="B" reason="..."/> (a description: '
        "[[disable_collisions]] with link1, link2, reason)", pairs=rows)


def _neutral_boxes(gd: pin.GeometryData, spheres: list) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Oriented boxes of every geometry at the neutral configuration: rotations ``(G, 3, 3)``, centres and half extents ``(G, 3)``."""
    G = len(spheres)
    box_R = np.zeros((G, 3, 3))
    box_c = np.zeros((G, 3))
    box_half = np.zeros((G, 3))
    for k, (center, _, half) in enumerate(spheres):
        M = gd.oMg[k]
        box_R[k], box_c[k], box_half[k] = M.rotation, M.rotation @ center + M.translation, half
    return box_R, box_c, box_half


def _reach_balls(model: pin.Model, data: pin.Data, objs: list, joint: list[int],
                 spheres: list) -> tuple[np.ndarray, np.ndarray]:
    """Centres ``(G, 3)`` and radii ``(G,)`` of the balls every moving geometry stays in (0 for static ones).

    The centre is the origin of the geometry's root joint (the arm's first joint, at the
    neutral ``data``); the radius adds the joint offsets along the chain, the prismatic
    strokes and the geometry's own bounding sphere (triangle inequality).
    """
    G = len(objs)
    lower, upper = model.lowerPositionLimit, model.upperPositionLimit
    ball_center = np.zeros((G, 3))
    ball_radius = np.zeros(G)
    for k, g in enumerate(objs):
        if joint[k] == 0:
            continue
        center, radius, _ = spheres[k]
        r = _root_joint(model, joint[k])
        ball_center[k] = data.oMi[r].translation
        total, j = float(np.linalg.norm(g.placement.act(center))) + radius, joint[k]
        while j > 0:
            jm = model.joints[j]
            if j != r:
                total += float(np.linalg.norm(model.jointPlacements[j].translation))
            if _is_prismatic(model, data, j):
                iq = jm.idx_q
                scale = abs(jm.extract().scaling) if "Mimic" in jm.shortname() else 1.0
                stroke = max(abs(lower[iq]), abs(upper[iq])) if np.isfinite(lower[iq]) else np.inf
                total += scale * stroke
            j = model.parents[j]
        ball_radius[k] = total
    return ball_center, ball_radius


def _sampled_contacts(cell: "CellModel", objs: list, data: pin.Data, checked: list[tuple[int, int]],
                      seed: int) -> list[tuple[float, float]]:
    """Per pair, from :data:`ALWAYS_SAMPLES` seeded random configurations (:mod:`.pair_samples`, cached by
    content): the share of them in contact and the deepest penetration found [m] (0 if none). Only for the
    :data:`ALWAYS_SHARE` rule: a sample never skips a pair."""
    hits, depth = sample_pairs(cell, objs, data, checked, seed)
    return [(float(h) / ALWAYS_SAMPLES, float(depth[k])) for k, h in enumerate(hits)]


def _owners(cell: "CellModel") -> tuple[list[str], list[str], list[bool]]:
    model, objs = cell.model, list(cell.collision_model.geometryObjects)
    link = [model.frames[g.parentFrame].name for g in objs]
    owner_of_link: dict[str, str] = {}
    for arm in cell.spec.arms:
        for name in arm.links:
            owner_of_link[name] = arm.name
    for name in cell.spec.fixtures:
        owner_of_link[name] = name
    owner = [owner_of_link.get(name, name) for name in link]
    arms = {a.name for a in cell.spec.arms}
    return link, owner, [name in arms for name in owner]


def _pair(a: int, b: int, objs: list, link: list[str], owner: list[str], is_arm: list[bool]) -> CollisionPair:
    if not is_arm[a] and is_arm[b]:
        a, b = b, a
    if is_arm[a] and is_arm[b]:
        kind = "self" if owner[a] == owner[b] else "arm-arm"
    else:
        kind = "arm-fixture"
    return CollisionPair(a, b, objs[a].name, objs[b].name, link[a], link[b], owner[a], owner[b], kind)


def reach_pairs(cell: "CellModel", allowed: tuple[AllowedPair, ...]) -> tuple[tuple[CollisionPair, ...], np.ndarray]:
    """The ``"out of reach"`` and ``"constant"`` pairs (:data:`BOUNDED`) as :class:`CollisionPair` s, in increasing order of
    their bound, and the bounds [m]."""
    objs = list(cell.collision_model.geometryObjects)
    link, owner, is_arm = _owners(cell)
    reach = sorted((p for p in allowed if p.reason in BOUNDED), key=lambda p: (p.distance_bound, p.index_a, p.index_b))
    pairs = tuple(_pair(p.index_a, p.index_b, objs, link, owner, is_arm) for p in reach)
    return pairs, np.array([p.distance_bound for p in reach], dtype=float)


def _is_prismatic(model: pin.Model, data: pin.Data, j: int) -> bool:
    motion = np.array(data.joints[j].S).reshape(6, -1)[:, 0]
    return bool(np.linalg.norm(motion[3:]) < 1e-12)


def _reach_gaps(joint: np.ndarray, ball_center, ball_radius, box_R, box_c, box_half, owner: list[str]) -> np.ndarray:
    """``(G, G)`` proven lower bounds of every pair's distance over every configuration (≤ 0 or -inf: no proof).

    Two moving geometries of different owners: the gap between their reach balls; a moving
    geometry and a static one: the gap from the reach ball to the static one's oriented box.
    """
    G = joint.size
    gaps = np.full((G, G), -np.inf)
    moving = np.flatnonzero(joint > 0)
    static = np.flatnonzero(joint == 0)
    if moving.size:
        owners = np.unique(np.array(owner, dtype=object)[moving], return_inverse=True)[1]
        c, r = ball_center[moving], ball_radius[moving]
        mm = np.linalg.norm(c[:, None] - c[None], axis=-1) - r[:, None] - r[None]
        mm[owners[:, None] == owners[None]] = -np.inf  # one arm's own links: never "out of reach"
        gaps[np.ix_(moving, moving)] = mm
    if moving.size and static.size:
        local = np.einsum("sji,msj->msi", box_R[static], ball_center[moving][:, None] - box_c[static][None])
        outside = np.linalg.norm(np.maximum(np.abs(local) - box_half[static][None], 0.0), axis=-1)
        ms = outside - ball_radius[moving][:, None]
        gaps[np.ix_(moving, static)] = ms
        gaps[np.ix_(static, moving)] = ms.T
    return gaps
