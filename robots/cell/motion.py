"""Check the arms of a cell moving together, continuously in time.

Each arm follows its own joint trajectory with its own time offset (and, for a cyclic
schedule, its own period); arms without a motion hold still. :func:`check_motion` samples
the common time window and proves, between the samples, what it reports.

The time-step rule
------------------
For each arm, the speed of every point of its collision geometry is at most
``v(t) = Σ_j |q̇_j(t)| · ℓ_j``, with ``ℓ_j`` the *lever* of joint ``j`` (1 for a prismatic
joint; for a revolute joint, a bound of the distance from its origin to any point of the
geometry it carries, from the joint offsets, strokes and bounding spheres downstream, see
:func:`joint_levers`). Two bodies approach each other at most at ``V(t) = 2 max_arms v(t)``.
Over a short step ``h`` the speed cannot exceed its larger end value by more than
``A h / 2`` (``A = Σ_j max|q̈_j| ℓ_j``, from the trajectory's exact acceleration peaks), nor
``2 Σ_j max|q̇_j| ℓ_j`` (the exact velocity peaks). The samples are placed so that the
*approach budget* ``∫ V dt`` between two consecutive samples is at most ``margin``:
dense where the arms move fast, sparse where they dwell. On an interval ``[a, b]`` with
budget ``B`` the distance of every pair then stays at least ``(d_a + d_b − B) / 2``, where
``d`` is the smallest distance over the checked pairs at a sample (coal, exact).

Each sample is first screened by Pinocchio's C++ broad phase with a safety distance
``required + margin``: a sample farther than that from every contact has
``d ≥ required + margin`` and needs no exact distance (its interval bound is then at least
``required``). The others get coal's exact smallest distance. An interval whose bound is
below its target (the required clearance, or 0 where a sample is already closer than it)
while its ends are clear is split in halves (same formula, half the budget) until it is
proven or a sample shows the violation, at most 6 times (budget ``margin / 64``); an interval
still unproven then (a distance within ``margin / 128`` of the target) counts as not clear.
Nothing thinner than ``margin`` is missed, and a reported "collision-free" or "clear" is a
proof, not a sampling guess.

The first contact (a sample with distance ≤ 0) is located by bisection to within 1e-6 s
and reported with its pair and depth.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Mapping

import numpy as np
import pinocchio as pin

from ..errors import InvalidInput
from .collision import _margin, exact_min_distance
from .pairs import CollisionPair

if TYPE_CHECKING:  # pragma: no cover
    from .cell import Cell

__all__ = ["ArmMotion", "Contact", "MotionCheck", "check_motion", "joint_levers", "motion_window", "sample_motions"]

#: Largest number of halvings of one interval (its approach budget then 1/64 of the margin);
#: an interval still unproven is reported as not clear (never as clear).
MAX_SPLITS = 6
#: Largest number of samples of one check.
MAX_SAMPLES = 2_000_000
#: Largest magnitude of a time (offset, period, window end, trajectory time) [s]: about 11.6
#: days; beyond it a double cannot resolve the bisection's 1e-6 s.
MAX_TIME = 1e6
#: Largest margin or clearance a check takes [m].
MAX_DISTANCE = 1e3
#: Largest number of bisection steps locating the first contact (1e-6 s over MAX_TIME needs 41).
MAX_BISECTIONS = 64


def _time(value: Any, what: str) -> float:
    ok = isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool)
    t = float(value) if ok else float("nan")
    if not (math.isfinite(t) and abs(t) <= MAX_TIME):
        raise InvalidInput(f"{what} must be a finite time within ±{MAX_TIME:.0e} s, got {value!r}")
    return t


@dataclass(frozen=True)
class ArmMotion:
    """One arm's motion in a cell.

    Attributes:
        arm: the arm's name in the cell.
        trajectory: its joint trajectory (a :class:`pinarms.planning.Trajectory`, or any
            object with ``start_time``, ``end_time`` [s], ``sample(t) -> (q, qd, ...)`` and
            ``peaks().velocity``), in the arm's own joint order.
        offset: cell time [s] at which the trajectory's ``start_time`` is played.
        period: if given [s] (≥ the trajectory's duration), the motion repeats every
            ``period`` s (a cycle); between the trajectory's end and the next start the
            arm holds its last position.
    """

    arm: str
    trajectory: Any
    offset: float = 0.0
    period: float | None = None

    def local_time(self, t: np.ndarray) -> np.ndarray:
        """The trajectory's own time for cell times ``t`` (held at its ends)."""
        traj = self.trajectory
        tau = np.asarray(t, dtype=float) - self.offset
        if self.period is not None:
            tau = np.mod(tau, self.period)
        return np.clip(tau + traj.start_time, traj.start_time, traj.end_time)


@dataclass(frozen=True, eq=False)
class Contact:
    """Where a motion first touches.

    Attributes:
        time: cell time [s] (the first instant found in contact, within ``dt / 1024``).
        pair: the pair in contact.
        depth: penetration depth there [m] (≥ 0).
        q: the cell configuration at that time ``(nq,)``.
    """

    time: float
    pair: CollisionPair
    depth: float
    q: np.ndarray


@dataclass(frozen=True, eq=False)
class MotionCheck:
    """What :func:`check_motion` found.

    Attributes:
        collision_free: proven: no contact anywhere in the window.
        clear: proven: every distance stays ≥ ``required`` [m] in the window.
        first_contact: the first contact (:class:`Contact`) or ``None``.
        max_depth: the largest penetration depth seen at a sample [m] (0 when none).
        min_clearance: the smallest distance at the samples [m] (negative: overlap), its
            time [s] and pair (``min_clearance_time``, ``min_clearance_pair``).
        lower_bound: when no contact is found, a proven lower bound of the distance over
            the whole window [m]; with a contact, the deepest sample.
        times: ``(M,)`` sample times [s] (refinement samples included, sorted);
            ``clearance``: ``(M,)`` smallest distance at each [m], exact where ``exact``
            ``(M,)`` is true, else the screen's bound ``required + margin`` (the sample is at
            least that far from every contact); ``pair_index``: ``(M,)`` index into
            ``pairs`` of the closest pair (−1 where not exact).
        min_clearance: the smallest value of ``clearance``: an exact distance when
            :attr:`min_clearance_is_exact` (then ``min_clearance_pair`` is its pair), else
            — no sample came within ``required + margin`` of a contact and ``curve`` was
            off — the screening *bound* ``required + margin`` and ``min_clearance_pair`` is
            ``None``. Quote :attr:`min_sample_distance` for a distance and
            :attr:`lower_bound` for a proven bound.
        dt: the finest time step [s] (at the global speed bound); ``speed_bound``: that
            bound ``V`` [m/s];
            ``margin`` and ``required`` [m]; ``window``: ``(t_start, t_end)`` [s].
        pairs: the pairs looked at (:meth:`Cell.pairs_for` at ``required + margin``); the
            pairs left out are proven farther than that in every configuration.

    ``repr`` is :meth:`summary`.
    """

    collision_free: bool
    clear: bool
    first_contact: Contact | None
    max_depth: float
    min_clearance: float
    min_clearance_time: float
    min_clearance_pair: CollisionPair | None
    lower_bound: float
    times: np.ndarray
    clearance: np.ndarray
    pair_index: np.ndarray
    exact: np.ndarray
    dt: float
    speed_bound: float
    margin: float
    required: float
    window: tuple[float, float]
    pairs: tuple[CollisionPair, ...]

    @property
    def n_samples(self) -> int:
        """Number of configurations whose distance was computed."""
        return int(self.times.size)

    @property
    def min_clearance_is_exact(self) -> bool:
        """Whether :attr:`min_clearance` is an exact distance (else the screening bound)."""
        return self.min_clearance_pair is not None

    @property
    def min_sample_distance(self) -> float:
        """The smallest exact distance at a sample [m] (coal); ``nan`` when every sample was screened clear."""
        d = self.clearance[self.exact]
        return float(d.min()) if d.size else float("nan")

    @property
    def screening_bound(self) -> float:
        """The screen's distance ``required + margin`` [m]: a sample not computed exactly is at least this far."""
        return self.required + self.margin

    def __repr__(self) -> str:
        return f"MotionCheck({self.summary()})"

    @property
    def in_contact(self) -> np.ndarray:
        """``(M,)`` bool: the samples in contact (distance ≤ 0)."""
        return self.clearance <= 0.0

    def summary(self) -> str:
        """One line: verdict, first contact or minimum clearance, samples and step."""
        if self.first_contact is not None:
            c = self.first_contact
            head = f"contact at t = {c.time:.4f} s: {c.pair} (depth {c.depth * 1e3:.1f} mm)"
        elif self.min_clearance_pair is None:
            head = (f"{'clear' if self.clear else 'NOT proven clear'}: every sample at least {self.min_clearance * 1e3:.1f} mm"
                    f" (screening bound), proven lower bound {self.lower_bound * 1e3:.1f} mm")
        else:
            head = (
                f"{'clear' if self.clear else 'NOT proven clear'}: smallest sampled distance {self.min_clearance * 1e3:.1f} mm"
                f" at t = {self.min_clearance_time:.4f} s ({self.min_clearance_pair}), proven lower bound "
                f"{self.lower_bound * 1e3:.1f} mm"
            )
        return f"{head}; {self.n_samples} samples, dt = {self.dt * 1e3:.3f} ms, speed bound {self.speed_bound:.2f} m/s"


# ------------------------------------------------------------------- speed bound
def joint_levers(cell: "Cell") -> np.ndarray:
    """``(nq,)`` levers ``ℓ`` [m per rad, or 1 for prismatic]: point speed ≤ ``Σ |q̇_c| ℓ_c``.

    See the module doc; a mimic joint adds ``|scale| ×`` its own lever to its master's.
    """
    cached = getattr(cell, "_levers", None)
    if cached is not None:
        return cached
    model, gm = cell.model, cell.collision_model
    data = model.createData()
    pin.forwardKinematics(model, data, pin.neutral(model))
    n = model.njoints
    revolute = np.zeros(n, dtype=bool)
    scale = np.ones(n)
    for i in range(1, n):
        jm = model.joints[i]
        s = jm.extract().scaling if "Mimic" in jm.shortname() else 1.0
        scale[i] = s
        motion = np.array(data.joints[i].S).reshape(6, -1)[:, 0]
        revolute[i] = np.linalg.norm(motion[3:]) > 1e-12
    stroke = np.zeros(n)
    lo, hi = model.lowerPositionLimit, model.upperPositionLimit
    for i in range(1, n):
        if not revolute[i]:
            iq = model.joints[i].idx_q
            stroke[i] = abs(scale[i]) * max(abs(lo[iq]), abs(hi[iq]))
    reach = np.zeros(n)  # bound of |point − origin of joint i| over the geometry joint i carries
    for g in gm.geometryObjects:
        g.geometry.computeLocalAABB()
        lo_g, hi_g = np.asarray(g.geometry.aabb_local.min_), np.asarray(g.geometry.aabb_local.max_)
        own = float(np.linalg.norm(g.placement.act((lo_g + hi_g) / 2.0))) + float(np.linalg.norm((hi_g - lo_g) / 2.0))
        j, acc = int(g.parentJoint), own
        while j > 0:
            reach[j] = max(reach[j], acc)
            acc += float(np.linalg.norm(model.jointPlacements[j].translation)) + stroke[j]
            j = model.parents[j]
    levers = np.zeros(cell.nq)
    for i in range(1, n):
        c = model.joints[i].idx_v
        levers[c] += abs(scale[i]) * (reach[i] if revolute[i] else 1.0)
    cell._levers = levers
    return levers


def _peak_speed(traj: Any, nq: int, what: str) -> np.ndarray:
    peaks = getattr(traj, "peaks", None)
    if callable(peaks):
        v = np.asarray(peaks().velocity, dtype=float)
    else:
        t = np.linspace(traj.start_time, traj.end_time, 4001)
        v = np.abs(np.asarray(traj.sample(t)[1], dtype=float)).max(axis=0) * 1.05
    if v.shape != (nq,) or not np.all(np.isfinite(v)):
        raise InvalidInput(f"{what}: peak joint speeds must be {nq} finite numbers, got {v!r}")
    return v


# ------------------------------------------------------------------ inputs
def _motions(cell: "Cell", motions: Any) -> list[ArmMotion]:
    if isinstance(motions, ArmMotion):
        motions = [motions]
    if isinstance(motions, Mapping):
        out = []
        for arm, value in motions.items():
            if isinstance(value, tuple):
                out.append(ArmMotion(arm, *value))
            else:
                out.append(ArmMotion(arm, value))
        motions = out
    motions = list(motions)
    if not motions:
        raise InvalidInput("check_motion needs at least one ArmMotion")
    seen = set()
    for m in motions:
        if not isinstance(m, ArmMotion):
            raise InvalidInput(f"motions must be ArmMotion objects or {{arm: trajectory}}, got {type(m).__name__}")
        arm = cell.arm(m.arm)
        if m.arm in seen:
            raise InvalidInput(f"arm {m.arm!r} has two motions; give each arm one trajectory")
        seen.add(m.arm)
        traj = m.trajectory
        for attr in ("start_time", "end_time", "sample"):
            if not hasattr(traj, attr):
                raise InvalidInput(f"the trajectory of arm {m.arm!r} has no {attr!r}: pass a pinarms.planning.Trajectory")
        n = np.asarray(traj.sample(traj.start_time)[0]).shape
        if n != (arm.nq,):
            raise InvalidInput(f"the trajectory of arm {m.arm!r} has {n[0] if n else 0} joints, the arm {arm.nq}")
        _time(m.offset, f"offset of arm {m.arm!r}")
        start = _time(traj.start_time, f"start_time of the trajectory of arm {m.arm!r}")
        end = _time(traj.end_time, f"end_time of the trajectory of arm {m.arm!r}")
        if end < start:
            raise InvalidInput(f"the trajectory of arm {m.arm!r} ends ({end!r} s) before it starts ({start!r} s)")
        if m.period is not None:
            _time(m.period, f"period of arm {m.arm!r}")
            duration = traj.end_time - traj.start_time
            if not (math.isfinite(float(m.period)) and float(m.period) >= duration - 1e-12 and m.period > 0):
                raise InvalidInput(
                    f"period of arm {m.arm!r} must be at least the trajectory's duration {duration:.6g} s, got {m.period!r}"
                )
    return motions


def configurations(cell: "Cell", motions: list[ArmMotion], times: np.ndarray, hold: np.ndarray) -> np.ndarray:
    """Cell configurations ``(M, nq)`` at cell ``times`` (arms without a motion at ``hold``)."""
    Q = np.tile(hold, (times.size, 1))
    for m in motions:
        arm = cell.arm(m.arm)
        Q[:, arm.q_slice] = np.asarray(m.trajectory.sample(m.local_time(times))[0], dtype=float).reshape(times.size, -1)
        if not np.isfinite(Q[:, arm.q_slice]).all():
            bad = times[np.flatnonzero(~np.isfinite(Q[:, arm.q_slice]).all(axis=1))[0]]
            raise InvalidInput(f"the trajectory of arm {m.arm!r} gives non-finite joint values at t = {bad!r} s")
    return Q


def motion_window(motions: list[ArmMotion]) -> tuple[float, float]:
    """Default time window [s]: earliest start to latest end, or ``(0, longest period)`` if a motion repeats."""
    if any(m.period is not None for m in motions):
        return (0.0, max(float(m.period or (m.trajectory.end_time - m.trajectory.start_time)) for m in motions))
    return (
        min(float(m.offset) for m in motions),
        max(float(m.offset) + m.trajectory.end_time - m.trajectory.start_time for m in motions),
    )


def sample_motions(cell: "Cell", motions: Any, *, hz: float = 100.0, window: tuple[float, float] | None = None,
                   hold: Any = None) -> tuple[np.ndarray, np.ndarray]:
    """The arms' motions sampled together: times ``(M,)`` [s] and cell configurations ``(M, nq)``.

    ``hz`` samples per second over ``window`` (default :func:`motion_window`), its end included.
    """
    motions = _motions(cell, motions)
    if not (isinstance(hz, (int, float)) and math.isfinite(hz) and hz > 0):
        raise InvalidInput(f"hz must be a positive sampling rate in 1/s, got {hz!r}")
    w0, w1 = motion_window(motions) if window is None else (window[0], window[1])
    t0, t1 = _time(w0, "window start"), _time(w1, "window end")
    if t1 < t0:
        raise InvalidInput(f"window must be (t_start, t_end) with t_end >= t_start, got {window!r}")
    n = max(2, int(math.ceil((t1 - t0) * hz)) + 1)
    if n > MAX_SAMPLES:
        raise InvalidInput(f"{n} samples at {hz!r} Hz over {t1 - t0:.3g} s: at most {MAX_SAMPLES}; lower hz or the window")
    times = np.linspace(t0, t1, n)
    hold_q = cell.neutral if hold is None else cell.robot.check_q(hold)[0][0]
    return times, configurations(cell, motions, times, hold_q)


# ------------------------------------------------------------------ the check
def _speed_profile(cell: "Cell", motions: list[ArmMotion], grid: np.ndarray) -> tuple[np.ndarray, float]:
    """Bound of the approach speed ``V`` [m/s] on each cell of ``grid`` (module doc), and the global bound."""
    levers = joint_levers(cell)
    h = np.diff(grid)
    per_arm = []
    global_v = 0.0
    for m in motions:
        arm = cell.arm(m.arm)
        lev = levers[arm.q_slice]
        peak_v = _peak_speed(m.trajectory, arm.nq, f"trajectory of arm {m.arm!r}")
        peaks = getattr(m.trajectory, "peaks", None)
        peak_a = np.asarray(peaks().acceleration, dtype=float) if callable(peaks) else None
        v_cap = float(peak_v @ lev)
        global_v = max(global_v, v_cap)
        qd = np.asarray(m.trajectory.sample(m.local_time(grid))[1], dtype=float).reshape(grid.size, -1)
        v = np.abs(qd) @ lev
        if peak_a is None or not np.all(np.isfinite(peak_a)):
            cell_v = np.full(h.size, v_cap)
        else:
            A = float(np.abs(peak_a) @ lev)
            cell_v = np.minimum(np.maximum(v[:-1], v[1:]) + A * h / 2.0, v_cap)
        if True:
            # a cell holding the trajectory's end (outside [offset, offset + duration]) has v = 0 at
            # both ends and may still straddle a restart: keep the cap where the local time jumps
            tau = m.local_time(grid)
            jump = np.abs(np.diff(tau) - h) > 1e-9 * np.maximum(1.0, h)
            moving = (tau[:-1] > m.trajectory.start_time) | (tau[1:] > m.trajectory.start_time)
            cell_v = np.where(jump & moving, v_cap, cell_v)
        per_arm.append(cell_v)
    V = 2.0 * np.max(np.vstack(per_arm), axis=0) if per_arm else np.zeros(h.size)
    return V, 2.0 * global_v


def check_motion(
    cell: "Cell",
    motions: Any,
    *,
    margin: float = 0.01,
    clearance: float = 0.0,
    window: tuple[float, float] | None = None,
    hold: Any = None,
    curve: bool = False,
) -> MotionCheck:
    """Check the arms' motions together, continuously in time (module doc: the rule).

    Args:
        motions: :class:`ArmMotion` objects, or ``{arm: trajectory}`` /
            ``{arm: (trajectory, offset[, period])}``.
        margin: the thinnest gap or obstacle the check resolves [m] (sets the time step).
        clearance: the distance every pair must keep [m] (``clear`` tells if proven).
        window: ``(t_start, t_end)`` [s]; default: from the earliest start to the latest
            end of the motions, or ``(0, longest period)`` when a motion is periodic.
        hold: cell configuration ``(nq,)`` of the arms without a motion (default neutral).
        curve: compute the exact smallest distance at every sample (for a clearance-over-
            time plot) instead of only at the samples the screen flags.

    Raises:
        InvalidInput: an unknown arm, a trajectory of the wrong width, bad numbers, or a
            window that would need more than 2 000 000 samples.
    """
    margin = _margin(margin)
    if margin <= 0.0 or margin > MAX_DISTANCE:
        raise InvalidInput(f"margin must be > 0 m and at most {MAX_DISTANCE:g} m: it sets the time step, got {margin!r}")
    required = _margin(clearance)
    if required > MAX_DISTANCE:
        raise InvalidInput(f"clearance must be at most {MAX_DISTANCE:g} m, got {clearance!r}")
    motions = _motions(cell, motions)
    hold_q = cell.neutral if hold is None else cell.robot.check_q(hold)[0][0]
    if window is None:
        window = motion_window(motions)
    try:
        w0, w1 = window
    except (TypeError, ValueError):
        raise InvalidInput(f"window must be (t_start, t_end) [s], got {window!r}") from None
    t0, t1 = _time(w0, "window start"), _time(w1, "window end")
    if t1 < t0:
        raise InvalidInput(f"window must be (t_start, t_end) with t_end >= t_start, got {window!r}")

    # fine grid at the global bound's step, then samples every `margin` of approach budget
    _, V_global = _speed_profile(cell, motions, np.array([t0, max(t1, t0 + 1e-9)]))
    if V_global <= 0.0 or t1 == t0:
        grid = np.array([t0]) if t1 == t0 else np.array([t0, t1])
        budget = np.zeros(grid.size)
        dt = max(t1 - t0, 0.0)
    else:
        dt = margin / V_global
        n = int(math.ceil((t1 - t0) / dt))
        if n + 1 > MAX_SAMPLES:
            raise InvalidInput(
                f"the window of {t1 - t0:.3g} s needs {n + 1} samples at dt = {dt:.3g} s (speed bound "
                f"{V_global:.3g} m/s); check a shorter window or a larger margin (at most {MAX_SAMPLES} samples)"
            )
        grid = np.linspace(t0, t1, n + 1)
        V, _ = _speed_profile(cell, motions, grid)
        budget = np.concatenate([[0.0], np.cumsum(V * np.diff(grid))])
    keep = [0]
    for i in range(1, grid.size):
        if budget[i] - budget[keep[-1]] > margin * (1.0 + 1e-12):
            keep.append(i - 1)
    if keep[-1] != grid.size - 1:
        keep.append(grid.size - 1)
    idx = np.array(sorted(set(keep)), dtype=int)
    times = grid[idx]

    def budget_at(t: float) -> float:
        return float(np.interp(t, grid, budget))

    Q = configurations(cell, motions, times, hold_q)
    screen = required + margin
    # every pair not proven farther than the screen distance (Cell.pairs_for): the pairs left
    # out keep a distance above `screen` >= `required` in every configuration
    n_pairs = cell._n_for(screen + 1e-6)
    pairs = cell._candidates[:n_pairs]
    left_out = cell._reach_bounds[n_pairs - len(cell.pairs):]
    exact = np.ones(times.size, dtype=bool) if curve else cell.in_collision(Q, margin=screen + 1e-6)
    d = np.full(times.size, screen)
    k = np.full(times.size, -1, dtype=int)
    if exact.any():
        de, ke, _, _ = exact_min_distance(cell, Q[exact], n=n_pairs)
        d[exact], k[exact] = de, ke

    samples_t, samples_d, samples_k, samples_x = list(times), list(d), list(k), list(exact)

    def evaluate(ts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        Qs = configurations(cell, motions, ts, hold_q)
        ds, ks, _, _ = exact_min_distance(cell, Qs, n=n_pairs)
        samples_t.extend(ts)
        samples_d.extend(ds)
        samples_k.extend(ks)
        samples_x.extend([True] * ts.size)
        return ds, ks

    # prove every interval: (d_a + d_b - B) / 2 reaches the target (the required clearance,
    # or 0 where a sample is already below it), else split it in halves; one level at a time,
    # all the midpoints of a level in one batched evaluation
    lower = float(d.min()) if d.size else np.inf
    unresolved = False
    level = [(times[i], times[i + 1], d[i], d[i + 1]) for i in range(times.size - 1)]
    depth = 0
    while level:
        split = []
        for ta, tb, da, db in level:
            low = min(da, db)
            if low <= 0.0:
                lower = min(lower, low)
                continue  # a sample in contact: reported below
            target = required if low >= required else 0.0
            bound = (da + db - (budget_at(tb) - budget_at(ta))) / 2.0
            if bound >= target:
                lower = min(lower, bound)
            elif depth >= MAX_SPLITS:
                unresolved = True
                lower = min(lower, bound)
            else:
                split.append((ta, tb, da, db))
        if not split:
            break
        mids = np.array([0.5 * (ta + tb) for ta, tb, _, _ in split])
        dm = evaluate(mids)[0]
        level = []
        for (ta, tb, da, db), tm, dmid in zip(split, mids, dm):
            level.append((ta, tm, da, dmid))
            level.append((tm, tb, dmid, db))
        depth += 1

    def collected():
        order = np.argsort(np.asarray(samples_t), kind="stable")
        return (np.asarray(samples_t)[order], np.asarray(samples_d)[order],
                np.asarray(samples_k, dtype=int)[order], np.asarray(samples_x, dtype=bool)[order])

    all_t, all_d, all_k, all_x = collected()
    first = None
    contact_idx = np.flatnonzero(all_d <= 0.0)
    if contact_idx.size:
        i = int(contact_idx[0])
        t_hit, d_hit, k_hit = all_t[i], all_d[i], all_k[i]
        if i > 0:  # bisect between the last clear sample and the first in contact
            ta, tb = all_t[i - 1], all_t[i]
            for _ in range(MAX_BISECTIONS):
                tm = 0.5 * (ta + tb)
                if tb - ta <= 1e-6 or not ta < tm < tb:
                    break
                dm, km = evaluate(np.array([tm]))
                if dm[0] <= 0.0:
                    tb, d_hit, k_hit = tm, dm[0], km[0]
                else:
                    ta = tm
            t_hit = tb
        first = Contact(
            time=float(t_hit),
            pair=pairs[int(k_hit)],
            depth=float(max(-d_hit, 0.0)),
            q=configurations(cell, motions, np.array([t_hit]), hold_q)[0],
        )
        all_t, all_d, all_k, all_x = collected()
    lower = min(lower, float(all_d.min()))
    if left_out.size:  # the pairs left out are proven at least this far apart
        lower = min(lower, float(left_out[0]))
    exact_d = np.where(all_x, all_d, np.inf)
    i_min = int(np.argmin(exact_d)) if np.isfinite(exact_d).any() else int(np.argmin(all_d))
    collision_free = first is None and lower > 0.0
    clear = first is None and lower >= required and not unresolved
    return MotionCheck(
        collision_free=bool(collision_free),
        clear=bool(clear),
        first_contact=first,
        max_depth=float(max(0.0, -all_d.min())),
        min_clearance=float(all_d[i_min]),
        min_clearance_time=float(all_t[i_min]),
        min_clearance_pair=pairs[int(all_k[i_min])] if all_k[i_min] >= 0 else None,
        lower_bound=float(lower),
        times=all_t,
        clearance=all_d,
        pair_index=all_k,
        exact=all_x,
        dt=float(dt),
        speed_bound=float(V_global),
        margin=margin,
        required=required,
        window=(t0, t1),
        pairs=pairs,
    )
