"""Self-collision of an arm from its URDF collision primitives (Pinocchio + coal).

:class:`SelfCollision` loads the ``<collision>`` geometry of a robot's URDF, keeps the
pairs of bodies that can really touch, and tells for a batch of configurations which
ones bring two bodies into contact. The pair filter follows the usual practice of
motion-planning setup tools (e.g. MoveIt's setup assistant), with pinarms' rules:

1. *adjacent* bodies are never checked: bodies on the same joint, or on joints directly
   connected, where ``<mimic>`` joints count as part of the joint they hang from (a
   parallelogram's passive links touch their neighbours by design);
2. *default* collisions: pairs already in contact at the neutral configuration;
3. *always* collisions: pairs in contact in at least 95 % of 200 random configurations
   (seeded), i.e. overlapping primitives of one rigid assembly.

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
from typing import TYPE_CHECKING, Any

import numpy as np
import pinocchio as pin

from .collision_requests import cold_start
from .errors import InvalidInput, ModelError

if TYPE_CHECKING:  # pragma: no cover
    from .robot import Robot

__all__ = ["SelfCollision"]

_ALWAYS_SHARE = 0.95
#: From this many checked pairs on, one configuration is checked through the broad phase
#: (below it, the AABB tree costs more than it culls: AUBO-i3, 50 pairs).
BROAD_PHASE_PAIRS = 64
_ALWAYS_SAMPLES = 200


class SelfCollision:
    """Self-collision checker of ``robot`` built from its URDF ``<collision>`` elements.

    Attributes:
        robot: the robot.
        pairs: ``(k, 2)`` names of the body pairs that are checked.
        n_geometries: number of collision primitives.

    Raises:
        ModelError: Pinocchio cannot read the collision geometry (e.g. a mesh file is missing).
    """

    def __init__(self, robot: "Robot", seed: int = 0) -> None:
        self.robot = robot
        model = robot.model
        try:
            gm = pin.buildGeomFromUrdfString(model, robot.urdf_text, pin.COLLISION, package_dirs=list(robot.package_dirs))
        except Exception as exc:  # Pinocchio raises ValueError/RuntimeError with its own text
            raise ModelError(f"cannot load the collision geometry of '{robot.name}': {exc}") from exc
        self.n_geometries = len(gm.geometryObjects)
        eff = [self._effective_joint(model, g.parentJoint) for g in gm.geometryObjects]
        for a in range(self.n_geometries):
            for b in range(a + 1, self.n_geometries):
                ja, jb = eff[a], eff[b]
                adjacent = ja == jb or self._effective_joint(model, model.parents[ja]) == jb or (
                    self._effective_joint(model, model.parents[jb]) == ja
                )
                if not adjacent:
                    gm.addCollisionPair(pin.CollisionPair(a, b))
        self._gm = gm
        self._gd = cold_start(pin.GeometryData(gm))
        self._data = model.createData()
        # default and always-colliding pairs
        q_probe = np.vstack([robot.neutral[None, :], robot.random_q(_ALWAYS_SAMPLES, seed=seed)])
        hits = self._pair_hits(q_probe)
        drop = hits[0] | (hits[1:].mean(axis=0) >= _ALWAYS_SHARE) if hits.size else np.zeros(0, bool)
        for k in sorted(np.flatnonzero(drop), reverse=True):
            gm.removeCollisionPair(gm.collisionPairs[int(k)])
        self._gd = cold_start(pin.GeometryData(gm))
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

    @staticmethod
    def _effective_joint(model: pin.Model, j: int) -> int:
        """``j``, or the first non-mimic ancestor when ``j`` is a mimic joint."""
        while j > 0 and "Mimic" in model.joints[j].shortname():
            j = model.parents[j]
        return j

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

    def in_collision(self, q: Any, pairs: np.ndarray | None = None) -> bool | np.ndarray:
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
