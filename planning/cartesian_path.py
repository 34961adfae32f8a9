"""The joint-space image of a tool path: IK along the path, on one branch, within a tolerance.

:func:`cartesian_path` (tcp poses → :class:`pinarms.planning.ToolPath` → joints) and
:func:`joint_image` (a ToolPath you built) return a :class:`CartesianPath`: a
:class:`pinarms.planning.JointPath` ``q(s)`` whose tcp stays within ``tolerance`` of the tool path
at the same arc length s.

**How.** Knots ``s_k`` carry the exact IK solution ``q_k`` and its path derivatives
``q' = J⁺ X'`` and ``q'' = J⁺ (X'' − J̇ q')`` (X: the tool path, J the tcp Jacobian in base
axes with the angular rows weighted by the path's ``w``; J̇ q' by a central difference
along q'). Between knots q(s) is the **quintic Hermite** interpolant of (q, q', q'') at
both ends: C² in s, error O(h⁶).

1. *Continuation, one branch* (:mod:`pinarms.planning.ik_continuation`). From the start
   configuration each knot is reached by a predictor (Taylor step) and Newton's method on
   the pose error, so the solution moves continuously and never jumps to another IK branch. A step is refused — and halved —
   when Newton does not converge, when the correction or the joint step is large (a jump),
   when a joint leaves its limits, or when the Jacobian's smallest singular value falls
   below ``singular_tolerance``. When the step has shrunk below ``locate`` (10 µm of arc
   length by default) the path stops there with a named error:
   :class:`pinarms.planning.errors.SingularityOnPath`, :class:`~pinarms.planning.errors.JointLimitOnPath`
   or :class:`~pinarms.planning.errors.UnreachableOnPath` (s, pose, reason).
2. *Tolerance rule.* Every interval is checked by FK at 1/4, 1/2 and 3/4 of its length:
   it is split in two when the tcp there is farther than ``tolerance / 2`` from the tool
   path's position (or its orientation more than ``tolerance / (2 w)`` rad away), or when
   the Jacobian's smallest singular value changes by more than a factor 2 across it
   (ill-conditioned stretches get dense knots). New knots are solved in one batch. The
   factor 1/2 is the margin that the tolerance holds everywhere between the checks (tests
   verify it by FK at ten times the knot density).

With a closed-form IK (``robot.ik_branches``) the start's branch label is recorded, and the
end's label is checked to be the same.

Units: m, rad; s in m (the tool path's weighted arc length).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Iterable, TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from pinarms.robots import so3 as _so3
from pinarms.planning._inputs import finite_array, per_joint
from pinarms.planning.errors import (JointLimitOnPath, PathError, SingularityOnPath, TrajectoryError,
                                     UnreachableOnPath)
from pinarms.planning.ik_continuation import MAX_CORRECTION, Knot, PathSolver, Stop, continue_to, solve_knots
from pinarms.planning.joint_path import JointPath
from pinarms.planning.multi_quintic import quintic_hermite_coefficients
from pinarms.planning.tool_path import DEFAULT_WEIGHT, ToolPath, tool_path
from pinarms.errors import UnreachableTarget
from pinarms.robots.ties import argmin_tied

if TYPE_CHECKING:
    from pinarms.robots.robot import Robot

__all__ = ["CartesianPath", "KnotFit", "cartesian_path", "joint_image", "DEFAULT_TOLERANCE", "DEFAULT_SINGULAR_TOLERANCE"]

#: Default largest tcp deviation from the tool path [m] (0.1 mm).
DEFAULT_TOLERANCE = 1e-4
#: Default smallest singular value of the weighted Jacobian [m/rad] below which the arm counts as singular.
DEFAULT_SINGULAR_TOLERANCE = 1e-4
MIN_TOLERANCE = 1e-9  #: smallest tolerance [m]: a tighter one refines for minutes on rounding noise
#: Longest initial knot spacing [m of arc length].
_INITIAL_STEP = 0.1
#: Check points of the tolerance rule, as fractions of an interval.
_CHECKS = np.array([0.25, 0.5, 0.75])


@dataclass(frozen=True)
class KnotFit:
    """What the continuation found at the knots of a :class:`CartesianPath` (its attributes of the same names).

    Attributes:
        q_knots: (K+1, nq) exact IK solutions at the knots (made read-only).
        sigma_min: (K+1,) smallest singular value of the weighted Jacobian at the knots [m/rad] (made read-only).
        branch: closed-form IK branch label of the whole path, or None (numerical IK).
        max_deviation: (position [m], rotation [rad]) largest tcp deviation found at the check points.

    Raises:
        TrajectoryError: shapes that do not match, or a deviation that is not two finite numbers >= 0.
    """

    q_knots: np.ndarray
    sigma_min: np.ndarray
    branch: int | None
    max_deviation: tuple[float, float]

    def __post_init__(self) -> None:
        q = np.asarray(self.q_knots, dtype=float)
        sigma = np.asarray(self.sigma_min, dtype=float)
        if q.ndim != 2 or sigma.shape != (q.shape[0],):
            raise TrajectoryError(f"KnotFit: q_knots must be (K+1, nq) and sigma_min (K+1,), "
                                  f"got {q.shape} and {sigma.shape}")
        dev = tuple(float(v) for v in self.max_deviation)
        if len(dev) != 2 or not all(np.isfinite(v) and v >= 0.0 for v in dev):
            raise TrajectoryError(f"KnotFit: max_deviation must be (position m, rotation rad), finite and >= 0, "
                                  f"got {self.max_deviation!r}")
        q.flags.writeable = False
        sigma.flags.writeable = False
        object.__setattr__(self, "q_knots", q)
        object.__setattr__(self, "sigma_min", sigma)
        object.__setattr__(self, "max_deviation", dev)


class CartesianPath(JointPath):
    """A :class:`pinarms.planning.JointPath` that follows a :class:`pinarms.planning.ToolPath` (module docstring).

    Extra attributes:
        tool_path: the followed :class:`ToolPath` (s is its arc length, m).
        tolerance: the tcp position tolerance [m] it was built to (orientation: ``tolerance / w`` rad).
        q_knots: (K+1, nq) exact IK solutions at the knots ``breaks``.
        sigma_min: (K+1,) smallest singular value of the weighted Jacobian at the knots [m/rad].
        branch: closed-form IK branch label of the whole path, or None (numerical IK).
        max_deviation: (position [m], rotation [rad]) largest tcp deviation found at the check points.
    """

    def __init__(self, breaks: np.ndarray, coefficients: np.ndarray, *, tool: ToolPath, robot: Robot, frame: str,
                 tolerance: float, fit: KnotFit) -> None:
        super().__init__(breaks, coefficients, stops=tool.stops, robot=robot, frame=frame)
        self.tool_path = tool
        self.tolerance = float(tolerance)
        self.q_knots = fit.q_knots
        self.sigma_min = fit.sigma_min
        self.branch = fit.branch
        self.max_deviation = fit.max_deviation

    def deviation(self, s: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """tcp deviation at arc lengths ``s``: position [m] and rotation [rad] from the tool path at the same s."""
        arr, _ = self._check_s(s)
        T = np.asarray(self.robot.fk(self(arr), frame=self.frame))
        ref = self.tool_path.pose(arr)
        pos = np.linalg.norm(T[:, :3, 3] - ref[:, :3, 3], axis=1)
        rot = _so3.angle(np.swapaxes(ref[:, :3, :3], 1, 2) @ T[:, :3, :3])
        return pos, rot

    def as_dict(self) -> dict[str, Any]:
        """JSON-able summary (SI units)."""
        return {"tool_path": self.tool_path.as_dict(), "tolerance_m": self.tolerance, "knots_m": self.breaks.tolist(),
                "q_knots": self.q_knots.tolist(), "sigma_min_m_per_rad": self.sigma_min.tolist(),
                "branch": self.branch, "max_deviation_m": self.max_deviation[0],
                "max_rotation_deviation_rad": self.max_deviation[1]}


# ---------------------------------------------------------------------------- helpers
def _quintic_values(c: np.ndarray, sig: np.ndarray) -> np.ndarray:
    """Value of quintic pieces c (K, 6, n) at local offsets sig (K, M) -> (K, M, n)."""
    powers = sig[..., None] ** np.arange(6)
    return np.einsum("kmd,kdn->kmn", powers, c)


def _failure(sv: PathSolver, s: float, q_last: np.ndarray, kind: str, detail: str) -> PathError:
    """The named error for a continuation that cannot get past arc length s."""
    robot, tool = sv.robot, sv.tool
    pose = tool.pose(min(s, tool.length))
    where = (f"at s = {s:.6g} m of the {tool.length:.6g} m tool path, tcp at "
             f"{np.array2string(pose[:3, 3], precision=6, separator=', ')} m")
    if kind == "limit":
        reason = f"{detail} on this IK branch"
        return JointLimitOnPath(f"robot '{robot.name}' cannot follow the path {where}: {reason}; move the path, "
                                "start from another branch (q_start) or split the path there",
                                s=s, pose=pose, reason=reason, q=q_last)
    # out of reach, or an orientation the arm cannot take, a little farther on?
    ahead = tool.pose(min(s + max(1e-3, 1e-3 * tool.length), tool.length))
    for target in (ahead, pose):
        why = robot.ik_failure_reason(target) if hasattr(robot, "ik_failure_reason") else None
        if why is not None and "outside its limits" not in why and "outside their limits" not in why:
            reason = f"the path leaves the workspace: {why}"
            return UnreachableOnPath(f"robot '{robot.name}' cannot follow the path {where}: {reason}",
                                     s=s, pose=pose, reason=reason, q=q_last)
    reason = (f"the arm comes too close to a singular configuration ({detail}); it cannot follow the path "
              "through it without changing IK branch")
    return SingularityOnPath(f"robot '{robot.name}' cannot follow the path {where}: {reason}; move the path away "
                             "from the singularity or split it there", s=s, pose=pose, reason=reason, q=q_last)


def _labels(robot: Any, pose: np.ndarray, q: np.ndarray) -> int | None:
    if not (getattr(robot, "has_analytic_ik", False) and hasattr(robot, "ik_branches")):
        return None
    sols, labels = robot.ik_branches(pose, q_ref=q)
    sols = np.asarray(sols, dtype=float).reshape(-1, q.size)
    if sols.shape[0] == 0:
        return None
    k = argmin_tied(np.linalg.norm(sols - q, axis=1))
    return int(labels[k]) if np.linalg.norm(sols[k] - q) < 1e-6 else None


def _starts(robot: Any, pose: np.ndarray, q_start: np.ndarray | None) -> list[np.ndarray]:
    """Start configurations to try, in order: near q_start, or every closed-form branch, or numerical IK."""
    nq = int(robot.nq)
    if q_start is not None:
        T = np.asarray(robot.fk(q_start))
        if np.linalg.norm(T[:3, 3] - pose[:3, 3]) < 1e-6 and _so3.angle(T[:3, :3].T @ pose[:3, :3]) < 1e-6:
            return [q_start]
    if getattr(robot, "has_analytic_ik", False) and hasattr(robot, "ik_branches"):
        sols, _ = robot.ik_branches(pose, q_ref=q_start)
        sols = np.asarray(sols, dtype=float).reshape(-1, nq)
        if q_start is not None and sols.shape[0]:
            return [sols[argmin_tied(np.linalg.norm(sols - q_start, axis=1))]]
        if sols.shape[0]:
            return list(sols)
    return [np.asarray(robot.ik(pose, q_seed=q_start), dtype=float).reshape(nq)]


def _build(sv: PathSolver, q0: np.ndarray, tolerance: float, locate: float) -> CartesianPath:
    """The joint path from ``q0`` along the whole tool path (module docstring, steps 1 and 2), on one branch.

    Raises:
        Stop: where the continuation or the tolerance rule cannot go on (:func:`joint_image` names it).
    """
    tool = sv.tool
    L = tool.length
    knots, pos, rot = _refined(sv, _walked(sv, q0, locate), tolerance, locate)
    s = np.array([k.s for k in knots])
    s[-1] = L
    q = np.array([k.q for k in knots])
    branch = _labels(sv.robot, tool.pose(0.0), q[0])
    if branch is not None:
        end = _labels(sv.robot, tool.pose(L), q[-1])
        if end is not None and end != branch:
            raise Stop(L, q[-1], "singular", f"the closed-form branch changed from {branch} to {end} on the way")
    fit = KnotFit(q_knots=q, sigma_min=np.array([k.sigma for k in knots]), branch=branch,
                  max_deviation=(float(pos.max()), float(rot.max())))
    return CartesianPath(s, _coefficients(knots), tool=tool, robot=sv.robot, frame=sv.frame, tolerance=tolerance, fit=fit)


def _walked(sv: PathSolver, q0: np.ndarray, locate: float) -> list[Knot]:
    """Knots from ``q0`` to the path's end by continuation (step 1) through the planned knots: the tool
    path's breaks, each piece cut into steps of at most ``_INITIAL_STEP``."""
    tool = sv.tool
    L = tool.length
    first = solve_knots(sv, np.array([0.0]), q0[None])[0]
    if first.sigma < sv.singular:
        raise Stop(0.0, q0, "singular", f"smallest singular value of the weighted Jacobian {first.sigma:.4g} "
                                        f"m/rad < singular_tolerance {sv.singular:g} at the start")
    planned = [0.0]
    for a, b in zip(tool.breaks[:-1], tool.breaks[1:]):
        n = max(1, int(np.ceil((b - a) / _INITIAL_STEP)))
        planned.extend((a + (b - a) * np.arange(1, n + 1) / n).tolist())
    planned[-1] = L
    knots = [first]
    for target in planned[1:]:
        knots.extend(continue_to(sv, knots[-1], target, locate))
    return knots


def _refined(sv: PathSolver, knots: list[Knot], tolerance: float,
             locate: float) -> tuple[list[Knot], np.ndarray, np.ndarray]:
    """The tolerance rule (step 2): intervals halved until every one passes its check points; the knots and
    the last round's tcp deviations (position [m], rotation [rad]) at the check points."""
    for _ in range(60):
        s = np.array([k.s for k in knots])
        coefs = _coefficients(knots)
        h = np.diff(s)
        bad, pos, rot, qc, sc, sig_all = _failing_intervals(sv, knots, s, h, coefs, tolerance, locate)
        if not bad.any():
            return knots, pos, rot
        _stop_where_too_short(sv, knots, bad, h, qc, sc, sig_all, locate)
        knots = _bisected(sv, knots, bad, s, h, coefs, locate)
    # 60 halvings of every interval is far below `locate`
    raise TrajectoryError("the tolerance rule did not converge in 60 refinement rounds")  # pragma: no cover


def _failing_intervals(sv: PathSolver, knots: list[Knot], s: np.ndarray, h: np.ndarray, coefs: np.ndarray,
                       tolerance: float, locate: float) -> tuple[np.ndarray, ...]:
    """Which intervals fail their check points (too far from the tool path, σ_min changing by more than 2,
    outside the joint limits, or singular): (bad (K,), pos, rot, q, s, σ_min at the check points and ends).

    Raises:
        Stop: a check point is singular on an interval already as short as ``locate``.
    """
    sc = s[:-1, None] + h[:, None] * _CHECKS
    qc = _quintic_values(coefs, h[:, None] * _CHECKS)  # (K, 3, n)
    K, C, n = qc.shape
    flat = qc.reshape(-1, n)
    ref = sv.tool.pose(sc.reshape(-1))
    F = np.asarray(sv.robot.fk(flat, frame=sv.frame))
    pos = np.linalg.norm(F[:, :3, 3] - ref[:, :3, 3], axis=1).reshape(K, C)
    rot = _so3.angle(np.swapaxes(ref[:, :3, :3], 1, 2) @ F[:, :3, :3]).reshape(K, C)
    sig_c = np.linalg.svd(sv.jacobian(flat), compute_uv=False)[:, -1].reshape(K, C)
    sig_k = np.array([k.sigma for k in knots])
    sig_all = np.concatenate([sig_k[:-1, None], sig_c, sig_k[1:, None]], axis=1)
    rot_tol = 0.5 * tolerance / sv.w
    bad = (pos.max(axis=1) > 0.5 * tolerance) | (rot.max(axis=1) > rot_tol) | \
          (sig_all.max(axis=1) > 2.0 * sig_all.min(axis=1)) | (sv.outside(flat).reshape(K, C).max(axis=1) > 1e-9)
    if np.any(sig_c < sv.singular):
        i, c = np.unravel_index(int(np.argmin(sig_c)), sig_c.shape)
        if h[i] <= locate:
            raise Stop(float(sc[i, c]), knots[i].q, "singular",
                       f"smallest singular value of the weighted Jacobian {sig_c[i, c]:.4g} m/rad "
                       f"< singular_tolerance {sv.singular:g}")
        bad[i] = True
    return bad, pos, rot, qc, sc, sig_all


def _stop_where_too_short(sv: PathSolver, knots: list[Knot], bad: np.ndarray, h: np.ndarray, qc: np.ndarray,
                          sc: np.ndarray, sig_all: np.ndarray, locate: float) -> None:
    """Raise :class:`Stop` at the first failing interval already as short as ``locate`` (a joint limit
    between knots, or a joint path that bends too fast); nothing when every failing one can be halved."""
    idx = np.flatnonzero(bad)
    tiny = idx[h[idx] <= locate]
    if tiny.size:
        i = int(tiny[0])
        if sv.outside(qc[i]).max() > 1e-9:
            j = int(np.argmax(np.maximum(sv.lower - qc[i], qc[i] - sv.upper).max(axis=0)))
            raise Stop(float(sc[i, 1]), knots[i].q, "limit",
                       f"joint {sv.robot.joint_names[j]} would pass its limit between knots")
        raise Stop(float(sc[i, 1]), knots[i].q, "singular",
                   f"the tolerance cannot be met: the joint path bends too fast (σ_min {sig_all[i].min():.3g} m/rad)")


def _bisected(sv: PathSolver, knots: list[Knot], bad: np.ndarray, s: np.ndarray, h: np.ndarray, coefs: np.ndarray,
              locate: float) -> list[Knot]:
    """The knots with a new one at the middle of every failing interval: solved in one batch from the
    interpolant's prediction, or by continuation across the interval where the batch fails."""
    idx = np.flatnonzero(bad)
    mids = s[idx] + 0.5 * h[idx]
    pred = _quintic_values(coefs[idx], (0.5 * h[idx])[:, None])[:, 0]
    q_new, ok = sv.newton(pred, sv.tool.pose(mids))
    ok &= np.abs(q_new - pred).max(axis=1) <= MAX_CORRECTION
    ok &= sv.outside(q_new) <= 1e-9
    new = solve_knots(sv, mids[ok], q_new[ok]) if ok.any() else []
    new = [k for k in new if k.sigma >= sv.singular]
    inserted = {round(k.s, 15): k for k in new}
    result = []
    for i, k in enumerate(knots):
        result.append(k)
        if i < len(knots) - 1 and bad[i]:
            mid = inserted.get(round(s[i] + 0.5 * h[i], 15))
            if mid is not None:
                result.append(mid)
            else:  # the batch could not solve it: walk the interval step by step (raises where it fails)
                result.extend(continue_to(sv, k, float(s[i] + 0.5 * h[i]), locate))
    return result


def _coefficients(knots: list[Knot]) -> np.ndarray:
    s = np.array([k.s for k in knots])
    a = (np.array([k.q for k in knots[:-1]]), np.array([k.dq for k in knots[:-1]]), np.array([k.ddq for k in knots[:-1]]))
    b = (np.array([k.q for k in knots[1:]]), np.array([k.dq_l for k in knots[1:]]), np.array([k.ddq_l for k in knots[1:]]))
    return quintic_hermite_coefficients(s[1:] - s[:-1], *a, *b)


def joint_image(robot: Robot, path: ToolPath, *, tolerance: float = DEFAULT_TOLERANCE, q_start: ArrayLike | None = None,
                frame: str = "tcp", singular_tolerance: float = DEFAULT_SINGULAR_TOLERANCE,
                locate: float = 1e-5) -> CartesianPath:
    """The joint path that makes the tcp follow ``path`` within ``tolerance`` (module docstring).

    Args:
        robot: a :class:`pinarms.robots.Robot` (``fk``, ``jacobian``, ``lower``/``upper``, ``ik`` or
            ``ik_branches``, ``ik_failure_reason``).
        path: the :class:`pinarms.planning.ToolPath` (tcp → base poses, m).
        tolerance: largest tcp position deviation [m] (default 0.1 mm); the orientation's is
            ``tolerance / path.weight`` rad.
        q_start: configuration (nq,) selecting the branch: the path starts at the IK solution
            nearest to it (itself if its tcp is at the start pose). Default: each closed-form
            solution at the start in the robot's order until one follows the whole path (if
            none does, the error of the one that got farthest is raised, ties to the first);
            numerical IK for other arms.
        frame: the robot frame that follows the path (default the tcp).
        singular_tolerance: smallest singular value [m/rad] of the weighted Jacobian
            ``[J_v; w J_ω]`` allowed on the way (default 1e-4: closer to a singularity a joint
            turning 1 rad moves the tool less than 0.1 mm in its weakest direction; on an
            AUBO-i3 passing through a wrist singularity this stops the path about 5 mm before it).
        locate: arc length [m] to which a failure is located (10 µm).

    Raises:
        SingularityOnPath, JointLimitOnPath, UnreachableOnPath: the arm cannot follow the path on
            one branch; ``s``, ``pose`` and ``reason`` say where and why.
        TrajectoryError: bad arguments.
    """
    if not isinstance(path, ToolPath):
        raise TrajectoryError(f"path must be a planning.ToolPath, got {type(path).__name__}")
    tol = _positive(tolerance, "tolerance [m]")
    if tol < MIN_TOLERANCE:
        raise TrajectoryError(f"tolerance {tol:g} m is below {MIN_TOLERANCE:g} m (1 nm): give 1e-9 m or more")
    sing = _positive(singular_tolerance, "singular_tolerance [m/rad]")
    loc = _positive(locate, "locate [m]")
    nq = int(robot.nq)
    q0 = None if q_start is None else per_joint(q_start, nq, "q_start")
    sv = PathSolver(robot, path, frame, sing)
    pose0 = path.pose(0.0)
    try:
        starts = _starts(robot, pose0, q0)
    except UnreachableTarget as exc:
        reason = robot.ik_failure_reason(pose0) if hasattr(robot, "ik_failure_reason") else str(exc)
        raise UnreachableOnPath(f"robot '{robot.name}' cannot reach the start of the path (s = 0): {reason}",
                                s=0.0, pose=pose0, reason=str(reason)) from exc
    if not starts:
        reason = robot.ik_failure_reason(pose0) or "no IK solution"
        raise UnreachableOnPath(f"robot '{robot.name}' cannot reach the start of the path (s = 0): {reason}",
                                s=0.0, pose=pose0, reason=reason)
    farthest: Stop | None = None
    for q in starts:
        try:
            return _build(sv, np.asarray(q, dtype=float), tol, loc)
        except Stop as stop:
            if farthest is None or stop.s > farthest.s + loc:
                farthest = stop
    assert farthest is not None
    raise _failure(sv, farthest.s, farthest.q_last, farthest.kind, farthest.detail)


def cartesian_path(robot: Robot, poses: ArrayLike, *, blend: ArrayLike = 0.0, weight: float = DEFAULT_WEIGHT,
                   stops: Iterable[int] = (), tolerance: float = DEFAULT_TOLERANCE, q_start: ArrayLike | None = None,
                   frame: str = "tcp", singular_tolerance: float = DEFAULT_SINGULAR_TOLERANCE) -> CartesianPath:
    """Straight tcp lines through ``poses`` (blends of radius ``blend`` at the corners), as joints.

    :func:`pinarms.planning.tool_path` builds the geometry (position linear, orientation by SLERP,
    arc length with ``weight`` m/rad), :func:`joint_image` its joint-space image on one IK
    branch within ``tolerance`` (default 0.1 mm). Time it with :func:`pinarms.optim.time_optimal`.

    Args:
        robot: a :class:`pinarms.robots.Robot`.
        poses: (N, 4, 4) tcp → base poses [m].
        blend, weight, stops: see :func:`pinarms.planning.tool_path`.
        tolerance, q_start, frame, singular_tolerance: see :func:`joint_image`.
    """
    return joint_image(robot, tool_path(poses, blend=blend, weight=weight, stops=stops), tolerance=tolerance,
                       q_start=q_start, frame=frame, singular_tolerance=singular_tolerance)


def _positive(value: Any, what: str) -> float:
    arr = finite_array(value, what)
    if arr.ndim != 0 or float(arr) <= 0.0:
        raise TrajectoryError(f"{what} must be a positive number, got {value!r}")
    return float(arr)
