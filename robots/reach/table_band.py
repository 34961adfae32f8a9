"""Where to place the pick/place tables: a radial band of the sampled workspace.

:func:`recommend_region` derives the band from the samples of a
:class:`~pinarms.robots.reach.workspace.Workspace` with three criteria, all evaluated per radial shell
(width ``width``) around the workspace's outer-hull sphere centre (``about="centre"``) or
around the base's vertical axis (``about="axis"``):

1. **Base plane.** Only samples on the working side of the base plane ``z = 0`` count:
   ``z > z_clearance`` for a floor-standing arm, ``z < −z_clearance`` for a suspended arm.
   ``side="auto"`` takes the side holding most samples.
2. **Outer shell (dexterity).** A shell is rejected when more than ``max_singular_share``
   of its samples are near-singular (``σ_min/σ_max`` of the position Jacobian below
   ``singular_threshold``). Near the reach boundary the arm is stretched and this share
   rises from a few percent to 100 %.
3. **Crowded centre (own body).** For a seeded sub-sample of ``n_collision`` samples,
   each configuration is checked for collisions between the arm and its *core* bodies
   (base, and the bodies carried only by the first ``core_joints`` joints: the turret)
   with the URDF's collision primitives (:class:`~pinarms.robots.self_collision.SelfCollision`).
   A shell is rejected when more than ``max_collision_share`` of its configurations
   collide so: most ways of reaching it fold the arm onto its own base. Collisions among
   the moving links (wrist against forearm) are not counted: they depend on the tool
   orientation, not on where the tool is.

The band is the longest run of consecutive accepted shells. The defaults were chosen from
the meaning of each share (a usable shell is one where a random configuration is more
likely usable than not, and at most one in four is near-singular), not from any paper's
answer.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from pinarms.errors import InvalidInput
from pinarms.robots.reach.workspace import SINGULAR_INVERSE_CONDITION, as_point, check_singular_threshold, radial_distance

if TYPE_CHECKING:  # pragma: no cover
    from pinarms.robots.reach.workspace import Workspace

__all__ = ["RegionCriteria", "RecommendedRegion", "recommend_region"]


@dataclass(frozen=True)
class RecommendedRegion:
    """A radial band ``r_inner < r < r_outer`` on the working side of the base plane.

    Attributes:
        robot, frame: what was sampled.
        about: ``"centre"`` (r = distance to ``origin``) or ``"axis"`` (r = horizontal
            distance to the vertical line through ``origin``).
        origin: ``(3,)`` [m].
        r_inner, r_outer: the band [m] (both NaN when no shell is accepted).
        side: ``"above"`` (z > z_limit) or ``"below"`` (z < z_limit).
        z_limit: the plane the band is bounded by [m].
        edges: ``(k+1,)`` shell radii [m]; ``counts``, ``singular_share``,
            ``collision_share``, ``collision_checked`` and ``accepted`` are per shell ``(k,)``.
        criteria: thresholds used (name → value).
    """

    robot: str
    frame: str
    about: str
    origin: np.ndarray
    r_inner: float
    r_outer: float
    side: str
    z_limit: float
    edges: np.ndarray = field(repr=False)
    counts: np.ndarray = field(repr=False)
    singular_share: np.ndarray = field(repr=False)
    collision_share: np.ndarray = field(repr=False)
    collision_checked: np.ndarray = field(repr=False)
    accepted: np.ndarray = field(repr=False)
    criteria: dict = field(default_factory=dict)

    @property
    def empty(self) -> bool:
        """True when no shell met the criteria."""
        return not np.isfinite(self.r_inner)

    def contains(self, points: ArrayLike) -> np.ndarray:
        """``(N,)`` bool: which ``points (N, 3)`` [m] lie in the region."""
        P = np.atleast_2d(np.asarray(points, dtype=float))
        if P.ndim != 2 or P.shape[1] != 3:
            raise InvalidInput(f"points must have shape (N, 3) [m], got {np.shape(points)}")
        if self.empty:
            return np.zeros(P.shape[0], dtype=bool)
        r = radial_distance(P, self.origin, self.about)
        z_ok = P[:, 2] > self.z_limit if self.side == "above" else P[:, 2] < self.z_limit
        return (r > self.r_inner) & (r < self.r_outer) & z_ok

    def text(self) -> str:
        """A readable report (mm)."""
        mm = 1000.0
        where = "distance to ({:.0f}, {:.0f}, {:.0f}) mm".format(*(self.origin * mm))
        if self.about == "axis":
            where = "horizontal distance to the vertical axis through ({:.0f}, {:.0f}) mm".format(*(self.origin[:2] * mm))
        head = f"recommended table region of {self.robot} ({self.frame})"
        if self.empty:
            return f"{head}: no shell meets the criteria {self.criteria}"
        lines = [
            head,
            f"  z {'>' if self.side == 'above' else '<'} {self.z_limit * mm + 0.0:.0f} mm and "
            f"{self.r_inner * mm:.0f} mm < r < {self.r_outer * mm:.0f} mm (r = {where})",
            "  criteria: " + ", ".join(f"{k} = {v:g}" for k, v in self.criteria.items()),
            "  shell [mm]   samples  near-singular  core collision  accepted",
        ]
        for lo, hi, n, s, c, a in zip(
            self.edges[:-1], self.edges[1:], self.counts, self.singular_share, self.collision_share, self.accepted
        ):
            if n:
                lines.append(f"  {lo * mm:4.0f}-{hi * mm:4.0f}  {n:9d}  {s:12.1%}  {c:14.1%}  {'yes' if a else 'no'}")
        return "\n".join(lines)


@dataclass(frozen=True)
class RegionCriteria:
    """When a shell of :func:`recommend_region` is accepted (see the module doc), checked when made.

    Attributes:
        singular_threshold: ``sigma_min / sigma_max`` below which a sample is near-singular.
        max_singular_share: outer-shell criterion: largest near-singular share in [0, 1].
        max_collision_share: crowded-centre criterion: largest core-collision share in [0, 1].
        n_collision: samples (seeded by ``seed``) checked for collisions with the core bodies
            (base and the bodies of the first ``core_joints`` joints); 0 skips the check.
        core_joints: how many joints' bodies count as the core.
        seed: seed of the collision sub-sample (>= 0).

    Raises:
        InvalidInput: a criterion out of range, naming it.
    """

    singular_threshold: float = SINGULAR_INVERSE_CONDITION
    max_singular_share: float = 0.25
    max_collision_share: float = 0.5
    n_collision: int = 10_000
    core_joints: int = 1
    seed: int = 0

    def __post_init__(self) -> None:
        for name in ("max_singular_share", "max_collision_share"):
            v = getattr(self, name)
            if not isinstance(v, (int, float, np.integer, np.floating)) or isinstance(v, bool):
                raise InvalidInput(f"{name} must be a number, got {v!r}")
            if not (0.0 <= v <= 1.0):
                raise InvalidInput(f"{name} must be a share in [0, 1], got {v!r}")
        object.__setattr__(self, "singular_threshold", check_singular_threshold(self.singular_threshold))
        seed, n = self.seed, self.n_collision
        if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
            raise InvalidInput(f"seed must be an integer >= 0, got {seed!r}")
        if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 0:
            raise InvalidInput(f"n_collision must be an integer ≥ 0, got {n!r}")


def recommend_region(
    workspace: "Workspace",
    *,
    about: str = "centre",
    origin: ArrayLike | None = None,
    width: float = 0.025,
    side: str = "auto",
    z_clearance: float = 0.0,
    criteria: RegionCriteria | None = None,
) -> RecommendedRegion:
    """Radial band where tables should stand, from the workspace samples (see the module doc).

    Args:
        workspace: a sampled workspace (its robot supplies the collision geometry).
        about: ``"centre"`` (spherical shells) or ``"axis"`` (cylindrical shells).
        origin: centre of the shells [m]; default: the outer-hull sphere centre (its x, y
            for ``about="axis"``).
        width: shell width [m].
        side: ``"above"``, ``"below"`` or ``"auto"`` (the side of ``z = 0`` with most samples).
        z_clearance: distance kept from the base plane [m] (≥ 0).
        criteria: the outer-shell and crowded-centre criteria (:class:`RegionCriteria`;
            default ``RegionCriteria()``).

    Raises:
        InvalidInput: an option is out of range.
    """
    c = RegionCriteria() if criteria is None else criteria
    if not isinstance(c, RegionCriteria):
        raise InvalidInput(f"criteria must be a robots.reach.table_band.RegionCriteria, got {type(c).__name__}")
    _checked_options(about, side, width, z_clearance)
    singular_threshold, max_singular_share, max_collision_share = c.singular_threshold, c.max_singular_share, \
        c.max_collision_share
    n_collision, core_joints, seed = c.n_collision, c.core_joints, c.seed
    P = workspace.points
    origin = _shells_origin(workspace, origin, about)
    if side == "auto":
        side = "above" if np.count_nonzero(P[:, 2] > 0) >= P.shape[0] / 2 else "below"
    z_limit = z_clearance if side == "above" else -z_clearance
    side_mask = P[:, 2] > z_limit if side == "above" else P[:, 2] < z_limit
    keep = np.flatnonzero(side_mask)
    profile = workspace.radial_profile(
        origin, about=about, width=width, mask=side_mask, singular_threshold=singular_threshold
    )
    edges, counts, singular_share = profile.edges, profile.counts, profile.singular_share
    k = counts.size
    shell = np.minimum((radial_distance(P[keep], origin, about) / width).astype(int), k - 1)
    checked, collision_share = _core_collision_share(workspace, keep, shell, k, n_collision, core_joints, seed)

    coll_ok = collision_share <= max_collision_share if n_collision > 0 else np.ones(k, dtype=bool)
    accepted = (counts > 0) & (singular_share <= max_singular_share) & coll_ok
    r_in, r_out = _longest_run(accepted, edges)
    criteria = {
        "shell width [m]": width,
        "z clearance [m]": z_clearance,
        "near-singular sigma_min/sigma_max <": singular_threshold,
        "max near-singular share": max_singular_share,
        "max core-collision share": max_collision_share,
        "core joints": float(core_joints),
        "self-collision samples": float(min(int(n_collision), keep.size)),
    }
    return RecommendedRegion(robot=workspace.robot.name, frame=workspace.frame, about=about, origin=origin,
                             r_inner=r_in, r_outer=r_out, side=side, z_limit=z_limit, edges=edges, counts=counts,
                             singular_share=singular_share, collision_share=collision_share, collision_checked=checked,
                             accepted=accepted, criteria=criteria)


def _shells_origin(workspace: "Workspace", origin: Any, about: str) -> np.ndarray:
    """The shells' centre: ``origin``, by default the outer-hull sphere's centre (at ``z = 0`` for ``about="axis"``)."""
    if origin is None:
        origin = workspace.fit_sphere().centre.copy()
        if about == "axis":
            origin[2] = 0.0
    return as_point(origin, "origin")


def _checked_options(about: Any, side: Any, width: Any, z_clearance: Any) -> None:
    """Check the shell options of :func:`recommend_region` (raising :class:`InvalidInput`)."""
    if about not in ("centre", "axis"):
        raise InvalidInput(f"about must be 'centre' or 'axis', got {about!r}")
    if side not in ("auto", "above", "below"):
        raise InvalidInput(f"side must be 'auto', 'above' or 'below', got {side!r}")
    if not isinstance(width, (int, float, np.integer, np.floating)) or isinstance(width, bool):
        raise InvalidInput(f"width must be a number, got {width!r}")
    if not (np.isfinite(width) and width > 0):
        raise InvalidInput(f"width must be a positive shell width in m, got {width!r}")
    real = (int, float, np.integer, np.floating)
    if isinstance(z_clearance, bool) or not isinstance(z_clearance, real) or not (np.isfinite(z_clearance) and z_clearance >= 0):
        raise InvalidInput(f"z_clearance must be a length ≥ 0 in m, got {z_clearance!r}")


def _core_collision_share(workspace: "Workspace", keep: np.ndarray, shell: np.ndarray, k: int, n_collision: int,
                          core_joints: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """Criterion 3: per shell, the configurations checked and the share colliding with the core bodies.

    ``keep`` are the samples on the working side, ``shell (len(keep),)`` their shell among ``k``;
    ``n_collision`` of them (seeded) are checked. A shell with none checked has share NaN (0 when
    ``n_collision`` is 0: the check is skipped).
    """
    from pinarms.robots.self_collision import SelfCollision

    checked = np.zeros(k, dtype=int)
    collided = np.zeros(k)
    if n_collision > 0 and keep.size:
        rng = np.random.default_rng(seed)
        pick = rng.choice(keep.size, size=min(int(n_collision), keep.size), replace=False)
        checker = SelfCollision(workspace.robot, seed=seed)
        hits = checker.in_collision(workspace.q[keep[pick]], pairs=checker.core_pair_mask(core_joints))
        checked = np.bincount(shell[pick], minlength=k)
        collided = np.bincount(shell[pick], weights=hits.astype(float), minlength=k)
    with np.errstate(invalid="ignore", divide="ignore"):
        collision_share = np.where(checked > 0, collided / np.maximum(checked, 1), np.nan if n_collision else 0.0)
    return checked, collision_share


def _longest_run(accepted: np.ndarray, edges: np.ndarray) -> tuple[float, float]:
    """``(r_inner, r_outer)`` of the longest run of accepted shells (first on ties); NaN if none."""
    best, start, best_span = None, None, 0
    for i, a in enumerate(list(accepted) + [False]):
        if a and start is None:
            start = i
        elif not a and start is not None:
            if i - start > best_span:
                best, best_span = (start, i), i - start
            start = None
    if best is None:
        return float("nan"), float("nan")
    return float(edges[best[0]]), float(edges[best[1]])
