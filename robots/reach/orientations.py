"""Tool orientation sets of a reachability map: evenly spread over SO(3), or tool-axis directions with rolls.

Two families, both deterministic (no random numbers):

- :func:`so3_orientations` — ``n`` rotations spread over the whole rotation group by a
  *super-Fibonacci spiral* (M. Alexa, "Super-Fibonacci Spirals: Fast, Low-Discrepancy
  Sampling of SO(3)", CVPR 2022). Sample ``i`` of ``n`` is the unit quaternion
  ``(r sin α, r cos α, R sin β, R cos β)`` with ``s = i + ½``, ``r = √(s/n)``,
  ``R = √(1 − s/n)``, ``α = 2π s/φ``, ``β = 2π s/ψ``, ``φ = √2`` and ``ψ ≈ 1.533751``
  (the real root of ``ψ⁴ = ψ + 4``): a low-discrepancy sequence for the Haar measure.
- :func:`tool_axis_orientations` — directions of one tool axis spread over the sphere (or a
  cone) by a Fibonacci (golden-angle) spiral, each combined with ``roll_steps`` rotations about
  that axis. Direction ``i`` of ``n`` on a cap of half-angle ``θ`` around ``about`` has
  ``cos(angle to about) = 1 − (1 − cos θ)·i/(n − 1)`` (the whole sphere: ``θ = π``) and
  azimuth ``i·π(3 − √5)``: equal area per point, the cap's centre (``i = 0``) and its rim
  (``i = n − 1``) included. :func:`tool_down_orientations` is the food-line case: the tool axis
  within a cone around straight down, the roll about it *free* (a direction counts as reached
  when any of its rolls is).

How even a set is, :meth:`OrientationSet.spread` measures it: the largest and mean angle from
a dense seeded probe (uniform rotations, or uniform directions in the cone) to the nearest
member (the *covering radius*, a lower bound of the exact one), and the smallest angle between
two members. Angles between rotations are geodesic (the angle of ``R_aᵀ R_b``) [rad].

Rotations are *tool frame → base*: column ``k`` of ``R`` is the tool frame's axis ``k`` in
base axes.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from pinarms.errors import InvalidInput
from pinarms.robots.so3 import about as _rotation_about
from pinarms.robots.so3 import frame_z_to as _frame_z_to
from pinarms.robots.so3 import from_quaternion as _quat_to_matrix

__all__ = [
    "OrientationSet",
    "OrientationSpread",
    "so3_orientations",
    "fibonacci_directions",
    "tool_axis_orientations",
    "tool_down_orientations",
    "MAX_ORIENTATIONS",
    "align_rotations",
]

#: Largest orientation set a map accepts (poses per voxel).
MAX_ORIENTATIONS = 100_000

_PHI = np.sqrt(2.0)
_PSI = 1.533751168755204288118041  # real root of psi**4 = psi + 4
_GOLDEN_ANGLE = np.pi * (3.0 - np.sqrt(5.0))
_DOWN = np.array([0.0, 0.0, -1.0])


@dataclass(frozen=True)
class OrientationSpread:
    """How evenly an :class:`OrientationSet` covers its domain (angles in rad).

    Attributes:
        covering_radius: largest angle from a probe to its nearest member (a lower bound of
            the exact covering radius; it converges from below as the probe grows).
        mean_distance: mean angle from a probe to its nearest member.
        min_separation: smallest angle between two distinct members (directions for tool-axis
            sets, rotations for SO(3) sets).
        probes: number of probe rotations or directions used.
        domain: ``"SO(3)"`` or ``"directions"`` (the tool axis over the sphere or the cone).
    """

    covering_radius: float
    mean_distance: float
    min_separation: float
    probes: int
    domain: str


@dataclass(frozen=True, eq=False)
class OrientationSet:
    """The tool orientations tried in every voxel.

    Attributes:
        kind: ``"so3"`` or ``"tool_axis"``.
        rotations: ``(M, 3, 3)`` tool frame → base rotations (read-only).
        group: ``(M,)`` index of the direction each rotation belongs to (``so3``: ``0..M-1``).
        n_groups: number of directions (``so3``: ``M``). The reachability index of a voxel is
            the fraction of rotations reached, or for a roll-free set the fraction of groups
            reached (:attr:`n_index` counts them).
        roll_free: a group counts as reached when *any* of its rotations is (roll ignored);
            ``False`` for ``so3`` sets, where each group is one rotation.
        tool_axis: ``(3,)`` unit tool axis in the tool frame (``so3``: ``(0, 0, 1)``, for display).
        directions: ``(n_groups, 3)`` the tool axis of each group in base axes.
        parameters: how the set was made (JSON-able), e.g. ``{"n": 50}`` or the cone and roll steps.
    """

    kind: str
    rotations: np.ndarray = field(repr=False)
    group: np.ndarray = field(repr=False)
    n_groups: int
    roll_free: bool
    tool_axis: np.ndarray = field(repr=False)
    directions: np.ndarray = field(repr=False)
    parameters: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        for name in ("rotations", "group", "tool_axis", "directions"):
            getattr(self, name).flags.writeable = False

    @property
    def size(self) -> int:
        """Number of rotations ``M`` (poses per voxel)."""
        return int(self.rotations.shape[0])

    def __len__(self) -> int:
        return self.size

    @property
    def n_index(self) -> int:
        """What the reachability index counts: directions (roll-free sets) or rotations (the others)."""
        return self.n_groups if self.roll_free else self.size

    def describe(self) -> str:
        """One line: what the set is."""
        p = self.parameters
        if self.kind == "so3":
            return f"{self.size} rotations over SO(3) (super-Fibonacci spiral)"
        cone = p.get("cone_deg")
        where = "the whole sphere" if cone is None or cone >= 180.0 else f"a {cone:g}° cone around {tuple(p.get('about'))}"
        roll = "roll free (any roll counts)" if self.roll_free else "each roll counted"
        return (
            f"{self.n_groups} tool-axis directions ({tuple(np.round(self.tool_axis, 6).tolist())} of the tool) "
            f"over {where} × {p.get('roll_steps')} roll steps = {self.size} poses, {roll}"
        )

    def nearest(self, rotations: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """Index of the nearest member and the angle to it [rad] for ``rotations (N, 3, 3)`` (or ``(3, 3)``).

        ``so3`` sets: geodesic angle between rotations. ``tool_axis`` sets: the angle between
        tool-axis directions picks the group; with ``roll_free`` the member is the group's
        first rotation and the angle is the direction angle alone, otherwise the nearest
        rotation within the group by geodesic angle.
        """
        R = np.asarray(rotations, dtype=float)
        single = R.ndim == 2
        R = R.reshape(-1, 3, 3)
        if self.kind == "so3":
            ang = _geodesic(R, self.rotations)
            k = np.argmin(ang, axis=1)
            out = k, ang[np.arange(R.shape[0]), k]
        else:
            d = R @ self.tool_axis
            cos = np.clip(d @ self.directions.T, -1.0, 1.0)
            g = np.argmax(cos, axis=1)
            dir_angle = np.arccos(cos[np.arange(R.shape[0]), g])
            first = np.searchsorted(self.group, np.arange(self.n_groups))
            if self.roll_free:
                out = first[g], dir_angle
            else:
                ang = _geodesic(R, self.rotations)
                ang = np.where(self.group[None, :] == g[:, None], ang, np.inf)
                k = np.argmin(ang, axis=1)
                out = k, ang[np.arange(R.shape[0]), k]
        return (int(out[0][0]), float(out[1][0])) if single else out

    def spread(self, probes: int = 20_000, seed: int = 0) -> OrientationSpread:
        """Covering radius, mean nearest angle and minimum separation (see :class:`OrientationSpread`)."""
        if isinstance(probes, bool) or not isinstance(probes, (int, np.integer)) or probes < 1:
            raise InvalidInput(f"probes must be a positive integer, got {probes!r}")
        rng = np.random.default_rng(seed)
        if self.kind == "so3":
            quats = rng.normal(size=(int(probes), 4))
            P = _quat_to_matrix(quats / np.linalg.norm(quats, axis=1, keepdims=True))
            dist = np.concatenate([_geodesic(P[s : s + 2000], self.rotations).min(axis=1) for s in range(0, P.shape[0], 2000)])
            self_ang = _geodesic(self.rotations, self.rotations)
            domain = "SO(3)"
        else:
            cone = np.radians(self.parameters.get("cone_deg") or 180.0)
            about = np.asarray(self.parameters.get("about", _DOWN), dtype=float)
            cz = 1.0 - rng.uniform(size=int(probes)) * (1.0 - np.cos(cone))
            az = rng.uniform(0.0, 2.0 * np.pi, size=int(probes))
            local = np.column_stack([np.sqrt(np.maximum(1.0 - cz * cz, 0.0)) * np.cos(az),
                                     np.sqrt(np.maximum(1.0 - cz * cz, 0.0)) * np.sin(az), cz])
            dirs = local @ _frame_z_to(about).T
            cos = np.clip(dirs @ self.directions.T, -1.0, 1.0)
            dist = np.arccos(cos.max(axis=1))
            self_ang = np.arccos(np.clip(self.directions @ self.directions.T, -1.0, 1.0))
            domain = "directions"
        np.fill_diagonal(self_ang, np.inf)
        sep = float(self_ang.min()) if self_ang.size > 1 else float("nan")
        return OrientationSpread(float(dist.max()), float(dist.mean()), sep, int(probes), domain)


# ----------------------------------------------------------------------------- helpers
def _geodesic(A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """Angles ``(len(A), len(B))`` between rotations [rad]: ``arccos((tr(A_iᵀ B_j) − 1) / 2)``."""
    tr = np.einsum("iab,jab->ij", A, B)
    return np.arccos(np.clip(0.5 * (tr - 1.0), -1.0, 1.0))


def _unit(v: Any, what: str) -> np.ndarray:
    try:
        a = np.asarray(v, dtype=float).reshape(-1)
    except (TypeError, ValueError) as exc:
        raise InvalidInput(f"{what} must be a 3-vector of numbers, got {v!r}") from exc
    if a.shape != (3,) or not np.all(np.isfinite(a)) or np.linalg.norm(a) < 1e-12:
        raise InvalidInput(f"{what} must be a finite non-zero 3-vector, got {v!r}")
    return a / np.linalg.norm(a)


def _count(n: Any, what: str, low: int = 1) -> int:
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < low or n > MAX_ORIENTATIONS:
        raise InvalidInput(f"{what} must be an integer in [{low}, {MAX_ORIENTATIONS}], got {n!r}")
    return int(n)


def align_rotations(a: np.ndarray, d: np.ndarray) -> np.ndarray:
    """Rotations ``(N, 3, 3)`` taking the unit vector ``a`` to each unit direction ``d (N, 3)``.

    The smallest rotation (about ``a × d``); for ``d = −a`` a half turn about a fixed axis
    perpendicular to ``a`` (the first column of :func:`_frame_z_to`).
    """
    v = np.cross(a, d)
    c = d @ a
    out = np.empty((d.shape[0], 3, 3))
    anti = c < -1.0 + 1e-12
    ok = ~anti
    vx = np.zeros((int(ok.sum()), 3, 3))
    vv = v[ok]
    vx[:, 0, 1], vx[:, 0, 2], vx[:, 1, 2] = -vv[:, 2], vv[:, 1], -vv[:, 0]
    vx[:, 1, 0], vx[:, 2, 0], vx[:, 2, 1] = vv[:, 2], -vv[:, 1], vv[:, 0]
    out[ok] = np.eye(3) + vx + (vx @ vx) / (1.0 + c[ok])[:, None, None]
    if anti.any():
        perp = _frame_z_to(a)[:, 0]
        out[anti] = 2.0 * np.outer(perp, perp) - np.eye(3)
    return out


# ----------------------------------------------------------------------------- sets
def so3_orientations(n: int = 50) -> OrientationSet:
    """``n`` rotations spread over SO(3) by a super-Fibonacci spiral (see the module doc)."""
    n = _count(n, "number of orientations n")
    s = np.arange(n) + 0.5
    r, R = np.sqrt(s / n), np.sqrt(1.0 - s / n)
    alpha, beta = 2.0 * np.pi * s / _PHI, 2.0 * np.pi * s / _PSI
    quats = np.column_stack([r * np.sin(alpha), r * np.cos(alpha), R * np.sin(beta), R * np.cos(beta)])
    rot = _quat_to_matrix(quats)
    axis = np.array([0.0, 0.0, 1.0])
    return OrientationSet("so3", rot, np.arange(n), n, False, axis, rot[:, :, 2].copy(), {"n": n})


def fibonacci_directions(n: int, *, cone: float | None = None, about: ArrayLike = (0.0, 0.0, -1.0)) -> np.ndarray:
    """``n`` unit directions ``(n, 3)`` spread over the sphere, or over a cone of half-angle ``cone`` [rad] around ``about``.

    Equal area per point by a golden-angle spiral (module doc); the cap's centre and rim are
    included (``n = 1``: the centre alone).
    """
    n = _count(n, "number of directions")
    about = _unit(about, "cone axis 'about'")
    theta = np.pi if cone is None else float(cone)
    if not (np.isfinite(theta) and 0.0 < theta <= np.pi):
        raise InvalidInput(f"cone half-angle must be in (0, π] rad, got {cone!r}")
    i = np.arange(n, dtype=float)
    if n == 1:
        cz = np.ones(1)
    elif theta >= np.pi:  # whole sphere: equal-area bands without duplicating the poles
        cz = 1.0 - 2.0 * (i + 0.5) / n
    else:
        cz = 1.0 - (1.0 - np.cos(theta)) * i / (n - 1)
    sz = np.sqrt(np.maximum(1.0 - cz * cz, 0.0))
    az = i * _GOLDEN_ANGLE
    local = np.column_stack([sz * np.cos(az), sz * np.sin(az), cz])
    return local @ _frame_z_to(about).T


def tool_axis_orientations(
    n_directions: int,
    roll_steps: int = 1,
    *,
    tool_axis: ArrayLike = (0.0, 0.0, 1.0),
    cone: float | None = None,
    about: ArrayLike = (0.0, 0.0, -1.0),
    roll_free: bool = False,
) -> OrientationSet:
    """Tool-axis directions (Fibonacci spiral) × ``roll_steps`` rolls about the tool axis.

    Args:
        n_directions: directions of the tool axis.
        roll_steps: rolls per direction, ``2π k / roll_steps``, ``k = 0..roll_steps-1``.
        tool_axis: the axis in the tool frame that is pointed (default the tool's z).
        cone: half-angle [rad] of the cone of directions around ``about`` (default the sphere).
        about: the cone's axis in base axes (default straight down, ``(0, 0, −1)``).
        roll_free: a direction counts as reached when any of its rolls is.

    Roll zero of direction ``d`` is ``Q(d) · A``: ``A`` a fixed rotation taking ``tool_axis`` to
    ``about`` (:func:`align_rotations`), ``Q(d)`` the smallest rotation taking ``about`` to ``d``; roll
    ``ρ`` is then ``Q(d) · A · Rot(tool_axis, ρ)``.
    """
    tool_axis = _unit(tool_axis, "tool_axis")
    about_u = _unit(about, "cone axis 'about'")
    roll_steps = _count(roll_steps, "roll_steps")
    dirs = fibonacci_directions(n_directions, cone=cone, about=about_u)
    total = dirs.shape[0] * roll_steps
    if total > MAX_ORIENTATIONS:
        raise InvalidInput(f"{dirs.shape[0]} directions × {roll_steps} rolls = {total} poses per voxel, more than {MAX_ORIENTATIONS}")
    A = align_rotations(tool_axis, about_u[None])[0]
    Q = align_rotations(about_u, dirs)
    rolls = _rotation_about(tool_axis, 2.0 * np.pi * np.arange(roll_steps) / roll_steps)
    rot = np.einsum("dij,jk,rkl->dril", Q, A, rolls).reshape(-1, 3, 3)
    group = np.repeat(np.arange(dirs.shape[0]), roll_steps)
    params = {
        "n_directions": int(dirs.shape[0]),
        "roll_steps": roll_steps,
        "cone_deg": None if cone is None else float(np.degrees(cone)),
        "about": about_u.tolist(),
        "tool_axis": tool_axis.tolist(),
    }
    return OrientationSet("tool_axis", rot, group, int(dirs.shape[0]), bool(roll_free), tool_axis, dirs, params)


def tool_down_orientations(
    cone: float = np.radians(15.0), n_directions: int = 16, roll_steps: int = 8, *, tool_axis: ArrayLike = (0.0, 0.0, 1.0)
) -> OrientationSet:
    """The food-line set: ``tool_axis`` within ``cone`` [rad] of straight down, roll free.

    ``n_directions`` Fibonacci directions in the cone (straight down first), each tried at
    ``roll_steps`` rolls; a direction is reached when any roll is.
    """
    return tool_axis_orientations(
        n_directions, roll_steps, tool_axis=tool_axis, cone=cone, about=_DOWN, roll_free=True
    )
