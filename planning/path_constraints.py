"""Limits along a geometric path, as objects: each gives linear bounds on (s̈, ṡ²) per grid point.

Along a path ``q(s)`` timed by ``s(t)`` the joint velocity and acceleration are

    ``q̇ = q'(s) ṡ``,   ``q̈ = q'(s) s̈ + q''(s) ṡ²``

so with ``u = s̈`` and ``x = ṡ²`` every limit of first or second order is **linear in
(u, x)** at a given s. A :class:`PathConstraint` turns a :class:`PathSamples` (the path
and its derivatives at the grid points) into :class:`PathRows`: arrays ``a, b, lo, hi`` of
shape (N, m) meaning

    ``lo[i, r] <= a[i, r] * u + b[i, r] * x <= hi[i, r]``   at grid point i, for each row r

(``±inf`` where a side is free). The time-optimal scaling (:func:`pinarms.optim.time_optimal`, a
reachability analysis) reads nothing else, so **adding a limit never touches the
algorithm** (the split toppra makes). The classes here:

* :class:`JointVelocityConstraint`: ``|q'_j| ṡ <= v_j`` → ``q'_j² x <= v_j²``;
* :class:`JointAccelerationConstraint`: ``|q'_j u + q''_j x| <= a_j``;
* :class:`ToolSpeedConstraint`: tcp speed ``|p'| ṡ <= v`` (and angular ``|ω| ṡ <= Ω``);
* :class:`ToolAccelerationConstraint`: ``|p' u + p'' x| <= A``, a disc in (u, x) space
  after the 2×2 reduction below, replaced by an inscribed regular polygon (``sides``
  rows; exact when p' and p'' are parallel, e.g. on a straight line).

Writing another (e.g. joint torque ``τ = M(q)(q' u + q'' x) + C(q, q') q' x + g(q)``:
``a = M q'``, ``b = M q'' + C q'``, bounds ``±τ_max − g``): subclass
:class:`PathConstraint`, give it a ``name`` and implement :meth:`PathConstraint.rows`;
:attr:`PathSamples.path` gives the robot (``path.robot``) and the tool frame.

Units: u in [s-unit]/s², x in [s-unit]²/s² (m for Cartesian paths); limits SI per joint.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field
from typing import Any, TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from pinarms.planning._inputs import finite_array
from pinarms.planning.errors import TrajectoryError

if TYPE_CHECKING:
    from pinarms.planning.joint_path import JointPath
    from pinarms.planning.timed_curve import TimedCurve

__all__ = ["PathSamples", "PathRows", "PathConstraint", "JointVelocityConstraint", "JointAccelerationConstraint",
           "ToolSpeedConstraint", "ToolAccelerationConstraint"]


@dataclass(frozen=True, eq=False)
class PathSamples:
    """A path at grid points ``s`` (N,): joints ``q``, ``dq = q'(s)``, ``ddq = q''(s)`` (N, n).

    ``path`` is the :class:`pinarms.planning.JointPath` sampled (its ``robot`` and ``frame`` serve
    tool and dynamics constraints); ``side`` tells which piece was used at a break.
    :attr:`tool` is evaluated once, on first use.
    """

    s: np.ndarray
    q: np.ndarray
    dq: np.ndarray
    ddq: np.ndarray
    path: Any = field(repr=False)
    side: str = "right"

    @classmethod
    def of(cls, path: JointPath, s: ArrayLike, side: str = "right") -> "PathSamples":
        """Sample ``path`` at ``s``."""
        arr = np.atleast_1d(np.asarray(s, dtype=float))
        q, dq, ddq = path.sample(arr, side)
        return cls(arr, q, dq, ddq, path, side)

    @functools.cached_property
    def tool(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """tcp pose (N, 4, 4) and its s-derivatives ``(p', ω)`` and ``(p'', ω')`` (N, 6), base axes."""
        return self.path.tool_derivatives(self.s, self.side)


@dataclass(frozen=True, eq=False)
class PathRows:
    """``lo <= a u + b x <= hi`` row-wise at every grid point; each array (N, m); ``labels`` (m,) name the rows."""

    a: np.ndarray
    b: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    labels: tuple[str, ...] = ()

    @staticmethod
    def concatenate(parts: list["PathRows"]) -> "PathRows":
        """All rows of several constraints side by side."""
        return PathRows(*(np.concatenate([getattr(p, k) for p in parts], axis=1) for k in ("a", "b", "lo", "hi")),
                        tuple(label for p in parts for label in p.labels))

    @staticmethod
    def concatenate_points(parts: list["PathRows"]) -> "PathRows":
        """The same rows at the points of several samplings, one after the other."""
        return PathRows(*(np.concatenate([getattr(p, k) for p in parts], axis=0) for k in ("a", "b", "lo", "hi")),
                        parts[0].labels)

    def values(self, u: np.ndarray, x: np.ndarray) -> np.ndarray:
        """``a u + b x`` (N, m) for per-point ``u``, ``x`` (N,)."""
        return self.a * u[:, None] + self.b * x[:, None]


class PathConstraint:
    """Base of the path constraints: a ``name`` and :meth:`rows` (see the module docstring)."""

    name = "constraint"

    def rows(self, samples: PathSamples) -> PathRows:  # pragma: no cover - abstract
        """Linear bounds on (u, x) at every sample."""
        raise NotImplementedError

    def exact_dilation(self, trajectory: TimedCurve) -> float:
        """Smallest time dilation factor f >= 1 that makes a timed ``trajectory`` satisfy the limit exactly.

        ``trajectory`` is a :class:`pinarms.planning.Trajectory`, or the timing's stand-in with
        ``n_joints``, ``peaks()`` (computed once for every constraint) and ``trajectory`` (the
        Trajectory itself). Default 1 (not known exactly: the timing checks the rows densely
        instead); joint limits use the exact peaks, joint torque its refined torque peaks.
        """
        return 1.0


def _limit(value: Any, n: int, what: str) -> np.ndarray:
    arr = finite_array(value, what)
    if arr.ndim > 1 or (arr.ndim == 1 and arr.size not in (1, n)):
        raise TrajectoryError(f"{what} must be one number or one per joint ({n}), got shape {arr.shape}")
    arr = np.broadcast_to(arr.reshape(-1) if arr.ndim else arr, (n,)).astype(float)
    if np.any(arr <= 0.0):
        raise TrajectoryError(f"{what} must be positive, got {arr.tolist()}")
    return arr


def _positive(value: Any, what: str) -> float:
    arr = finite_array(value, what)
    if arr.ndim != 0 or float(arr) <= 0.0:
        raise TrajectoryError(f"{what} must be one positive number, got {value!r}")
    return float(arr)


@dataclass(frozen=True, eq=False)
class JointVelocityConstraint(PathConstraint):
    """``|q̇_j| <= vmax_j`` [rad/s or m/s], scalar or per joint."""

    vmax: Any
    name = "joint velocity"

    def rows(self, samples: PathSamples) -> PathRows:
        n = samples.dq.shape[1]
        v = _limit(self.vmax, n, "vmax [rad/s or m/s]")
        N = samples.s.size
        return PathRows(np.zeros((N, n)), samples.dq**2, np.full((N, n), -np.inf), np.broadcast_to(v * v, (N, n)).copy(),
                        tuple(f"velocity of joint {j + 1}" for j in range(n)))

    def exact_dilation(self, trajectory: TimedCurve) -> float:
        v = _limit(self.vmax, trajectory.n_joints, "vmax [rad/s or m/s]")
        return float(max(1.0, np.max(trajectory.peaks().velocity / v)))


@dataclass(frozen=True, eq=False)
class JointAccelerationConstraint(PathConstraint):
    """``|q̈_j| <= amax_j`` [rad/s² or m/s²], scalar or per joint."""

    amax: Any
    name = "joint acceleration"

    def rows(self, samples: PathSamples) -> PathRows:
        n = samples.dq.shape[1]
        a = np.broadcast_to(_limit(self.amax, n, "amax [rad/s² or m/s²]"), samples.dq.shape)
        return PathRows(samples.dq.copy(), samples.ddq.copy(), -a, a.copy(),
                        tuple(f"acceleration of joint {j + 1}" for j in range(n)))

    def exact_dilation(self, trajectory: TimedCurve) -> float:
        a = _limit(self.amax, trajectory.n_joints, "amax [rad/s² or m/s²]")
        return float(max(1.0, np.sqrt(np.max(trajectory.peaks().acceleration / a))))


@dataclass(frozen=True, eq=False)
class ToolSpeedConstraint(PathConstraint):
    """tcp speed ``|ṗ| <= linear`` [m/s] (e.g. 0.5 m/s carrying food) and optionally ``|ω| <= angular`` [rad/s].

    Evaluated on the joint path (``ṗ = J_v(q) q' ṡ``); needs ``path.robot``.
    """

    linear: Any = None
    angular: Any = None
    name = "tool speed"

    def __post_init__(self) -> None:
        if self.linear is None and self.angular is None:
            raise TrajectoryError("ToolSpeedConstraint needs a linear [m/s] or an angular [rad/s] limit")

    def rows(self, samples: PathSamples) -> PathRows:
        _, d1, _ = samples.tool
        cols, his, labels = [], [], []
        if self.linear is not None:
            cols.append(np.sum(d1[:, :3] ** 2, axis=1))
            his.append(_positive(self.linear, "linear tool speed [m/s]") ** 2)
            labels.append("tool speed")
        if self.angular is not None:
            cols.append(np.sum(d1[:, 3:] ** 2, axis=1))
            his.append(_positive(self.angular, "angular tool speed [rad/s]") ** 2)
            labels.append("tool angular speed")
        b = np.stack(cols, axis=1)
        N = b.shape[0]
        return PathRows(np.zeros_like(b), b, np.full(b.shape, -np.inf), np.broadcast_to(np.array(his), (N, len(his))).copy(),
                        tuple(labels))


@dataclass(frozen=True, eq=False)
class ToolAccelerationConstraint(PathConstraint):
    """tcp linear acceleration ``|p̈| <= linear`` [m/s²], as ``sides`` linear rows (see the module docstring).

    ``p̈ = p' u + p'' x = M z`` with ``M = [p', p'']`` (3×2) and ``z = (u, x)``. With
    ``MᵀM = Vᵀ Λ V`` (eigen-decomposition) ``|M z| = |C z|``, ``C = Λ^½ V``: the limit is the
    disc ``|C z| <= A`` of the plane, replaced by the regular polygon inscribed in it with
    vertices on C's axes (``sides`` a multiple of 4): at most ``1 − cos(π / sides)`` of the
    limit is lost (0.12 % for 64), nothing where p'' is parallel to p'.
    """

    linear: Any
    sides: int = 64
    name = "tool acceleration"

    def __post_init__(self) -> None:
        _positive(self.linear, "linear tool acceleration [m/s²]")
        if isinstance(self.sides, bool) or not isinstance(self.sides, (int, np.integer)) or self.sides < 4 \
                or self.sides % 4:
            raise TrajectoryError(f"sides must be a multiple of 4 (>= 4), got {self.sides!r}")

    def rows(self, samples: PathSamples) -> PathRows:
        A = _positive(self.linear, "linear tool acceleration [m/s²]")
        _, d1, d2 = samples.tool
        M = np.stack([d1[:, :3], d2[:, :3]], axis=2)  # (N, 3, 2)
        lam, vec = np.linalg.eigh(np.swapaxes(M, 1, 2) @ M)  # (N, 2), (N, 2, 2) columns
        C = np.sqrt(np.maximum(lam, 0.0))[:, :, None] * np.swapaxes(vec, 1, 2)  # rows = sqrt(λ_k) v_kᵀ
        K = int(self.sides)
        ang = (2.0 * np.arange(K) + 1.0) * np.pi / K
        normals = np.stack([np.cos(ang), np.sin(ang)], axis=1)  # (K, 2)
        coef = np.einsum("kc,ncz->nkz", normals, C)  # (N, K, 2)
        N = coef.shape[0]
        hi = np.full((N, K), A * np.cos(np.pi / K))
        return PathRows(coef[..., 0].copy(), coef[..., 1].copy(), np.full((N, K), -np.inf), hi,
                        tuple("tool acceleration" for _ in range(K)))
