"""From a shortcut polyline to a smooth joint path, proven clear again after smoothing.

The planner's path is a polyline in joint space: timed as it is, the arm would stop at
every corner. :func:`smooth_path` replaces it by the C² cubic spline through its vertices
(:func:`pinarms.planning.joint_spline`, parameter = joint-space chord length), which the time
scaling passes without stopping. A spline is not the polyline that was proven: it is
**proven again** (:func:`prove_path`) with the same continuous rule as the edges, its travel
bound taken from the exact peaks of ``|q'(s)|`` on parts of every piece (:func:`_travel_bound`:
a cumulative bound ``T(s)``; the samples are placed at equal steps of T, and every interval
the proof halves gets the bound of its own half from T). The proof runs first compiled on the
sphere cover (:mod:`.spline_proof`: the same rule on the same ``T``, the cover's lower bound of
the excess at each state); the exact proof (the ladder, coal where the cover is inconclusive)
takes only the sample intervals around the ranges the cover leaves open. Where the proof fails the
polyline edges around the failing piece get vertices at their quarter points, which pulls
the spline towards the proven polyline, and the spline is proven again
(:data:`REFINE_ROUNDS` rounds at most; the pieces around the new vertices are proven first,
so that a spline failing there again is refused before the rest is proven). A piece whose exact
joint extrema leave the joint limits (by more than :data:`LIMIT_TOL`) is refused before anything
else is proven. A spline through a vertex on a joint limit where the joint turns leaves the limit
next to it, which no vertex insertion removes: then (or after the rounds, when the spline leaves a
limit anywhere) the spline kept inside the limits (:func:`within_limits`: monotone slopes at the
pieces that leave) is refined the same way. If that does not succeed either, the polyline
itself is the path, with stops at its corners, proven by the search.
"""

from __future__ import annotations

from bisect import bisect_right
from typing import Any, TYPE_CHECKING

import numpy as np

from pinarms.optim.motion.proof import Verdict
from pinarms.optim.motion.spline_proof import LIMIT_TOL, MAX_OPEN, cover_proof, joint_extrema, merged, outside_joints
from pinarms.planning import JointPath, joint_spline
from pinarms.planning.extrema import normalised_pieces, piece_extrema

if TYPE_CHECKING:
    from pinarms.optim.motion.checker import MotionChecker
    from pinarms.robots.robot import Robot

__all__ = ["REFINE_ROUNDS", "LIMIT_TOL", "prove_path", "polyline_path", "smooth_path", "path_speed_bounds",
           "within_limits"]

#: The compiled proof stops at the first range it leaves open, which the exact proof takes at once (a
#: spline failing there is refused before the rest is proven), then goes on. Measured on the simplified
#: paths of 12 queries (best of 3, interleaved, load 3.8–4.3): ``panda_shelf`` 175 ms in all with it,
#: 222 ms without, 361 ms with the exact proof alone; ``aubo_crate_guard`` 187, 197, 237 ms. A refused
#: spline may then be refined at another failing piece than the exact proof's (1 of the 100 benchmark
#: paths), the result proven the same way.
PROBE = True
#: Rounds of vertex insertion before falling back to the polyline with stops.
REFINE_ROUNDS = 4
#: Parts per sample interval of a piece's peak speed over which the travel bound is taken (:func:`_samples`).
FINE = 4
#: Relative allowance on a travel bound for the rounding of its evaluation.
SAFETY = 1.0 + 1e-9
#: The spline's samples are up to ``step · 2^COARSE`` of travel apart; the proof starts at that level
#: (screens raised by ``step · 2^(COARSE−1)``) and halves what it does not prove. Measured on 22
#: planner paths of the four benchmark scenes (best of 3, interleaved, load 5.8–6.3): 1 045, 895 and
#: 869 ms in all at 0, 1 and 2 (1 120 ms before the travel bound per part), 1 the steadier per scene.
COARSE = 1


def path_speed_bounds(path: JointPath) -> np.ndarray:
    """Exact ``max |dq_j/ds|`` on every piece of ``path``: ``(pieces, n_joints)``."""
    h = np.diff(path.breaks)
    values, _ = piece_extrema(normalised_pieces(path.coefficients, h), h, (1,))
    return np.nanmax(np.abs(values[0]), axis=-1)


def _hermite(s: np.ndarray, y: np.ndarray, m: np.ndarray) -> np.ndarray:
    """Coefficients (K, 4) ascending of the cubic Hermite pieces through ``y`` (K+1,) with slopes ``m`` (K+1,)."""
    h = np.diff(s)
    delta = np.diff(y) / h
    return np.stack([y[:-1], m[:-1], (3.0 * delta - 2.0 * m[:-1] - m[1:]) / h,
                     (m[:-1] + m[1:] - 2.0 * delta) / h ** 2], axis=1)


def within_limits(path: JointPath, waypoints: np.ndarray, lower: np.ndarray, upper: np.ndarray) -> JointPath:
    """The spline ``path`` through ``waypoints`` kept inside the joint limits where it leaves them.

    A C² spline through vertices at or near a joint limit overshoots it (a vertex on the limit
    where the joint turns: the spline's slope is not 0 there). For every joint whose piece leaves
    its limits, the slopes at both ends of that piece become the monotone (PCHIP,
    Fritsch–Carlson) slopes of that joint's waypoints, which keep a piece between its end values;
    repeated until no piece of the joint leaves (at worst every slope of the joint: its PCHIP).
    The other joints and slopes stay: C² except at the changed knots, C¹ there. ``path`` itself
    when no piece leaves. The result is proven like any spline (:func:`prove_path` refuses a
    piece whose exact extrema leave the limits).
    """
    bad = outside_joints(path, lower, upper)
    if not bad.any():
        return path
    from scipy.interpolate import PchipInterpolator

    s = np.asarray(path.breaks, dtype=float)
    C = path.coefficients.copy()
    W = np.asarray(waypoints, dtype=float)
    h = s[-1] - s[-2]
    slopes = np.concatenate([C[:, 1], (C[-1, 1] + h * (2.0 * C[-1, 2] + 3.0 * C[-1, 3] * h))[None]])
    for j in np.flatnonzero(bad.any(axis=0)):
        monotone = PchipInterpolator(s, W[:, j]).derivative()(s)
        m, changed = slopes[:, j].copy(), np.zeros(s.size, dtype=bool)
        piece_bad = bad[:, j]
        # first the knots of the bad pieces that lie on a limit alone (slope 0 there: PCHIP's own), then both ends
        on = (W[:, j] <= lower[j] + LIMIT_TOL) | (W[:, j] >= upper[j] - LIMIT_TOL)
        first = True
        while piece_bad.any() and not changed.all():
            ends = np.zeros(s.size, dtype=bool)
            ends[:-1] |= piece_bad
            ends[1:] |= piece_bad
            changed |= ends & on if first and (ends & on & ~changed).any() else ends
            first = False
            m[changed] = monotone[changed]
            C[:, :, j] = _hermite(s, W[:, j], m)
            lo, hi = joint_extrema(s, C[:, :, j:j + 1])
            piece_bad = ((lo < lower[j] - LIMIT_TOL) | (hi > upper[j] + LIMIT_TOL))[:, 0]
    return JointPath(s, C, robot=path.robot, frame=path.frame)


def _speed_bound(C: np.ndarray, k: np.ndarray, t0: np.ndarray, t1: np.ndarray) -> np.ndarray:
    """``max |dq_j/ds|`` (M, n) over local ``[t0, t1]`` of pieces ``k`` of a path of degree ≤ 3 (coefficients
    ``C`` (K, W, n), ascending in s − break): q' is a quadratic, its peak at an end or at its vertex."""
    W = C.shape[1]
    if W < 2:
        return np.zeros((k.size, C.shape[2]))
    zero = np.zeros((k.size, C.shape[2]))
    c1, c2, c3 = C[k, 1], (C[k, 2] if W > 2 else zero), (C[k, 3] if W > 3 else zero)

    def slope(t: np.ndarray) -> np.ndarray:
        return np.abs(c1 + t * (2.0 * c2 + 3.0 * c3 * t))

    a, b = t0[:, None], t1[:, None]
    best = np.maximum(slope(np.broadcast_to(a, c1.shape)), slope(np.broadcast_to(b, c1.shape)))
    with np.errstate(divide="ignore", invalid="ignore"):
        vertex = np.where(c3 != 0.0, -c2 / (3.0 * np.where(c3 != 0.0, c3, 1.0)), a)
    inside = (vertex > a) & (vertex < b)
    return np.where(inside, np.maximum(best, slope(np.where(inside, vertex, a))), best)


def _travel_parts(checker: Any, path: JointPath) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A cumulative travel bound along ``path``: nodes ``s`` (M+1,), ``T(s)`` [m] (M+1,), linear between them,
    and the bound of every joint's speed ``|q_j'|`` on each part ``(M, n)`` it comes from.

    Each piece is cut in :data:`FINE` times as many equal parts as its peak speed needs at the
    checker's step; on a part the points of the arm move at most ``Σ_j ℓ_j max |q_j'|`` per unit of
    s (the exact peak of the quadratic ``q'`` there; a path of higher degree keeps the piece's peak),
    so ``T(b) − T(a)`` bounds the travel between any ``a < b``.
    """
    breaks = np.asarray(path.breaks, dtype=float)
    C = path.coefficients
    levers = checker.levers
    if 2 <= C.shape[1] <= 4:  # compiled (:func:`._spline_kernel.travel_parts`), the same bound
        from pinarms.optim.motion._spline_kernel import travel_parts

        return travel_parts(breaks, np.ascontiguousarray(C, dtype=float), np.ascontiguousarray(levers, dtype=float),
                            float(checker.step), float(FINE), SAFETY)
    return _travel_parts_arrays(checker, path)


def _travel_parts_arrays(checker: Any, path: JointPath) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`_travel_parts` in numpy (any degree; above 3 each part keeps its piece's peak)."""
    breaks = np.asarray(path.breaks, dtype=float)
    C = path.coefficients
    levers = checker.levers
    h = np.diff(breaks)
    speeds = path_speed_bounds(path)
    peak = speeds @ levers
    fine = FINE if C.shape[1] <= 4 else 1
    m = np.maximum(1, np.ceil(fine * peak * h / checker.step * (1.0 + 1e-12))).astype(int)
    k = np.repeat(np.arange(h.size), m)
    j = np.arange(int(m.sum())) - np.repeat(np.cumsum(m) - m, m)
    t0, t1 = h[k] * j / m[k], h[k] * (j + 1) / m[k]
    V = _speed_bound(C, k, t0, t1) if fine > 1 else speeds[k]
    density = V @ levers
    nodes = breaks[k] + t1
    nodes[np.cumsum(m) - 1] = breaks[1:]  # a piece's last part ends on its break
    bound = density * np.diff(np.concatenate([[breaks[0]], nodes])) * SAFETY
    return np.concatenate([[breaks[0]], nodes]), np.concatenate([[0.0], np.cumsum(bound)]), V


def _travel_bound(checker: Any, path: JointPath) -> tuple[np.ndarray, np.ndarray]:
    """A cumulative travel bound along ``path``: nodes ``s`` and ``T(s)`` [m], linear between them
    (:func:`_travel_parts`)."""
    nodes, T, _ = _travel_parts(checker, path)
    return nodes, T


def _samples(checker: Any, path: JointPath,
             bound: tuple[np.ndarray, np.ndarray] | None = None) -> tuple[np.ndarray, np.ndarray, tuple[np.ndarray, np.ndarray]]:
    """Path positions ``s`` (N,) whose consecutive travel bounds (N-1,) are equal and below the checker's
    step, and the cumulative bound they come from (``bound``, default :func:`_travel_bound`)."""
    nodes, T = _travel_bound(checker, path) if bound is None else bound
    n = max(1, int(np.ceil(T[-1] / (checker.step * 2.0 ** COARSE) * (1.0 + 1e-9))))
    s = np.interp(T[-1] * np.arange(n + 1) / n, T, nodes)
    s[0], s[-1] = nodes[0], nodes[-1]
    s = np.maximum.accumulate(s)
    return s, np.diff(np.interp(s, nodes, T)), (nodes, T)


class _PointEvaluator:
    """One point at a time, as the proof's bisection asks for them: ``q(s)`` (Horner on the piece) and
    the cumulative travel bound ``T(s)`` (linear between its nodes), in plain Python floats and
    one small array (a call of :meth:`JointPath.sample` per point costs several times more)."""

    def __init__(self, path: JointPath, nodes: np.ndarray, T: np.ndarray) -> None:
        self.breaks = np.asarray(path.breaks, dtype=float).tolist()
        self.coefs = path.coefficients
        self.nodes, self.T = nodes.tolist(), T.tolist()

    def q(self, s: float) -> np.ndarray:
        k = min(max(bisect_right(self.breaks, s) - 1, 0), len(self.breaks) - 2)
        sigma = s - self.breaks[k]
        c = self.coefs[k]
        out = c[-1].copy()
        for d in range(c.shape[0] - 2, -1, -1):
            out *= sigma
            out += c[d]
        return out

    def bound(self, s: float) -> float:
        nodes, T = self.nodes, self.T
        j = min(max(bisect_right(nodes, s) - 1, 0), len(nodes) - 2)
        width = nodes[j + 1] - nodes[j]
        t = min(max((s - nodes[j]) / width, 0.0), 1.0) if width > 0.0 else 1.0
        return T[j] + (T[j + 1] - T[j]) * t


def _runs(s: np.ndarray, focus: tuple[float, float] | None) -> list[tuple[int, int]]:
    """Runs of sample intervals ``(first sample, last sample)`` to prove in turn: those meeting ``focus``
    (a range of s) first, then the rest before and after it; the whole path when ``focus`` is None."""
    last = s.size - 1
    if focus is None:
        return [(0, last)]
    a = int(np.clip(np.searchsorted(s, focus[0], side="right") - 1, 0, last - 1))
    b = int(np.clip(np.searchsorted(s, focus[1], side="left"), a + 1, last))
    return [(a, b)] + [(i, j) for i, j in ((0, a), (b, last)) if j > i]


def _open_groups(s: np.ndarray, ranges: np.ndarray, focus: tuple[float, float] | None) -> list[np.ndarray]:
    """The samples around ``ranges (M, 2)`` of s (sorted, disjoint): every sample interval meeting a range,
    with both its ends; as one group, or two when ``focus`` is given (the runs meeting it first)."""
    last = s.size - 1
    a = np.clip(np.searchsorted(s, ranges[:, 0], side="right") - 1, 0, last - 1)
    b = np.clip(np.searchsorted(s, ranges[:, 1], side="left"), a + 1, last)
    runs = [np.arange(i, j + 1) for i, j in zip(a.tolist(), b.tolist())]
    if focus is None:
        return [np.unique(np.concatenate(runs))]
    meets = [s[r[-1]] >= focus[0] and s[r[0]] <= focus[1] for r in runs]
    groups = [[r for r, m in zip(runs, meets) if m], [r for r, m in zip(runs, meets) if not m]]
    return [np.unique(np.concatenate(g)) for g in groups if g]


def prove_path(checker: MotionChecker, path: JointPath, extra: np.ndarray | None = None, *,
               focus: tuple[float, float] | None = None, compiled: bool = True) -> Any:
    """Prove that every configuration of ``path`` keeps the checker's margins (module docstring).

    Returns ``(verdict, piece)``: the piece of the first interval found not proven (``None`` when
    proven). ``focus``: a range of s proven first (where the path last changed: a failure there
    is found before the rest is proven). ``extra``: per-path-joint lever additions (unused for a
    planned arm's own path). ``compiled``: the compiled cover proof first
    (:func:`.spline_proof.cover_proof`), the exact proof only on the sample intervals around the
    ranges it leaves open (the first one found, and the joint limits', as soon as found: a path
    failing there is refused before the rest is proven; then the others in one proof, the
    intervals between them counted as proven: travel 0); ``False``: the exact proof alone.
    First of all, a path of degree ≤ 3 whose exact joint extrema leave the checker's joint limits
    (:func:`.spline_proof.outside_joints`) is refused at its first such piece.
    """
    if path.coefficients.shape[1] <= 4 and path.coefficients.shape[2] == checker.n:
        outside = np.flatnonzero(outside_joints(path, checker.lower, checker.upper).any(axis=1))
        if outside.size:  # a piece whose exact extrema leave the joint limits: refused at once
            return Verdict(False), int(outside[0])
    nodes, T, V = _travel_parts(checker, path)
    s, budgets, _ = _samples(checker, path, (nodes, T))
    at = _PointEvaluator(path, nodes, T)
    proof = cover_proof(checker, path, nodes, T, V) if compiled and extra is None else None
    if proof is not None:
        first = proof.advance(1 if PROBE else MAX_OPEN)
        if first is not None and (first.size or proof.limits.size):
            verdict, piece = _prove_groups(checker, path, s, budgets, at, _open_groups(s, merged([first, proof.limits]),
                                                                                        focus))
            if not verdict.ok:
                return verdict, piece
        rest = None if first is None else (np.empty((0, 2)) if proof.done else proof.advance())
        if rest is not None:
            if rest.size == 0:
                return Verdict(True), None
            return _prove_groups(checker, path, s, budgets, at, _open_groups(s, merged([rest]), focus))
    return _prove_groups(checker, path, s, budgets, at, [np.arange(a, b + 1) for a, b in _runs(s, focus)])


def _prove_groups(checker: Any, path: JointPath, s: np.ndarray, budgets: np.ndarray, at: _PointEvaluator,
                  groups: list[np.ndarray]) -> Any:
    """The exact proof (:meth:`MotionChecker.prove`) of each group of samples ``s[idx]`` in turn: ``(verdict,
    piece)`` of the first not proven, or of the last."""
    verdict = Verdict(True)
    for idx in groups:
        gap = np.diff(idx) != 1  # between two runs: already proven, travel 0 for this proof
        sel = np.where(gap, 0.0, budgets[np.minimum(idx[:-1], budgets.size - 1)])

        def midpoint(k: int, fa: float, fb: float, B: float, idx: np.ndarray = idx, gap: np.ndarray = gap):
            lo, hi = float(s[idx[k]]), float(s[idx[k] + 1])
            if gap[k]:  # never halved (both ends keep the margins); a state and no travel if asked
                return at.q(lo), 0.0, 0.0
            sa, sm, sb = lo + fa * (hi - lo), lo + 0.5 * (fa + fb) * (hi - lo), lo + fb * (hi - lo)
            Tm = at.bound(sm)  # each half's own bound
            return at.q(sm), min(Tm - at.bound(sa), B), min(at.bound(sb) - Tm, B)

        verdict = checker.prove(path(s[idx]), sel, midpoint, top=-COARSE)
        if not verdict.ok:
            i = min(int(idx[max(0, min(int(verdict.first_bad), idx.size - 2))]), s.size - 2)
            piece = np.searchsorted(path.breaks, 0.5 * (s[i] + s[i + 1]), side="right") - 1
            return verdict, int(np.clip(piece, 0, len(path.breaks) - 2))
    return verdict, None


def polyline_path(waypoints: np.ndarray, robot: Robot | None = None) -> JointPath:
    """The polyline through ``waypoints (K, n)`` as a :class:`JointPath` (s = chord length) with stops at its corners."""
    W = np.asarray(waypoints, dtype=float)
    step = np.linalg.norm(np.diff(W, axis=0), axis=1)
    keep = np.concatenate([[True], step > 1e-12])
    W = W[keep]
    step = np.linalg.norm(np.diff(W, axis=0), axis=1)
    s = np.concatenate([[0.0], np.cumsum(step)])
    coefs = np.stack([W[:-1], np.diff(W, axis=0) / step[:, None]], axis=1)
    return JointPath(s, coefs, stops=s[1:-1], robot=robot)


def _refined(W: np.ndarray, piece: int) -> tuple[np.ndarray, tuple[int, int]]:
    """``W`` with vertices at the quarter points of the edges around ``piece`` (the spline pulled towards the
    proven polyline there), and the range of pieces changed."""
    lo, hi = max(0, piece - 1), min(W.shape[0] - 2, piece + 1)
    rows = [W[: lo + 1]]
    for k in range(lo, hi + 1):
        a, b = W[k], W[k + 1]
        rows.append(np.stack([a + 0.25 * (b - a), a + 0.75 * (b - a), b]))
    rows.append(W[hi + 2:])
    return np.concatenate(rows), (lo, lo + 3 * (hi - lo + 1))


def smooth_path(checker: MotionChecker, waypoints: np.ndarray, robot: Robot | None = None, *,
                compiled: bool = True) -> tuple[JointPath, str, int]:
    """A proven joint path through the polyline ``waypoints``: ``(path, method, rounds)``.

    ``method`` is ``"straight line"`` (two waypoints), ``"cubic spline"`` (proven after ``rounds``
    splines refused) or ``"polyline with stops"`` (the fallback, ``rounds`` splines refused). ``compiled``: each
    spline proven on the compiled cover first (:func:`prove_path`); ``False``: the exact proof alone.

    The C² spline is refined up to :data:`REFINE_ROUNDS` times (no more once a piece leaves a joint
    limit next to a vertex on it, which no refinement pulls the spline back to); if it is still not
    proven and a refused spline left the joint limits, the same rounds again with the splines kept
    inside them (:func:`within_limits`).
    """
    W0 = np.asarray(waypoints, dtype=float)
    step = np.linalg.norm(np.diff(W0, axis=0), axis=1)
    W0 = W0[np.concatenate([[True], step > 1e-12])]
    if W0.shape[0] <= 2:
        return polyline_path(W0, robot), "straight line", 0
    path, rounds, left = _rounds(checker, W0, robot, compiled, limited=False)
    if path is None and left:  # a refused spline left a joint limit: the splines kept inside them
        path, more, _ = _rounds(checker, W0, robot, compiled, limited=True)
        rounds += more
    if path is not None:
        return path, "cubic spline", rounds
    return polyline_path(waypoints, robot), "polyline with stops", rounds


def _rounds(checker: Any, W: np.ndarray, robot: Any, compiled: bool, *,
            limited: bool) -> tuple[JointPath | None, int, bool]:
    """The refinement rounds of :func:`smooth_path` on the splines through ``W`` (``limited``: each kept inside
    the joint limits, :func:`within_limits`): ``(proven path or None, splines refused, whether a refused
    spline left a joint limit)``. Unlimited, the rounds end at a piece leaving a limit next to a vertex on it."""
    changed, left = None, False  # changed: the pieces around the last vertices inserted, proven first
    for r in range(REFINE_ROUNDS + 1):
        path = joint_spline(W, robot=robot)
        if limited:
            path = within_limits(path, W, checker.lower, checker.upper)
        focus = None if changed is None else \
            (path.breaks[max(0, changed[0] - 1)], path.breaks[min(len(path.breaks) - 1, changed[1] + 1)])
        verdict, piece = prove_path(checker, path, focus=focus, compiled=compiled)
        if verdict.ok:
            return path, r, left
        left = left or bool(outside_joints(path, checker.lower, checker.upper).any())
        if not limited and _on_limit(path, W, piece, checker.lower, checker.upper):
            return None, r + 1, left  # no vertex insertion removes that
        W, changed = _refined(W, piece)
    return None, REFINE_ROUNDS + 1, left


def _on_limit(path: JointPath, W: np.ndarray, piece: int, lower: np.ndarray, upper: np.ndarray) -> bool:
    """Whether ``piece`` of the spline through ``W`` leaves the limits of a joint at an end vertex on that limit."""
    bad = outside_joints(path, lower, upper)[piece]
    ends = W[piece:piece + 2][:, bad]
    return bool(np.any((ends <= lower[bad] + LIMIT_TOL) | (ends >= upper[bad] - LIMIT_TOL)))
