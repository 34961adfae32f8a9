"""Self-collision of an arm from its URDF collision primitives (Pinocchio + coal).

:class:`SelfCollision` loads the ``<collision>`` geometry of a robot's URDF, keeps the
pairs of bodies that can really touch, and tells for a batch of configurations which
ones bring two bodies into contact. A pair is skipped only for a reason
(:class:`~pinarms.robots.pair_rules.PairReason`, the same as a cell's, :mod:`pinarms.robots.pair_rules`), listed
per pair in :attr:`SelfCollision.allowed`:

1. ``same link``, ``rigid`` (no joint between them) or ``adjacent`` (bodies on joints directly
   connected, where ``<mimic>`` joints count as part of the joint they hang from: a
   parallelogram's passive links touch their neighbours by design), from the structure;
2. ``declared``: named by a ``<disable_collisions link1= link2= reason=/>`` element at the top
   level of the URDF (the SRDF element; Pinocchio ignores it);
3. for a pair in contact in at least :data:`~pinarms.robots.pair_rules.ALWAYS_SHARE` of
   :data:`ALWAYS_SAMPLES` seeded random configurations: ``coaxial`` or ``adjacent`` through a
   shape that turns about its own axis (:mod:`pinarms.robots.coaxial`, proven from the shapes). Such a
   pair with no reason is a :class:`~pinarms.errors.SelfContactError` naming the links, the
   share and the deepest penetration: the sample selects the pairs to explain, it never skips
   one alone. A pair in contact at the neutral configuration is checked like any other.

:meth:`SelfCollision.in_collision` runs coal's broad phase (a dynamic AABB tree culls the
pairs whose boxes are apart) through Pinocchio: one call for one configuration (Pinocchio's
plain loop below 64 pairs, where the tree costs more than it culls), and Pinocchio's C++
batch (``computeCollisionsInParallel``) for a batch, so no Python runs per configuration. Per-pair answers (a ``pairs`` mask) loop in
Python over the configurations: use them on sub-samples of a few thousand.

*Core* bodies are those fixed to the base or carried only by the first ``core_joints``
joints of the chain to the tool (for a floor-standing arm: the base and the turret turning
about J1). Collisions with them are what makes the space near the base unusable; other
self-collisions (wrist against forearm, ...) depend on the tool orientation rather than on
where the tool is, and a planner avoids them by choosing another orientation.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike
import pinocchio as pin

from pinarms.robots.coaxial import still_frames
from pinarms.robots.collision_requests import cold_start, pair_probe
from pinarms.errors import InvalidInput, ModelError, SelfContactError
from pinarms.robots.pair_rules import (ALWAYS_SHARE, AllowedPair, PairReason, by_design, contact_rows, declared_pairs, effective_joint,
                         structural_reason)

if TYPE_CHECKING:  # pragma: no cover
    from pinarms.robots.robot import Robot

__all__ = ["SelfCollision", "ALWAYS_SAMPLES"]

#: From this many checked pairs on, one configuration is checked through the broad phase
#: (below it, the AABB tree costs more than it culls: AUBO-i3, 50 pairs).
BROAD_PHASE_PAIRS = 64
#: Seeded random configurations sampled to find the pairs in contact in (almost) all of them.
ALWAYS_SAMPLES = 200


class SelfCollision:
    """Self-collision checker of ``robot`` built from its URDF ``<collision>`` elements.

    Attributes:
        robot: the robot.
        pairs: ``(k, 2)`` names of the geometry pairs that are checked.
        allowed: the pairs that are not checked, each with its reason (:class:`~pinarms.robots.pair_rules.AllowedPair`).
        n_geometries: number of collision primitives.

    Raises:
        ModelError: Pinocchio cannot read the collision geometry (e.g. a mesh file is missing), or a
            ``<disable_collisions>`` element names a link the URDF does not define.
        SelfContactError: two links are in contact in at least ``ALWAYS_SHARE`` of the samples
            without a reason (module doc).
    """

    def __init__(self, robot: "Robot", seed: int = 0) -> None:
        self.robot = robot
        model = robot.model
        try:
            gm = pin.buildGeomFromUrdfString(model, robot.urdf_text, pin.COLLISION, package_dirs=list(robot.package_dirs))
        except Exception as exc:  # Pinocchio raises ValueError/RuntimeError with its own text
            raise ModelError(f"cannot load the collision geometry of '{robot.name}': {exc}") from exc
        self.n_geometries = len(gm.geometryObjects)
        eff = [effective_joint(model, g.parentJoint) for g in gm.geometryObjects]
        checked, self.allowed = _classify(robot, gm, seed)
        for a, b in checked:
            gm.addCollisionPair(pin.CollisionPair(a, b))
        self._gm = gm
        self._gd = cold_start(pin.GeometryData(gm))
        self._data = model.createData()
        names = [g.name for g in gm.geometryObjects]
        self.pairs = np.array([(names[p.first], names[p.second]) for p in gm.collisionPairs], dtype=object).reshape(-1, 2)
        self._pair_joints = np.array(
            [(eff[p.first], eff[p.second]) for p in gm.collisionPairs], dtype=int
        ).reshape(-1, 2)
        self._bp_gd = cold_start(pin.GeometryData(gm))
        self._bp_data = model.createData()
        self._manager = pin.BroadPhaseManager_DynamicAABBTreeCollisionManager(model, gm, self._bp_gd)
        self._pool = None
        index = np.full(robot.nq, -1, dtype=int)  # cell of each coordinate in Pinocchio's q
        plain = True
        for i in range(1, model.njoints):
            joint = model.joints[i]
            if "Mimic" in joint.shortname():
                continue
            plain &= joint.nq == 1
            index[joint.idx_v] = joint.idx_q
        self._pin_index = index if plain and (index >= 0).all() else None
        self._pin_identity = self._pin_index is not None and model.nq == robot.nq and \
            bool(np.array_equal(self._pin_index, np.arange(robot.nq)))
        self._q_shape = (robot.nq,)
        self._n_pairs = len(gm.collisionPairs)
        self._model = model

    def _single(self, q_pin: np.ndarray) -> bool:
        """One configuration: the broad phase when it pays (many pairs), else Pinocchio's plain loop."""
        if self._n_pairs >= BROAD_PHASE_PAIRS:
            return bool(pin.computeCollisions(self._model, self._bp_data, self._manager, q_pin, True))
        pin.updateGeometryPlacements(self._model, self._bp_data, self._gm, self._bp_gd, q_pin)
        return bool(pin.computeCollisions(self._gm, self._bp_gd, True))

    def core_pair_mask(self, core_joints: int = 1) -> np.ndarray:
        """``(n_pairs,)`` bool: pairs with at least one *core* body (see the module doc).

        Core bodies hang from the base or from the first ``core_joints`` independent joints
        on the path from the base to the tool frame.
        """
        if isinstance(core_joints, bool) or not isinstance(core_joints, (int, np.integer)) or core_joints < 0:
            raise InvalidInput(f"core_joints must be an integer >= 0, got {core_joints!r}")
        model = self.robot.model
        tool_joint = model.frames[self.robot.frame_id("tcp")].parentJoint
        chain, j = [], tool_joint
        while j > 0:
            chain.append(j)
            j = model.parents[j]
        chain = [j for j in reversed(chain) if "Mimic" not in model.joints[j].shortname()]
        core = {0, *chain[: int(core_joints)]}
        return np.isin(self._pair_joints, list(core)).any(axis=1)

    def _pair_hits(self, q: np.ndarray) -> np.ndarray:
        """``(N, k)`` bool: which checked pairs touch in each configuration."""
        qp = np.atleast_2d(self.robot.q_to_pinocchio(q))
        k = len(self._gm.collisionPairs)
        out = np.zeros((qp.shape[0], k), dtype=bool)
        for i in range(qp.shape[0]):
            pin.updateGeometryPlacements(self.robot.model, self._data, self._gm, self._gd, qp[i])
            pin.computeCollisions(self._gm, self._gd, False)
            out[i] = [r.isCollision() for r in self._gd.collisionResults]
        return out

    @property
    def n_pairs(self) -> int:
        """Number of body pairs checked."""
        return len(self._gm.collisionPairs)

    def in_collision(self, q: ArrayLike, pairs: np.ndarray | None = None) -> bool | np.ndarray:
        """Whether ``q (nq,)`` (→ bool) or each row of ``q (N, nq)`` (→ ``(N,)`` bool) self-collides.

        Args:
            pairs: optional ``(n_pairs,)`` bool mask (e.g. :meth:`core_pair_mask`): only
                these pairs count.
        """
        if pairs is None and self._pin_index is not None and type(q) is np.ndarray and q.shape == self._q_shape \
                and q.dtype == np.float64 and math.isfinite(q.sum()):  # one plain vector: the short path
            if not self._n_pairs:
                return False
            if not self._pin_identity:
                qp = np.zeros(self._model.nq)
                qp[self._pin_index] = q
                q = qp
            if self._n_pairs >= BROAD_PHASE_PAIRS:
                return bool(pin.computeCollisions(self._model, self._bp_data, self._manager, q, True))
            pin.updateGeometryPlacements(self._model, self._bp_data, self._gm, self._bp_gd, q)
            return bool(pin.computeCollisions(self._gm, self._bp_gd, True))
        arr, single = self.robot.check_q(q)
        if pairs is not None:
            pairs = np.asarray(pairs, dtype=bool)
            if pairs.shape != (self.n_pairs,):
                raise InvalidInput(f"pairs must be a bool mask of shape ({self.n_pairs},), got {pairs.shape}")
            out = self._pair_hits(arr)[:, pairs].any(axis=1) if self.n_pairs else np.zeros(arr.shape[0], bool)
            return bool(out[0]) if single else out
        qp = np.atleast_2d(self.robot.q_to_pinocchio(arr))
        if not self.n_pairs:
            return False if single else np.zeros(arr.shape[0], dtype=bool)
        if single:
            return self._single(qp[0])
        if self._pool is None:
            self._pool = pin.BroadPhaseManagerPool_DynamicAABBTreeCollisionManager(self.robot.model, self._gm, 1)
            for gd in self._pool.getGeometryDatas():
                cold_start(gd)
        out = pin.computeCollisionsInParallel(1, self._pool, np.asfortranarray(qp.T), True, False)
        return np.asarray(out, dtype=bool).reshape(-1)


def _classify(robot: "Robot", gm: pin.GeometryModel, seed: int) -> tuple[list[tuple[int, int]], tuple[AllowedPair, ...]]:
    """The geometry pairs of ``gm`` to check, and the others with their reason (module doc).

    Raises:
        ModelError: a ``<disable_collisions>`` element naming a link the URDF does not define.
        SelfContactError: pairs in contact in at least ``ALWAYS_SHARE`` of the samples without a reason.
    """
    model, objs = robot.model, list(gm.geometryObjects)
    link = [model.frames[g.parentFrame].name for g in objs]
    owner = [robot.name] * len(objs)
    eff = [effective_joint(model, int(g.parentJoint)) for g in objs]
    declared = _declared(robot)
    allowed: list[AllowedPair] = []

    def allow(a: int, b: int, reason: PairReason, note: str = "") -> None:
        allowed.append(AllowedPair(objs[a].name, objs[b].name, link[a], link[b], reason, index_a=a, index_b=b, note=note))

    plain = [(e,) for e in eff]
    candidates = []
    for a in range(len(objs)):
        for b in range(a + 1, len(objs)):
            found = structural_reason(model, a, b, link, owner, eff, plain, declared)
            if found is not None:
                allow(a, b, found[0], note=found[1])
            else:
                candidates.append((a, b))
    data = model.createData()
    pin.forwardKinematics(model, data, pin.neutral(model))
    still = [tuple(effective_joint(model, j) for j in frames) for frames in still_frames(model, data, objs)]
    q = np.atleast_2d(robot.q_to_pinocchio(robot.random_q(ALWAYS_SAMPLES, seed=seed)))
    share = _contact_share(model, objs, candidates, q)
    checked, through = [], []
    for (a, b), s in zip(candidates, share):
        reason = by_design(model, a, b, link, owner, eff, still) if s >= ALWAYS_SHARE else None
        if reason is not None:
            allow(a, b, reason)
        elif s >= ALWAYS_SHARE:
            through.append((a, b, float(s)))
        else:
            checked.append((a, b))
    if through:
        raise _contact_error(robot, model, objs, link, through, q)
    return checked, tuple(allowed)


def _declared(robot: "Robot") -> dict[frozenset, str]:
    """The URDF's ``<disable_collisions>`` pairs of links, with the reason given."""
    root = ET.fromstring(robot.urdf_text)
    links = [el.get("name") for el in root.findall("link")]
    source = str(robot.urdf_path) if robot.urdf_path is not None else f"the URDF of {robot.name!r}"
    return {frozenset((a, b)): note for a, b, note in declared_pairs(root, links, source, ModelError)}


def _contact_share(model: pin.Model, objs: list, pairs: list[tuple[int, int]], q: np.ndarray) -> np.ndarray:
    """``(len(pairs),)``: the share of the configurations ``q`` (Pinocchio's, ``(N, nq)``) where each pair touches."""
    if not pairs:
        return np.zeros(0)
    probe, gd = pair_probe(objs, pairs, 1e-9)
    data = model.createData()
    hits = np.zeros(len(pairs))
    for qp in q:
        pin.updateGeometryPlacements(model, data, probe, gd, qp)
        pin.computeCollisions(probe, gd, False)
        hits += [r.isCollision() for r in gd.collisionResults]
    return hits / q.shape[0]


def _contact_error(robot: "Robot", model: pin.Model, objs: list, link: list[str],
                   through: list[tuple[int, int, float]], q: np.ndarray) -> SelfContactError:
    """The :class:`SelfContactError` of the geometry pairs ``through`` ``(a, b, share)``, with the deepest
    penetration of each over the configurations ``q``, by pair of links (deepest first)."""
    probe, gd = pair_probe(objs, [(a, b) for a, b, _ in through], 1e-9)
    data = model.createData()
    depth = np.zeros(len(through))
    for qp in q:
        pin.updateGeometryPlacements(model, data, probe, gd, qp)
        pin.computeDistances(probe, gd)
        depth = np.maximum(depth, [-r.min_distance for r in gd.distanceResults])
    rows, shown = contact_rows([(link[a], link[b], share, float(d)) for (a, b, share), d in zip(through, depth)],
                               ALWAYS_SAMPLES)
    source = robot.urdf_path or robot.name
    return SelfContactError(
        f"{source}: links in contact in (almost) every configuration, and no joint between them turns a shape "
        f"about its own axis: {shown}. Fix the collision shapes, or, if the contact is by design, declare "
        'the pair in the URDF: <disable_collisions link1="A" link2="B" reason="..."/>', pairs=rows)
