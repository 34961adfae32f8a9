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
clearance looks at in :meth:`Cell.pairs_for`.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Mapping

import coal
import numpy as np
import pinocchio as pin

from ..collision_requests import cold_start
from ..errors import CellError, CellTooLarge, CollisionGeometryError, InvalidInput
from ..robot import Robot
from ..xacro_expand import mesh_path
from .description import ArmSpec, CellSpec, arm_urdf, describe
from .placements import BatchedPlacements

__all__ = ["Cell", "CellArm", "Fixture", "Shape"]


@dataclass(frozen=True, eq=False)
class CellArm:
    """One arm of a cell.

    Attributes:
        name: the arm's name in the cell (``"left"``).
        robot: the arm alone (link and joint names without the prefix, its base link as
            root): IK, limits and trajectories work on it as on any :class:`Robot`.
        base_to_world: ``(4, 4)`` pose of the arm's base frame in the world [m].
        q_slice: the arm's coordinates in the cell joint vector.
        prefix: what the arm's names carry in the cell (``"left_"``).
        model: the built-in arm it is (``"scara_mushroom"``), told from its kinematics, never
            from names (:func:`~pinarms.robots.registry.match_builtin`), or ``None``.
    """

    name: str
    robot: Robot
    base_to_world: np.ndarray
    q_slice: slice
    prefix: str
    model: str | None

    @property
    def nq(self) -> int:
        """Number of the arm's joint coordinates."""
        return self.robot.nq

    @property
    def ik_family(self) -> str | None:
        """The closed-form IK family recognised from the arm's geometry (``robot.ik_family``), or ``None``."""
        return self.robot.ik_family

    def to_world(self, pose: Any) -> np.ndarray:
        """A pose ``(4, 4)`` / ``(N, 4, 4)`` or a point ``(3,)`` / ``(N, 3)`` from the arm's base frame to the world."""
        arr = np.asarray(pose, dtype=float)
        if arr.shape[-2:] == (4, 4):
            return self.base_to_world @ arr
        if arr.shape[-1:] == (3,):
            return arr @ self.base_to_world[:3, :3].T + self.base_to_world[:3, 3]
        raise InvalidInput(f"to_world takes poses (4, 4) or points (3,), got shape {arr.shape}")

    def to_base(self, pose: Any) -> np.ndarray:
        """Inverse of :meth:`to_world`: world pose(s) or point(s) in the arm's base frame."""
        inv = np.linalg.inv(self.base_to_world)
        arr = np.asarray(pose, dtype=float)
        if arr.shape[-2:] == (4, 4):
            return inv @ arr
        if arr.shape[-1:] == (3,):
            return arr @ inv[:3, :3].T + inv[:3, 3]
        raise InvalidInput(f"to_base takes poses (4, 4) or points (3,), got shape {arr.shape}")

    def tcp_to_world(self, q_arm: Any) -> np.ndarray:
        """Pose(s) of the arm's tcp in the world for the arm's own ``q (nq,)`` / ``(N, nq)``."""
        return self.base_to_world @ self.robot.fk(q_arm)


@dataclass(frozen=True, eq=False)
class Shape:
    """One collision primitive of a fixture.

    Attributes:
        kind: ``"box"``, ``"cylinder"``, ``"sphere"``, ``"capsule"`` or ``"mesh"``.
        size: box ``(sx, sy, sz)``, cylinder and capsule ``(radius, length)`` along local
            z, sphere ``(radius,)``, mesh its scale ``(x, y, z)`` [m or 1].
        shape_to_world: ``(4, 4)`` pose of the primitive's centre (mesh: its origin).
        mesh: the mesh file as the URDF names it (``None`` for primitives).
        geometry: its name in :attr:`Cell.collision_model`.
    """

    kind: str
    size: tuple[float, ...]
    shape_to_world: np.ndarray
    mesh: str | None
    geometry: str


@dataclass(frozen=True, eq=False)
class Fixture:
    """A fixed body of the cell (a link without joints to the arms): name and shapes."""

    name: str
    shapes: tuple[Shape, ...]


def _shape_of(geometry: Any) -> tuple[str, tuple[float, ...]]:
    if isinstance(geometry, coal.Box):
        return "box", tuple(float(v) for v in 2.0 * np.asarray(geometry.halfSide))
    if isinstance(geometry, coal.Cylinder):
        return "cylinder", (float(geometry.radius), float(2.0 * geometry.halfLength))
    if isinstance(geometry, coal.Capsule):
        return "capsule", (float(geometry.radius), float(2.0 * geometry.halfLength))
    if isinstance(geometry, coal.Sphere):
        return "sphere", (float(geometry.radius),)
    if isinstance(geometry, (coal.BVHModelBase, coal.ConvexBase)):
        return "mesh", ()
    return type(geometry).__name__, ()


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
        arms: the arms (:class:`CellArm`), in joint-vector order.
        fixtures: the fixtures (:class:`Fixture`), in document order.
        pairs: the checked pairs (:class:`~.pairs.CollisionPair`).
        allowed: the pairs not checked at clearance 0, each with its reason
            (:class:`~.pairs.AllowedPair`); the ``"out of reach"`` ones carry a proven
            ``distance_bound`` and come back in checks at a larger clearance
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
    ) -> None:
        from .pairs import classify_pairs

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
        from .limits import MAX_CELL_FILE_BYTES, check_counts, check_geometry

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
        self.robot = Robot(model, name=self.name, urdf_text=urdf_text, tcp_frame=tcp, description=f"cell {self.name}",
                           package_dirs=tuple(self._package_dirs()))
        self.model = model
        self.arms = tuple(self._build_arm(root, arm) for arm in spec.arms)
        self.arms = tuple(sorted(self.arms, key=lambda a: a.q_slice.start))
        self._arm_index = {a.name: k for k, a in enumerate(self.arms)}
        self.collision_model = self._build_geometry(root)
        self._placements = BatchedPlacements(model)
        self._pin_index = self._plain_pin_index()
        self.fixtures = self._fixtures()
        self.pairs, self.allowed = classify_pairs(self, seed=seed)
        self.kinds: tuple[str, ...] = ("self", "arm-arm", "arm-fixture")
        self._finish_geometry()

    # ------------------------------------------------------------------ building
    def _build_arm(self, root: ET.Element, spec: ArmSpec) -> CellArm:
        from ..registry import from_urdf_text, match_builtin

        text = arm_urdf(root, spec)
        # closed-form IK by geometry (robot.ik_family); the built-in it is by kinematics, not names
        robot = from_urdf_text(text, tcp=None, name=spec.name, source=f"arm {spec.name!r} of {self.source}",
                               package_dirs=tuple(self._package_dirs()))
        model_name = match_builtin(robot)
        robot.description = f"{model_name or 'arm'} {spec.name!r} of cell {self.name}"
        cell_names = self.robot.joint_names
        idx = [cell_names.index(spec.prefix + j) if spec.prefix + j in cell_names else -1 for j in robot.joint_names]
        if -1 in idx or idx != list(range(idx[0], idx[0] + len(idx))):
            raise CellError(
                f"{self.source}: the joints of arm {spec.name!r} are not one block of the cell's joint vector "
                f"(cell joints {list(cell_names)}); an arm must be one subtree below its base"
            )
        base_id = self.model.getFrameId(spec.base_link)
        data = self.model.createData()
        pin.framesForwardKinematics(self.model, data, pin.neutral(self.model))
        base_to_world = data.oMf[base_id].homogeneous.copy()
        return CellArm(
            name=spec.name,
            robot=robot,
            base_to_world=base_to_world,
            q_slice=slice(idx[0], idx[0] + len(idx)),
            prefix=spec.prefix,
            model=model_name,
        )

    def _plain_pin_index(self) -> np.ndarray | None:
        """Where each cell coordinate sits in Pinocchio's q, when every joint stores one value (else ``None``)."""
        index = np.full(self.nq, -1, dtype=int)
        for i in range(1, self.model.njoints):
            joint = self.model.joints[i]
            if "Mimic" in joint.shortname():
                continue
            if joint.nq != 1:
                return None  # a continuous joint (cos, sin): use Robot.q_to_pinocchio
            index[joint.idx_v] = joint.idx_q
        return None if (index < 0).any() else index

    def _package_dirs(self) -> list[str]:
        from ..xacro_expand import BUILTIN_PACKAGE

        return [str(self._base_dir.resolve()), str(BUILTIN_PACKAGE[1]), *(str(Path(v)) for v in self._packages.values())]

    def _resolved_urdf(self, root: ET.Element) -> str:
        """The URDF with every mesh filename replaced by its checked absolute path (for Pinocchio)."""
        resolved = ET.fromstring(ET.tostring(root))
        from .limits import check_mesh_size

        for mesh in resolved.iter("mesh"):
            path = mesh_path(mesh.get("filename", ""), self._base_dir, self._packages)
            check_mesh_size(path)  # by stat: a huge mesh is refused unread
            mesh.set("filename", str(path))
        return ET.tostring(resolved, encoding="unicode")

    def _build_geometry(self, root: ET.Element) -> pin.GeometryModel:
        text = self._resolved_urdf(root)
        try:
            gm = pin.buildGeomFromUrdfString(self.model, text, pin.COLLISION, package_dirs=self._package_dirs())
        except Exception as exc:
            raise CollisionGeometryError(f"cannot load the collision geometry of {self.source}: {exc}") from exc
        expected: dict[str, int] = {}
        for link in root.findall("link"):
            n = len(link.findall("collision"))
            if n:
                expected[link.get("name")] = n
        got: dict[str, int] = {}
        for g in gm.geometryObjects:
            link = self.model.frames[g.parentFrame].name
            got[link] = got.get(link, 0) + 1
        missing = sorted(link for link, n in expected.items() if got.get(link, 0) < n)
        if missing:
            raise CollisionGeometryError(
                f"{self.source}: the collision geometry of link(s) {', '.join(missing)} did not load "
                "(an unsupported or empty <geometry>?); every <collision> must give a box, cylinder, sphere, "
                "capsule or mesh"
            )
        self._visual_text = text
        return gm

    def _fixtures(self) -> tuple[Fixture, ...]:
        data = self.model.createData()
        gd = cold_start(pin.GeometryData(self.collision_model))
        pin.updateGeometryPlacements(self.model, data, self.collision_model, gd, pin.neutral(self.model))
        by_link: dict[str, list[Shape]] = {name: [] for name in self.spec.fixtures}
        for k, g in enumerate(self.collision_model.geometryObjects):
            link = self.model.frames[g.parentFrame].name
            if link not in by_link:
                continue
            kind, size = _shape_of(g.geometry)
            mesh = None
            if kind == "mesh":
                size = tuple(float(v) for v in np.asarray(g.meshScale))
                mesh = self._mesh_name(link)
            by_link[link].append(Shape(kind, size, gd.oMg[k].homogeneous.copy(), mesh, g.name))
        return tuple(Fixture(name, tuple(shapes)) for name, shapes in by_link.items())

    def _mesh_name(self, link: str) -> str | None:
        root = ET.fromstring(self.urdf_text)
        for el in root.findall("link"):
            if el.get("name") == link:
                mesh = el.find("collision/geometry/mesh")
                return None if mesh is None else mesh.get("filename")
        return None

    def _finish_geometry(self) -> None:
        """Keep only the checked pairs in the collision model, the candidate pairs, and test every checked pair once."""
        from .pairs import reach_pairs

        reach, bounds = reach_pairs(self, self.allowed)
        self._set_candidates(self.pairs, reach, bounds)
        # the checked pairs once each (an out-of-reach pair coal cannot measure is a named error when used)
        n = len(self.pairs)
        gm, gd = self._views.geometry(n), self._views.distance_data(n)
        pin.updateGeometryPlacements(self.model, self._views.data(), gm, gd, pin.neutral(self.model))
        for k, p in enumerate(self.pairs):
            try:
                d = pin.computeDistance(gm, gd, k).min_distance
                pin.computeCollision(gm, gd, k)
            except Exception as exc:
                raise CollisionGeometryError(
                    f"{self.source}: the pair ({p.body_a}, {p.body_b}) cannot be checked by coal: {exc}"
                ) from exc
            if not np.isfinite(d):
                raise CollisionGeometryError(
                    f"{self.source}: the distance between {p.body_a} and {p.body_b} is {d}: check their geometry"
                )

    def _set_candidates(self, pairs: tuple, reach: tuple, bounds: np.ndarray) -> None:
        """Checked pairs, then out-of-reach pairs by increasing bound; the collision model keeps the checked ones."""
        from .views import PairViews

        self.pairs = tuple(pairs)
        self._reach = tuple(reach)
        self._reach_bounds = np.asarray(bounds, dtype=float)
        self._candidates = self.pairs + self._reach
        gm = self.collision_model
        gm.removeAllCollisionPairs()
        for p in self.pairs:
            gm.addCollisionPair(pin.CollisionPair(p.index_a, p.index_b))
        self._views = PairViews(self.model, gm, self._candidates)
        for cache in ("_bounds",):
            self.__dict__.pop(cache, None)

    # ------------------------------------------------------------------ pairs
    def _n_for(self, clearance: float, *, strict: bool = False) -> int:
        """How many candidate pairs a check at ``clearance`` [m] needs (bound ≤ it; ``strict``: bound < it)."""
        side = "left" if strict else "right"
        return len(self.pairs) + int(np.searchsorted(self._reach_bounds, clearance, side=side))

    def pairs_for(self, clearance: float) -> tuple:
        """The pairs a check at ``clearance`` (or margin) [m] must look at.

        The checked pairs (:attr:`pairs`) followed by every ``"out of reach"`` pair whose
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
        return self._candidates[: self._n_for(value)]

    # --------------------------------------------------------------- joint vector
    @property
    def nq(self) -> int:
        """Length of the cell joint vector."""
        return self.robot.nq

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

    def q_from_arms(self, arm_q: Mapping[str, Any], base: Any = None) -> np.ndarray:
        """A cell joint vector from ``{arm name: q_arm (nq_arm,) or (N, nq_arm)}``.

        Arms not named keep ``base`` (default :attr:`neutral`). Batches of the named arms
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
        q0 = self.neutral if base is None else self.robot.check_q(base)[0][0]
        out = np.tile(q0, (rows or 1, 1))
        for arm, arr in parts.values():
            out[:, arm.q_slice] = arr
        return out[0] if rows is None else out

    def arm_q(self, q: Any, name: str) -> np.ndarray:
        """The block of arm ``name`` in the cell vector(s) ``q``."""
        arr, single = self.robot.check_q(q)
        out = arr[:, self.arm(name).q_slice]
        return out[0] if single else out

    def world_pose(self, q: Any, frame: str) -> np.ndarray:
        """Pose(s) ``(4, 4)`` / ``(N, 4, 4)`` of any cell frame (``"left_tcp"``) in the world."""
        return self.robot.fk(q, frame)

    def _q_pin_single(self, q: Any) -> np.ndarray | None:
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

    def geometry_placements(self, q: Any) -> tuple[np.ndarray, np.ndarray]:
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

    def with_arm_base(self, name: str, base_to_world: Any, carry: tuple[str, ...] = ()) -> "Cell":
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
        arm = self.arm(name)
        T = np.asarray(base_to_world, dtype=float)
        if T.shape != (4, 4) or not np.all(np.isfinite(T)) or np.abs(T[:3, :3] @ T[:3, :3].T - np.eye(3)).max() > 1e-9 \
                or np.linalg.det(T[:3, :3]) < 0 or np.abs(T[3] - [0, 0, 0, 1]).max() > 1e-12:
            raise InvalidInput(f"base_to_world of arm {name!r} must be a rigid transform (4, 4), got {base_to_world!r}")
        spec = next(a for a in self.spec.arms if a.name == arm.name)
        for fixture in carry:
            self.fixture(fixture)  # InvalidInput for an unknown name
        root = ET.fromstring(self.urdf_text)
        data = self.model.createData()
        pin.framesForwardKinematics(self.model, data, pin.neutral(self.model))

        def world(link: str) -> np.ndarray:
            return data.oMf[self.model.getFrameId(link)].homogeneous

        def place(link: str, link_to_world: np.ndarray) -> None:
            holder = next((j for j in root.iter("joint")
                           if j.find("child") is not None and j.find("child").get("link") == link), None)
            if holder is None or holder.get("type") != "fixed":
                raise CellError(f"link {link!r} of cell {self.name!r} is not held by a fixed joint: cannot move it")
            origin = np.linalg.inv(world(holder.find("parent").get("link"))) @ link_to_world
            element = holder.find("origin")
            if element is None:
                element = ET.SubElement(holder, "origin")
            element.set("xyz", " ".join(repr(float(v)) for v in origin[:3, 3]))
            element.set("rpy", " ".join(repr(float(v)) for v in pin.rpy.matrixToRpy(origin[:3, :3])))

        moved = T @ np.linalg.inv(arm.base_to_world)
        for fixture in carry:
            place(fixture, moved @ world(fixture))
        place(spec.base_link, T)
        return Cell(ET.tostring(root, encoding="unicode"), source=f"{self.source} (arm {name!r} moved)",
                    base_dir=self._base_dir, packages=self._packages, args=self.args, seed=self._seed)

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
    def in_collision(self, q: Any, *, margin: float = 0.0, threads: int = 1) -> bool | np.ndarray:
        """Whether ``q (nq,)`` (→ bool) or each row of ``q (N, nq)`` (→ ``(N,)`` bool) touches.

        A pair touches when its distance is at most ``margin`` [m] (0: contact or
        penetration); the pairs looked at are :meth:`pairs_for` ``(margin)``. Pinocchio's broad phase (dynamic AABB tree) culls pairs whose boxes are
        apart and coal decides the rest, stopping at the first contact; a batch runs in
        Pinocchio's C++ loop (``computeCollisionsInParallel``) on ``threads`` threads.
        """
        from .collision import in_collision

        return in_collision(self, q, margin=margin, threads=threads)

    def collisions(self, q: Any, *, margin: float = 0.0):
        """Which pairs of :meth:`pairs_for` ``(margin)`` touch (distance ≤ ``margin`` [m]) for ``q (nq,)`` or ``(N, nq)``: a :class:`~.collision.Collisions`."""
        from .collision import collisions

        return collisions(self, q, margin=margin)

    def clearance(self, q: Any, *, margin: float = 0.0):
        """Smallest signed distance [m] over every pair not allowed by design, and the pair: a :class:`~.collision.Clearance`.

        The checked pairs and every out-of-reach pair whose bound is below the smallest
        distance found: the true minimum over all pairs but those allowed by design.
        """
        from .collision import clearance

        return clearance(self, q, margin=margin)

    def check_motion(self, motions: Any, *, margin: float = 0.01, **kwargs):
        """Check the arms' trajectories together, continuously in time: a :class:`~.motion.MotionCheck`.

        See :func:`~pinarms.robots.cell.motion.check_motion` for the arguments and the time-step rule.
        """
        from .motion import check_motion

        return check_motion(self, motions, margin=margin, **kwargs)
