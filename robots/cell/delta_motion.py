"""The continuous check of a cell's delta pairs along the arms' motions: how fast a delta's bodies move, proven.

:func:`~.motion.check_motion` proves a motion of serial arms with a bound of how fast any point
of their links moves (joint levers, :mod:`.speed_bound`). A delta's rods and platform hang on
passive joints, so their speed is bounded here from the closed form, and the same Lipschitz
rule (:mod:`.ladder`) proves the delta's pairs (:mod:`.delta_pairs`) between the samples.

The speed bound
---------------
Let ``c_i`` be the exact peak speed of motor ``i`` over the delta's trajectory
(``peaks().velocity``), ``L`` the upper arm, ``l`` the forearm, ``E_i`` the elbows, ``p`` the
platform centre and ``n_i = (p + r e_i - E_i) / l`` the unit rod directions (rows of ``N``).
Each forearm keeps its length, so ``n_i · ṗ = n_i · Ė_i`` and ``|ṗ| ≤ L |c| / σ(N)``, with
``σ(N)`` the smallest singular value of ``N`` (zero at a parallel singularity). From a sample
at ``t_a`` with ``σ_a = σ(N(t_a))``, suppose ``σ ≥ σ_a / 2`` on ``[t_a, t_a + h]``: then
``|ṗ| ≤ P = 2 L |c| / σ_a``, and each row of ``N`` turns by at most ``(P + L max c) h / l``,
so ``σ`` drops by at most ``√3 (P + L max c) h / l`` (Weyl's inequality). A step ``h`` that
keeps this below ``σ_a / 2`` makes the supposition hold on the whole step (the first instant
it failed would contradict it). On such a step every point of
- an upper arm (within ``L + ρ_arm`` of its motor axis) moves at most at ``(L + ρ_arm) c_i``;
- a rod (a segment with ends at speeds ``≤ L c_i`` and ``≤ P``, and ``ρ_rod`` around it; its
  direction turns at most at ``(L c_i + P) / l``) at ``max(L c_i, P) + ρ_rod (L c_i + P) / l``;
- the platform and the tool (they translate; the tool turns about its own axis, which moves no
  point of its capsule) at ``P``; the base not at all.
Their largest is the delta's bound ``v``. Two bodies of the checked pairs approach at most at
``V``, the largest of: ``2 v`` (two bodies of one delta, if such pairs are checked), the sum of the
two largest ``v`` (two deltas), ``v + v_serial`` (a delta and a serial arm's link; ``v_serial`` the
largest ``Σ_j max|q̇_j| ℓ_j`` of the moving serial arms, :func:`~.speed_bound.joint_levers`), ``v``
(a fixture). A motion that gives its platform's speed bound (``platform_speed``: a platform path,
:class:`~pinarms.robots.delta.path_motion.PlatformPath`) has ``P`` from it and no ``σ`` rule.

The samples
-----------
No step is longer than ``margin / V`` or than the ``σ`` rule allows at its start (a motion that
nears a parallel singularity gets small steps; one that reaches it cannot be proven and is
refused). At each sample the smallest distance over the delta pairs
is exact below ``required + margin`` (coal), else a proven bound above it
(:meth:`~.delta_pairs.DeltaPairSet.bounded`). An interval whose bound
``(d_a + d_b − V h) / 2`` (:func:`~.ladder.interval_bound`) is below ``required`` while its
ends are not is halved, at most :data:`~.motion.MAX_SPLITS` times; still unproven, it is not
clear. The first contact is located by bisection to 1e-6 s.
"""

from __future__ import annotations

import numpy as np

from pinarms.errors import InvalidInput
from pinarms.robots.cell.delta_pairs import delta_pair_set
from pinarms.robots.cell.ladder import interval_bound
from pinarms.robots.cell.motion_report import Contact, MotionCheck
from pinarms.robots.cell.speed_bound import joint_levers, peak_speed
from pinarms.robots.cell.timeline import ArmMotion, configurations, motion_window
from pinarms.robots.delta import elbow_positions, forward_position
from pinarms.robots.delta.collision import PART_RADII

__all__ = ["delta_speed", "check_delta_pairs", "MAX_DELTA_SAMPLES"]

#: Most samples of one delta check before refinement (a motion near a parallel singularity needs tiny steps).
MAX_DELTA_SAMPLES = 200_000
_SPLITS = 6


def delta_speed(delta, theta, caps, platform: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """``(v, h_sigma)`` (each (M,)) at motor angles ``theta (M, 3)`` [rad] with motor speed caps ``caps (3,)``
    [rad/s]: the bound of every point's speed of the delta's bodies on a step from each sample, and the
    longest such step [s] (module doc); ``inf`` steps when the motors do not move. ``platform``: a proven
    bound of the platform's speed [m/s] given with the motion (a platform path's): used as ``P``, no ``σ``
    rule needed (infinite steps)."""
    g = delta.geometry
    th = np.atleast_2d(np.asarray(theta, dtype=float))
    c = np.asarray(caps, dtype=float)
    p = forward_position(g, th)
    rows = (p[:, None, :] + g.platform_radius * g.radial[None] - elbow_positions(g, th)) / g.forearm
    sigma = np.linalg.svd(rows, compute_uv=False)[:, -1]
    if not np.all(sigma > 0.0):
        raise InvalidInput(f"{delta.name}: the motion reaches a parallel singularity (smallest singular value of the "
                           "rod directions 0): its speed cannot be bounded")
    big_l, small_l, cmax = g.upper_arm, g.forearm, float(c.max())
    P = 2.0 * big_l * float(np.linalg.norm(c)) / sigma if platform is None else np.full(sigma.size, float(platform))
    arm = (big_l + PART_RADII["upper_arm"]) * cmax
    rod = np.maximum(big_l * cmax, P) + PART_RADII["rod"] * (big_l * cmax + P) / small_l
    v = np.maximum(np.maximum(arm, rod), P)
    with np.errstate(divide="ignore"):
        h = np.where(cmax > 0.0, 0.999 * sigma * small_l / (2.0 * np.sqrt(3.0) * (P + big_l * cmax)), np.inf)
    return v, (h if platform is None else np.full(sigma.size, np.inf))


def _caps(cell, motions: list[ArmMotion]) -> tuple[list[tuple[np.ndarray, float | None]], float]:
    """Per delta: its motor speed caps (3,) (0 without a motion) and its platform's proven speed bound when its
    trajectory gives one (``platform_speed``, :class:`~pinarms.robots.delta.path_motion.PlatformPath`), else None;
    and the serial arms' largest speed bound [m/s]."""
    levers = joint_levers(cell)
    by_arm = {m.arm: peak_speed(m.trajectory, cell.arm(m.arm).nq, f"the trajectory of arm {m.arm!r}") for m in motions}
    platform = {m.arm: getattr(m.trajectory, "platform_speed", None) for m in motions}
    caps = []
    for d in cell.deltas:
        v = by_arm.get(d.name)
        caps.append((np.zeros(3) if v is None else v[d.motor_cols - d.q_slice.start], platform.get(d.name)))
    names = {d.name for d in cell.deltas}
    serial = [float(v @ levers[cell.arm(a).q_slice]) for a, v in by_arm.items() if a not in names]
    return caps, max(serial, default=0.0)


def _step_rule(cell, motions, hold, times: np.ndarray, caps, v_serial: float, margin: float):
    """At each of ``times`` (M,): the approach speed bound ``V`` on a step from it [m/s] and the longest step [s]
    the rule allows there (``margin / V`` and every delta's ``σ`` step)."""
    Q = configurations(cell, motions, times, hold)
    v = np.zeros((len(cell.deltas), times.size))
    h = np.full(times.size, np.inf)
    for k, (d, (c, platform)) in enumerate(zip(cell.deltas, caps)):
        v[k], hd = delta_speed(d.delta, d.theta(Q), c, platform)
        h = np.minimum(h, hd)
    kinds = {p.kind for p in delta_pair_set(cell).pairs}
    top = np.sort(np.vstack([v, np.zeros((2, times.size))]), axis=0)
    # a delta's own bodies or two deltas: the two largest; a delta and a serial arm; a delta and a fixture
    speed = np.maximum.reduce([top[-1] + top[-2] if "self" in kinds or len(cell.deltas) > 1 else top[-1],
                               top[-1] + (v_serial if "arm-arm" in kinds else 0.0), top[-1]])
    if "self" in kinds:
        speed = np.maximum(speed, 2.0 * top[-1])
    with np.errstate(divide="ignore"):
        return speed, np.minimum(h, np.where(speed > 0.0, margin / speed, np.inf))


def _grid(cell, motions, hold, t0: float, t1: float, margin: float) -> tuple[np.ndarray, np.ndarray]:
    """Sample times (M,) from ``t0`` to ``t1`` and the approach speed bound (M - 1,) valid on each step.

    Starting from 64 even steps, every step longer than the rule allows at its start is cut into
    even pieces that are not (their starts evaluated together, in batches), until none is."""
    caps, v_serial = _caps(cell, motions)
    times = np.linspace(t0, t1, 65) if t1 > t0 else np.array([t0, t1])
    speed, step = _step_rule(cell, motions, hold, times, caps, v_serial, margin)
    while True:
        length = np.diff(times)
        over = length > step[:-1]
        if not over.any():
            return times, speed[:-1]
        pieces = np.where(over, np.ceil(length / np.maximum(step[:-1], 1e-300)), 1).astype(float)
        if times.size + pieces.sum() > MAX_DELTA_SAMPLES or not np.all(np.isfinite(pieces)):
            k = int(np.argmax(pieces))
            raise InvalidInput(f"the delta check of this motion needs more than {MAX_DELTA_SAMPLES} samples (steps of "
                               f"{step[k]:.3g} s near t = {times[k]:.4f} s): raise the margin, or keep the delta away "
                               "from a parallel singularity")
        new = np.concatenate([times[i] + length[i] * np.arange(1, int(pieces[i])) / pieces[i]
                              for i in np.flatnonzero(over)])
        s_new, h_new = _step_rule(cell, motions, hold, new, caps, v_serial, margin)
        order = np.argsort(np.concatenate([times, new]), kind="stable")
        times = np.concatenate([times, new])[order]
        speed, step = np.concatenate([speed, s_new])[order], np.concatenate([step, h_new])[order]


def check_delta_pairs(cell, motions: list[ArmMotion], hold: np.ndarray, window: tuple[float, float] | None,
                      margin: float, required: float) -> MotionCheck:
    """The continuous check of the cell's delta pairs along ``motions`` (module doc): a :class:`MotionCheck`
    whose ``pairs`` are :attr:`Cell.delta_pairs`."""
    dps = delta_pair_set(cell)
    t0, t1 = motion_window(motions) if window is None else window
    times, speeds = _grid(cell, motions, hold, float(t0), float(t1), margin)
    screen = required + margin
    value, exact, pair, _, _ = dps.bounded(configurations(cell, motions, times, hold), screen)
    T, D, E, K = list(times), list(value), list(exact), list(pair)
    open_ = [(a, a + 1, float(speeds[a] * (times[a + 1] - times[a])), speeds[a], 0) for a in range(len(times) - 1)]
    lower, proven_all, positive_all = np.inf, True, True
    while open_:   # level by level: the midpoints of every interval halved at a level in one batch
        split = []
        for a, b, budget, speed, level in open_:
            bound = float(interval_bound(D[a], D[b], budget))
            ends = min(D[a], D[b])
            if bound >= required and ends > 0.0:
                lower = min(lower, bound)
            elif ends <= 0.0 or ends < required or level >= _SPLITS:
                lower = min(lower, bound if ends > 0.0 else ends)
                proven_all = False
                positive_all &= bound > 0.0
            else:
                split.append((a, b, budget, speed, level))
        if not split:
            break
        mids = np.array([0.5 * (T[a] + T[b]) for a, b, *_ in split])
        v, e, k, _, _ = dps.bounded(configurations(cell, motions, mids, hold), screen)
        open_ = []
        for n, (a, b, budget, speed, level) in enumerate(split):
            T.append(float(mids[n])), D.append(float(v[n])), E.append(bool(e[n])), K.append(int(k[n]))
            m = len(T) - 1
            open_ += [(a, m, 0.5 * budget, speed, level + 1), (m, b, 0.5 * budget, speed, level + 1)]
    order = np.argsort(T, kind="stable")
    T, D, E, K = (np.asarray(x)[order] for x in (T, D, E, K))
    D, E, K = _exact_minimum(cell, motions, hold, T, D, E, K)
    return _report(cell, motions, hold, dps, (T, D, E, K), lower, proven_all, positive_all, speeds, times,
                   (float(t0), float(t1)), margin, required)


def _exact_minimum(cell, motions, hold, T, D, E, K):
    """Exact distances at the screened samples whose bound is below the smallest exact one, until none is: the
    smallest exact distance is then the true minimum over the samples (branch and bound)."""
    dps = delta_pair_set(cell)
    D, E, K = D.copy(), E.copy(), K.copy()
    while True:
        best = float(D[E].min()) if E.any() else np.inf
        need = np.flatnonzero(~E & (D < best))
        if np.isinf(best) and (~E).any():
            need = np.flatnonzero(~E & (D <= D[~E].min()))[:16]
        if not need.size:
            return D, E, K
        d, _, k, _, _ = dps.bounded(configurations(cell, motions, T[need], hold), np.inf)
        D[need], E[need], K[need] = d, True, k


def _report(cell, motions, hold, dps, samples, lower, proven_all, positive_all, speeds, times, window, margin,
            required) -> MotionCheck:
    T, D, E, K = samples
    touching = np.flatnonzero(E & (D <= 0.0))
    first = None
    if touching.size:
        first = _first_contact(cell, motions, hold, T, D, int(touching[0]))
    i = int(np.argmin(np.where(E, D, np.inf))) if E.any() else 0
    collision_free = first is None and positive_all
    clear = proven_all and first is None
    steps = np.diff(times)
    return MotionCheck(
        collision_free=bool(collision_free), clear=bool(clear), first_contact=first,
        max_depth=float(max(0.0, -D[E].min())) if E.any() else 0.0,
        min_clearance=float(D[i]) if E.any() else float("inf"), min_clearance_time=float(T[i]),
        min_clearance_pair=dps.pairs[int(K[i])] if E.any() and K[i] >= 0 else None,
        lower_bound=float(lower if first is None else min(lower, D[E].min())),
        times=T, clearance=D, pair_index=np.where(E, K, -1), exact=E,
        dt=float(steps.min()) if steps.size else 0.0, speed_bound=float(speeds.max()) if speeds.size else 0.0,
        margin=margin, required=required, window=window, pairs=dps.pairs)


def _first_contact(cell, motions, hold, T, D, k: int) -> Contact:
    """Bisection (to 1e-6 s) between the last sample before ``k`` not in contact and sample ``k``."""
    dps = delta_pair_set(cell)
    lo, hi = (float(T[k - 1]), float(T[k])) if k > 0 and D[k - 1] > 0.0 else (float(T[k]), float(T[k]))
    while hi - lo > 1e-6:
        mid = 0.5 * (lo + hi)
        d, _, _, _, _ = dps.bounded(configurations(cell, motions, np.array([mid]), hold), 0.0)
        lo, hi = (lo, mid) if d[0] <= 0.0 else (mid, hi)
    q = configurations(cell, motions, np.array([hi]), hold)
    d, _, k_pair, _, _ = dps.bounded(q, np.inf)
    return Contact(time=hi, pair=dps.pairs[int(k_pair[0])], depth=float(max(0.0, -d[0])), q=q[0])
