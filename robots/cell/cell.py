"""A cell: several arms at their bases, fixed fixtures, one Pinocchio model and its collision model.

:class:`Cell` is what :func:`~pinarms.robots.cell.load_cell` returns. Frames: every pose
is *world* (the cell URDF's root link, z up) unless a name says otherwise
(``base_to_world``: an arm's base frame → world). The **cell joint vector** ``q`` holds
one coordinate per independent joint of every arm (rad or m), arm after arm in the order
of :attr:`Cell.arms`; :attr:`CellArm.q_slice` is each arm's block.

Collision checks live in :mod:`.collision` (:meth:`Cell.in_collision`,
:meth:`Cell.collisions`, :meth:`Cell.clearance`) and :mod:`.motion`
(:meth:`Cell.check_motion`); the pairs they check and the pairs they skip, with the
reason, in :attr:`Cell.pairs` and :attr:`Cell.allowed` (:mod:`.pairs`); the pairs a check at a
clearance looks at in :meth:`Cell.pairs_for`. The arms and fixtures (:class:`~.components.CellArm`,
:class:`~.components.Fixture`) are in :mod:`.components`, the steps that build them from the
URDF in :mod:`.assembly`, the URDF edit behind :meth:`Cell.with_arm_base` in :mod:`.move_arm`.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any, Callable, Mapping, Sequence, TypeVar

import numpy as np
from numpy.typing import ArrayLike
import pinocchio as pin

from pinarms.errors import CellError, CellTooLarge, InvalidInput
from pinarms.robots.robot import Robot
from pinarms.robots.cell.arm_keys import arm_with_keys
from pinarms.robots.cell.assembly import build_arm, build_geometry, package_dirs, plain_pin_index, probe_pairs, read_fixtures
from pinarms.robots.cell.components import CellArm, Fixture
from pinarms.robots.cell.compose_file import ArmPlacement
from pinarms.robots.cell.description import CellSpec, describe
from pinarms.robots.cell.move_arm import urdf_with_arm_base
from pinarms.robots.cell.batch_fk import BatchedPlacements

__all__ = ["Cell", "GEOMETRY_MEMOS"]

T = TypeVar("T")

#: Keys of :meth:`Cell.memo` that do not depend on which pairs the cell checks (the geometry
#: alone, or caches keyed by the pairs themselves): a cell of fewer pairs (:meth:`Cell.with_pairs`)
#: shares them.
GEOMETRY_MEMOS = frozenset({"sphere cover", "joint levers", "motion cover pairs", "motion checker shared"})


class Cell:
    """Several arms, their fixtures and their collision geometry in one Pinocchio model.

    Build one with :func:`~pinarms.robots.cell.load_cell`.

    Attributes:
        name: the cell's name (the URDF's ``<robot name>``).
        source: where it came from (a file path or ``"builtin:<name>"``).
        urdf_text: the cell's URDF (mesh paths as the file gives them).
        args: the xacro arguments used (empty for a URDF).
        robot: the whole cell as one :class:`Robot` (joint vector = the cell's ``q``,
            poses in the world): batched FK of any frame, limits, random configurations.
        model: its Pinocchio model; ``collision_model``: the coal geometry
            (``pin.GeometryModel``) with the checked pairs as its collision pairs.
        arms: the arms (:class:`CellArm`), in joint-vector order, each with its tool point
            (``tcp_choice``), named ``states``, ``hold`` pose and ``frozen`` joints.
        arm_placements: the :class:`~.compose_file.ArmPlacement` s a composed cell (a
            description file, :func:`~.compose.compose_cell`) was made of; empty otherwise.
        fixtures: the fixtures (:class:`Fixture`), in document order.
        pairs: the checked pairs (:class:`~.pairs.CollisionPair`).
        allowed: the pairs not checked at clearance 0, each with its reason
            (:class:`~.pairs.AllowedPair`); the ``"out of reach"`` and ``"constant"`` ones carry a
            proven ``distance_bound`` and come back in checks at a larger clearance
            (:meth:`pairs_for`).

    Thread-safe: each thread uses its own Pinocchio and coal data (:mod:`.views`).
    """

    def __init__(
        self,
        urdf_text: str,
        *,
        source: str,
        base_dir: str | Path,
        packages: Mapping[str, str | Path] | None = None,
        args: Mapping[str, str] | None = None,
        seed: int = 0,
        placements: Sequence[ArmPlacement] = (),
    ) -> None:
        from pinarms.robots.cell.pairs import classify_pairs

        self.source = source
        self.urdf_text = urdf_text
        self.args = dict(args or {})
        self._seed = seed
        self._packages = dict(packages or {})
        self._base_dir = Path(base_dir)
        try:
            root = ET.fromstring(urdf_text)
        except ET.ParseError as exc:
            raise CellError(f"{source} is not well-formed XML: {exc}") from exc
        from pinarms.robots.cell.limits import MAX_CELL_FILE_BYTES, check_counts, check_extent, check_geometry

        if len(urdf_text) > MAX_CELL_FILE_BYTES:
            raise CellTooLarge(f"{source}: the cell's URDF is {len(urdf_text)} characters; the limit is {MAX_CELL_FILE_BYTES}")
        check_counts(root, 0, 0, source)  # geometries and pairs first: cheap, before anything else
        spec: CellSpec = describe(root, source)
        check_counts(root, len(spec.arms), len(spec.fixtures), source)
        check_geometry(root, spec.fixtures, source)
        self.spec = spec
        self.name = spec.name
        try:
            model = pin.buildModelFromXML(urdf_text, mimic=True)
        except Exception as exc:  # Pinocchio's own message
            raise CellError(f"Pinocchio cannot build a model of {source}: {exc}") from exc
        tcp = next((a.prefix + "tcp" for a in spec.arms if model.existFrame(a.prefix + "tcp")), None)
        tcp = tcp or model.frames[len(model.frames) - 1].name
        dirs = package_dirs(self._base_dir, self._packages)
        self.robot = Robot(model, name=self.name, urdf_text=urdf_text, tcp_frame=tcp, description=f"cell {self.name}",
                           package_dirs=tuple(dirs))
        self.model = model
        arms = tuple(build_arm(model, self.robot, root, arm, source=source, cell_name=self.name, dirs=dirs)
                     for arm in spec.arms)
        #: The arm placements the cell was composed from (tcp, freeze, states, hold), in the
        #: description's order; empty for a xacro or URDF cell.
        self.arm_placements: tuple[ArmPlacement, ...] = tuple(placements)
        by_name = {p.name: p for p in self.arm_placements}
        arms = tuple(arm_with_keys(a, by_name.get(a.name), source) for a in arms)
        self.arms = tuple(sorted(arms, key=lambda a: a.q_slice.start))
        from pinarms.robots.cell.delta_arm import cell_deltas

        #: The deltas among the arms (:class:`~.delta_arm.CellDelta`): bodies from the closed form, pairs in
        #: :attr:`delta_pairs`; empty for a cell of serial arms only.
        self.deltas = cell_deltas(self.arms, self.arm_placements)
        if self.deltas:
            from dataclasses import replace

            tcp_text = ("the platform's tcp (closed form; CellDelta.tcp_to_world): the cell's tree holds the delta's "
                        "motors only")
            names = {d.name for d in self.deltas}
            self.arms = tuple(replace(a, tcp_choice=tcp_text) if a.name in names else a for a in self.arms)
        self._hold = self.robot.neutral.copy()
        for a in self.arms:
            self._hold[a.q_slice] = a.hold
        self._hold.setflags(write=False)
        self._arm_index = {a.name: k for k, a in enumerate(self.arms)}
        self.collision_model = build_geometry(model, root, source=source, base_dir=self._base_dir,
                                              packages=self._packages)
        check_extent(model, self.collision_model, spec.fixtures, source)
        self._placements = BatchedPlacements(model)
        self._pin_index = plain_pin_index(model, self.nq)
        self.fixtures = read_fixtures(model, self.collision_model, spec.fixtures, urdf_text)
        self.pairs, self.allowed = classify_pairs(self, seed=seed)
        self.kinds: tuple[str, ...] = ("self", "arm-arm", "arm-fixture")
        self._finish_geometry()

    def _finish_geometry(self) -> None:
        """Keep only the checked pairs in the collision model, the candidate pairs, and test every checked pair once."""
        from pinarms.robots.cell.pairs import reach_pairs

        reach, bounds = reach_pairs(self, self.allowed)
        self._set_candidates(self.pairs, reach, bounds)
        # the checked pairs once each (an out-of-reach pair coal cannot measure is a named error when used)
        probe_pairs(self.model, self._views, self.pairs, self.source)

    def _set_candidates(self, pairs: tuple, reach: tuple, bounds: np.ndarray) -> None:
        """Checked pairs, then out-of-reach pairs by increasing bound; the collision model keeps the checked ones."""
        from pinarms.robots.cell.views import PairViews

        self.pairs = tuple(pairs)
        self._reach = tuple(reach)
        self._reach_bounds = np.asarray(bounds, dtype=float)
        self._reach_bounds.setflags(write=False)
        self._candidates = self.pairs + self._reach
        gm = self.collision_model
        gm.removeAllCollisionPairs()
        for p in self.pairs:
            gm.addCollisionPair(pin.CollisionPair(p.index_a, p.index_b))
        self._views = PairViews(self.model, gm, self._candidates)
        # a cell of other pairs (with_pairs) keeps only what depends on the geometry alone
        self._memo = {k: v for k, v in getattr(self, "_memo", {}).items() if k in GEOMETRY_MEMOS}

    def memo(self, key: str, build: Callable[[], T]) -> T:
        """The value kept with this cell under ``key``, built by ``build()`` the first time.

        For data derived from the cell's geometry and pairs that its checks reuse (the sphere
        cover, the joint levers, the broad phase's bounds, shared coal data): the cache belongs
        to the cell, and :meth:`with_pairs` starts a fresh one except for the keys of
        :data:`GEOMETRY_MEMOS`, which do not depend on the pairs.
        """
        memo = self._memo
        if key not in memo:
            memo[key] = build()
        return memo[key]

    def cover(self):
        """The sphere cover of every collision geometry (:func:`~pinarms.robots.cell.cover.link_cover`), built once."""
        from pinarms.robots.cell.cover import link_cover

        return link_cover(self)

    # ------------------------------------------------------------------ pairs
    @property
    def delta_pairs(self) -> tuple:
        """The checked pairs with a delta's body (:mod:`.delta_pairs`; empty without deltas): checked with
        :attr:`pairs` by every check, listed after them in its results."""
        from pinarms.robots.cell.delta_pairs import delta_pair_set

        return delta_pair_set(self).pairs if self.deltas else ()

    @property
    def delta_allowed(self) -> tuple:
        """The pairs with a delta's body not checked, each with its reason (``adjacent``, ``rigid``)."""
        from pinarms.robots.cell.delta_pairs import delta_pair_set

        return delta_pair_set(self).allowed if self.deltas else ()

    def pair_count(self, clearance: float, *, strict: bool = False) -> int:
        """How many of :attr:`candidates` a check at ``clearance`` [m] needs (bound ≤ it; ``strict``: bound < it).

        ``candidates[:pair_count(c)]`` is :meth:`pairs_for` ``(c)`` without its checks of ``c``.
        """
        side = "left" if strict else "right"
        return len(self.pairs) + int(np.searchsorted(self._reach_bounds, clearance, side=side))

    @property
    def candidates(self) -> tuple:
        """Every pair a check at some clearance may look at: :attr:`pairs`, then the out-of-reach
        pairs by increasing proven bound (:meth:`pairs_for` ``(inf)``)."""
        return self._candidates

    @property
    def reach_bounds(self) -> np.ndarray:
        """``(len(candidates) - len(pairs),)`` proven distance bounds [m] of the out-of-reach candidates, increasing (read-only)."""
        return self._reach_bounds

    @property
    def pair_views(self):
        """The per-thread Pinocchio and coal data of the candidate pairs (:class:`~pinarms.robots.cell.views.PairViews`)."""
        return self._views

    @property
    def batched_placements(self) -> BatchedPlacements:
        """Batched forward kinematics of every joint (:class:`~pinarms.robots.cell.batch_fk.BatchedPlacements`)."""
        return self._placements

    def pairs_for(self, clearance: float) -> tuple:
        """The pairs a check at ``clearance`` (or margin) [m] must look at.

        The checked pairs (:attr:`pairs`) followed by every ``"out of reach"`` or ``"constant"`` pair whose
        proven distance bound (:attr:`AllowedPair.distance_bound`) is at most ``clearance``,
        in increasing order of that bound: the pairs left out are proven farther than
        ``clearance`` in every configuration. ``pairs_for(0.0)`` is :attr:`pairs`; the
        result is always a prefix of ``pairs_for(inf)``, so a pair index means the same pair
        at every clearance.

        Raises:
            InvalidInput: ``clearance`` not a number ≥ 0 (``inf`` allowed).
        """
        ok = isinstance(clearance, (int, float, np.integer, np.floating)) and not isinstance(clearance, bool)
        value = float(clearance) if ok else float("nan")
        if not value >= 0.0:
            raise InvalidInput(f"clearance must be a number >= 0 [m] (inf allowed), got {clearance!r}")
        return self._candidates[: self.pair_count(value)]

    # --------------------------------------------------------------- joint vector
    @property
    def nq(self) -> int:
        """Length of the cell joint vector."""
        return self.robot.nq

    @property
    def packages(self) -> dict[str, Path]:
        """``{name: folder}`` of the ``package://name/`` files it was loaded with (a copy)."""
        return {str(k): Path(v) for k, v in self._packages.items()}

    @property
    def seed(self) -> int:
        """The seed its pair classification sampled with (a rebuilt cell reuses it)."""
        return self._seed

    @property
    def base_dir(self) -> Path:
        """The folder its relative mesh paths resolve against (its file's folder)."""
        return self._base_dir

    @property
    def joint_names(self) -> tuple[str, ...]:
        """Names of the cell's joints (with the arms' prefixes), in ``q`` order."""
        return self.robot.joint_names

    @property
    def lower(self) -> np.ndarray:
        """Lower joint limits ``(nq,)`` [rad or m]."""
        return self.robot.lower

    @property
    def upper(self) -> np.ndarray:
        """Upper joint limits ``(nq,)`` [rad or m]."""
        return self.robot.upper

    @property
    def neutral(self) -> np.ndarray:
        """Every arm at its neutral configuration."""
        return self.robot.neutral

    @property
    def hold(self) -> np.ndarray:
        """Every arm at its hold pose (:attr:`CellArm.hold`: the description's ``hold``, else neutral).

        What an arm that does not move is set to, everywhere: planning, motion checks,
        cycles, schedules and sessions (their ``hold`` arguments default to it).
        """
        return self._hold.copy()

    def random_q(self, n: int, seed: int | np.random.Generator | None = 0) -> np.ndarray:
        """``n`` cell configurations ``(n, nq)`` drawn uniformly within the joint limits."""
        return self.robot.random_q(n, seed=seed)

    def arm(self, name: str) -> CellArm:
        """The arm called ``name``; :class:`InvalidInput` lists the arms otherwise."""
        if name not in self._arm_index:
            raise InvalidInput(f"cell {self.name!r} has no arm {name!r}; arms: {', '.join(self._arm_index)}")
        return self.arms[self._arm_index[name]]

    def fixture(self, name: str) -> Fixture:
        """The fixture called ``name``; :class:`InvalidInput` lists the fixtures otherwise."""
        for f in self.fixtures:
            if f.name == name:
                return f
        raise InvalidInput(f"cell {self.name!r} has no fixture {name!r}; fixtures: {', '.join(f.name for f in self.fixtures)}")

    def q_from_arms(self, arm_q: Mapping[str, ArrayLike], base: ArrayLike | None = None) -> np.ndarray:
        """A cell joint vector from ``{arm name: q_arm (nq_arm,) or (N, nq_arm)}``.

        Arms not named keep ``base`` (default :attr:`hold`). Batches of the named arms
        must have the same ``N``; the result is ``(nq,)`` or ``(N, nq)``.
        """
        rows = None
        parts = {}
        for name, value in arm_q.items():
            arm = self.arm(name)
            arr, single = arm.robot.check_q(value)
            parts[name] = (arm, arr)
            if not single:
                if rows not in (None, arr.shape[0]):
                    raise InvalidInput(f"arm batches differ in length: {rows} and {arr.shape[0]}")
                rows = arr.shape[0]
        q0 = self.hold if base is None else self.robot.check_q(base)[0][0]
        out = np.tile(q0, (rows or 1, 1))
        for arm, arr in parts.values():
            out[:, arm.q_slice] = arr
        return out[0] if rows is None else out

    def arm_q(self, q: ArrayLike, name: str) -> np.ndarray:
        """The block of arm ``name`` in the cell vector(s) ``q``."""
        arr, single = self.robot.check_q(q)
        out = arr[:, self.arm(name).q_slice]
        return out[0] if single else out

    def world_pose(self, q: ArrayLike, frame: str) -> np.ndarray:
        """Pose(s) ``(4, 4)`` / ``(N, 4, 4)`` of any cell frame (``"left_tcp"``) in the world."""
        return self.robot.fk(q, frame)

    def pin_vector_or_none(self, q: ArrayLike) -> np.ndarray | None:
        """Pinocchio's vector for one finite float ``q (nq,)`` without the general checks, else ``None``."""
        if type(q) is not np.ndarray or q.shape != (self.nq,) or q.dtype != np.float64:
            return None
        if not np.isfinite(q).all():
            return None
        if self._pin_index is None:
            return None
        out = np.zeros(self.model.nq)
        out[self._pin_index] = q
        return out

    # ----------------------------------------------------------- geometry access
    @property
    def geometry_names(self) -> tuple[str, ...]:
        """Names of the collision geometries, in :attr:`collision_model` order."""
        return tuple(g.name for g in self.collision_model.geometryObjects)

    def geometry_placements(self, q: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """World rotations ``(N, G, 3, 3)`` and centres ``(N, G, 3)`` of every geometry frame, batched."""
        arr, _ = self.robot.check_q(q)
        R, p = self._placements.joints(arr)
        gm = self.collision_model
        parents = np.array([g.parentJoint for g in gm.geometryObjects], dtype=int)
        local_R = np.array([g.placement.rotation for g in gm.geometryObjects])
        local_p = np.array([g.placement.translation for g in gm.geometryObjects])
        Rg = R[:, parents] @ local_R
        pg = p[:, parents] + np.einsum("ngij,gj->ngi", R[:, parents], local_p)
        return Rg, pg

    def with_arm_base(self, name: str, base_to_world: ArrayLike, carry: tuple[str, ...] = ()) -> "Cell":
        """A new cell: this one with arm ``name``'s base at ``base_to_world`` ``(4, 4)`` [m] in the world.

        The fixed joint that holds the arm's base link to its parent gets the origin that puts
        the base there; its parent stays where it is. Fixtures named in ``carry`` (a stand, a
        pedestal) keep their pose relative to the arm's base instead of the world. The cell
        is rebuilt from the edited URDF (collision pairs classified again); this cell is
        unchanged. Used by layout searches that move an arm among fixed fixtures.

        Raises:
            InvalidInput: unknown arm or fixture, or not a rigid transform.
            CellError: the arm's base (or a carried fixture) is not held by a fixed joint.
        """
        text = urdf_with_arm_base(self, name, base_to_world, carry)
        return Cell(text, source=f"{self.source} (arm {name!r} moved)",
                    base_dir=self._base_dir, packages=self._packages, args=self.args, seed=self._seed,
                    placements=self.arm_placements)

    def with_pairs(self, kinds: str | tuple[str, ...] | list[str]) -> "Cell":
        """The same cell checking only the pairs of the given kinds.

        Args:
            kinds: one or several of ``"self"``, ``"arm-arm"``, ``"arm-fixture"``; or
                ``"external"`` for ``("arm-arm", "arm-fixture")`` (what a safety distance to
                obstacles and other arms is about: an arm's own links are designed close).

        The result shares the model and the arms; its :attr:`pairs` and its out-of-reach
        pairs (:meth:`pairs_for`), and so every check, are the subset. The pairs left out are
        not added to :attr:`allowed`.
        """
        import copy

        if isinstance(kinds, str):
            kinds = ("arm-arm", "arm-fixture") if kinds == "external" else (kinds,)
        kinds = tuple(kinds)
        unknown = [k for k in kinds if k not in ("self", "arm-arm", "arm-fixture")]
        if unknown or not kinds:
            raise InvalidInput(f"kinds must be among 'self', 'arm-arm', 'arm-fixture' (or 'external'), got {kinds!r}")
        view = copy.copy(self)
        view.collision_model = self.collision_model.copy()
        keep = np.array([p.kind in kinds for p in self._reach], dtype=bool)
        view._set_candidates(tuple(p for p in self.pairs if p.kind in kinds),
                             tuple(p for p, k in zip(self._reach, keep) if k), self._reach_bounds[keep])
        view.kinds = kinds
        return view

    def __repr__(self) -> str:
        return (
            f"Cell({self.name!r}, arms={[a.name for a in self.arms]}, fixtures={len(self.fixtures)}, "
            f"nq={self.nq}, pairs checked={len(self.pairs)}, allowed={len(self.allowed)})"
        )

    # ------------------------------------------------------------------ checks
    def in_collision(self, q: ArrayLike, *, margin: float = 0.0, threads: int = 1) -> bool | np.ndarray:
        """Whether ``q (nq,)`` (→ bool) or each row of ``q (N, nq)`` (→ ``(N,)`` bool) touches.

        A pair touches when its distance is at most ``margin`` [m] (0: contact or
        penetration); the pairs looked at are :meth:`pairs_for` ``(margin)``. Pinocchio's broad phase (dynamic AABB tree) culls pairs whose boxes are
        apart and coal decides the rest, stopping at the first contact; a batch runs in
        Pinocchio's C++ loop (``computeCollisionsInParallel``) on ``threads`` threads.
        """
        from pinarms.robots.cell import collision, delta_checks

        return (delta_checks if self.deltas else collision).in_collision(self, q, margin=margin, threads=threads)

    def collisions(self, q: ArrayLike, *, margin: float = 0.0):
        """Which pairs of :meth:`pairs_for` ``(margin)`` touch (distance ≤ ``margin`` [m]) for ``q (nq,)`` or ``(N, nq)``: a :class:`~.collision.Collisions`."""
        from pinarms.robots.cell import collision, delta_checks

        return (delta_checks if self.deltas else collision).collisions(self, q, margin=margin)

    def clearance(self, q: ArrayLike, *, margin: float = 0.0):
        """Smallest signed distance [m] over every pair not allowed by design, and the pair: a :class:`~.collision.Clearance`.

        The checked pairs and every out-of-reach pair whose bound is below the smallest
        distance found: the true minimum over all pairs but those allowed by design.
        """
        from pinarms.robots.cell import collision, delta_checks

        return (delta_checks if self.deltas else collision).clearance(self, q, margin=margin)

    def check_motion(self, motions: Any, *, margin: float = 0.01, **kwargs):
        """Check the arms' trajectories together, continuously in time: a :class:`~.motion.MotionCheck`.

        See :func:`~pinarms.robots.cell.motion.check_motion` for the arguments and the time-step rule.
        """
        from pinarms.robots.cell import delta_checks, motion

        return (delta_checks if self.deltas else motion).check_motion(self, motions, margin=margin, **kwargs)
