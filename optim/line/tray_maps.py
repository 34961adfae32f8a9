"""Task-time maps of picks placed in trays on a second moving belt, built from exact plans.

A :class:`TrayMap` stores, on a grid of pre-grasp points relative to the arm (``du`` along the
item belt, ``w`` across it) and of pre-place points along the tray belt (``dv``, from the arm's
base projected on the tray belt), the exact times of :func:`~.trays.plan_pick_to_tray`: the
approach ``t_A(du, w)`` (the same as a box pick's), the transfer ``t_X(du, w, dv)`` (from the end
of the pick's tracking segment to the pre-place point, moving with the tray) and the return
``t_R(du, w, dv)`` (from the end of the place tracking to rest at home); NaN where infeasible.
The place coordinate ``dv`` is where the tray's place point is at the place rendezvous: with the
tray's phase it fixes which tray and when (:mod:`~.tray_sim`). Between nodes the times are
interpolated (bilinear for ``t_A``, trilinear for ``t_X``, ``t_R``); a point is feasible when all
the nodes of its cell are. One IK branch: the one :func:`~.trays.plan_pick_to_tray` takes
(the rest configuration's where it reaches) for the pick; the place tracking segment on each
IK branch (``branches``: the SCARA's elbows), kept apart like the box maps': at a point the map
takes the fastest branch whose eight cell nodes are feasible (:meth:`TrayMap.branch_at`), never a
mixture (the place's elbow change costs ~0.7 s on seed 000's SCARA beside its base). The pick's
elbow (``pick_branch``, per node) may change where the rest configuration's stops reaching: a cell
whose four pick nodes are not on one elbow is infeasible (the arm does not pick there).
The approach ``t_A`` is a box pick's approach (the item not yet held): with ``approach_map`` (the
same station's box :class:`~.task_maps.TaskMap`, refined where t_A bends) it is read there on the
pick's elbow, and the simulator's pick part (:attr:`TrayMap.pick_map`) lies on that finer grid.
:func:`tray_map_error` re-plans at seeded random points on the branch the map chose. Built on the execution layer, one task per ``du`` column.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from pinarms.optim.errors import InfeasibleProblem, OptimError
from pinarms.optim.line.belt import Belt
from pinarms.optim.line.station import Station
from pinarms.optim.line.task_map_build import task_fixture_check
from pinarms.optim.line.task_map_error import MapError
from pinarms.optim.line.task_maps import TaskMap
from pinarms.optim.line.tracking import TrackingSpec, branch_label, ik_branch_labels, plan_pick, rest_configuration
from pinarms.optim.line.trays import TrayBelt, plan_pick_to_tray
from pinarms.optim.line.windows import belt_span, check_reach
from pinarms.errors import InvalidInput, PinarmsError, UnreachableTarget

__all__ = ["TrayMap", "build_tray_map", "tray_map_error"]


def _weights(grid: np.ndarray, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    i = np.clip(np.searchsorted(grid, x, side="right") - 1, 0, grid.size - 2)
    f = (x - grid[i]) / (grid[i + 1] - grid[i])
    return i, np.where((x < grid[0]) | (x > grid[-1]), np.nan, f)


@dataclass(frozen=True, eq=False)
class TrayMap:
    """Tray task times (module doc): ``du`` (nu,), ``w`` (nw,), ``dv`` (nv,) [m]; ``approach``
    (nu, nw), ``transfer`` and ``back`` (nb, nu, nw, nv) [s] on each place branch ``branches`` (nb,); ``track`` the pick's tracking and
    ``place`` the place's tracking (descend, release, lift) [s]; ``speed``, ``tray_speed`` [m/s]
    and ``mass`` [kg] it was built for."""

    station: str
    du: np.ndarray
    w: np.ndarray
    dv: np.ndarray
    approach: np.ndarray
    transfer: np.ndarray
    back: np.ndarray
    track: float
    place: float
    speed: float
    tray_speed: float
    mass: float
    build_seconds: float = 0.0
    branches: tuple[int, ...] = (-1,)
    pick_branch: np.ndarray | None = None  #: (nu, nw) the pick's IK branch label at each node (None: one)
    approach_map: Any = None  #: a finer source of t_A: the same station's box :class:`TaskMap` (module doc)
    fixture_infeasible: int = 0  #: nodes planned but closer than the clearance to the cell's fixtures

    def __post_init__(self) -> None:
        shape = (len(self.branches), self.du.size, self.w.size, self.dv.size)
        if self.approach.shape != shape[1:3] or self.transfer.shape != shape or self.back.shape != shape:
            raise InvalidInput(f"tray map {self.station!r}: tables of shapes {self.approach.shape}, "
                               f"{self.transfer.shape}, {self.back.shape} for a {shape} grid")
        P = np.zeros(shape[1:3], int) if self.pick_branch is None else np.asarray(self.pick_branch, int)
        one = (P[:-1, :-1] == P[1:, :-1]) & (P[:-1, :-1] == P[:-1, 1:]) & (P[:-1, :-1] == P[1:, 1:])
        object.__setattr__(self, "_one_pick_branch", one)  # cells whose four pick nodes share an elbow

    def times(self, du: Any, w: Any, dv: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Interpolated ``(t_A, t_X, t_R)`` [s] at ``du``, ``w``, ``dv`` (broadcast) on the branch
        :meth:`branch_at` names; NaN where infeasible."""
        tA, X, R = self._interp(du, w, dv)
        b = self._best(tA, X, R)
        bb = np.maximum(b, 0)[None]
        x, r = np.take_along_axis(X, bb, 0)[0], np.take_along_axis(R, bb, 0)[0]
        return tuple(np.where(b >= 0, v, np.nan) for v in (tA, x, r))

    def branch_at(self, du: float, w: float, dv: float) -> int | None:
        """The place's IK branch label the map uses at a point (None: one branch, or infeasible)."""
        b = int(self._best(*self._interp(du, w, dv)))
        return None if b < 0 or self.branches[b] < 0 else int(self.branches[b])

    @staticmethod
    def _best(tA: np.ndarray, X: np.ndarray, R: np.ndarray) -> np.ndarray:
        tot = tA[None] + X + R
        ok = np.isfinite(tot)
        return np.where(ok.any(axis=0), np.argmin(np.where(ok, tot, np.inf), axis=0), -1)

    def _interp(self, du: Any, w: Any, dv: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        du, w, dv = np.broadcast_arrays(*(np.asarray(x, float) for x in (du, w, dv)))
        (i, fu), (j, fw), (k, fv) = _weights(self.du, du), _weights(self.w, w), _weights(self.dv, dv)
        a = self.approach
        fu = np.where(self._one_pick_branch[i, j], fu, np.nan)  # never across the pick's elbow change
        tA = (a[i, j] * (1 - fu) + a[i + 1, j] * fu) * (1 - fw) + (a[i, j + 1] * (1 - fu) + a[i + 1, j + 1] * fu) * fw
        tA = self._fine_approach(tA, self._pick_label()[i, j], du, w)
        out = [tA]
        for T in (self.transfer, self.back):
            v = 0.0
            for di, wi in ((0, 1 - fu), (1, fu)):
                for dj, wj in ((0, 1 - fw), (1, fw)):
                    v = v + wi * wj * (T[:, i + di, j + dj, k] * (1 - fv) + T[:, i + di, j + dj, k + 1] * fv)
            out.append(v)
        return out[0], out[1], out[2]

    def _pick_label(self) -> np.ndarray:
        """(nu, nw) the pick's elbow label at each node (-1: one branch or none)."""
        return np.full(self.approach.shape, -1) if self.pick_branch is None else np.asarray(self.pick_branch, int)

    def _fine_approach(self, tA: np.ndarray, label: np.ndarray, du: np.ndarray, w: np.ndarray) -> np.ndarray:
        """``tA`` (this grid's) replaced by ``approach_map``'s on the same elbow where both are feasible."""
        if self.approach_map is None:
            return tA
        fine = self.approach_map.approach_on(label, du, w)
        return np.where(np.isfinite(tA) & np.isfinite(fine), fine, tA)

    def place_cells(self, du: float, w: float) -> tuple[np.ndarray, ...]:
        """The place times along ``dv`` for a pick at (``du``, ``w``), cell by cell on each place
        branch: ``(X0, X1, R0, R1)`` (nb, nv − 1), transfer and return at the start and the end of
        each ``dv`` cell, NaN where the cell is infeasible on that branch (one of its eight nodes,
        or the pick's cell). Within a cell and branch the times are linear in ``dv`` (what
        :meth:`times` gives there), so the simulator finds its crossings exactly, never across two
        cells (the branch, or the time, may change at a node)."""
        (i, fu), (j, fw) = _weights(self.du, np.asarray(du, float)), _weights(self.w, np.asarray(w, float))
        nc = self.dv.size - 1
        if not (np.isfinite(fu) and np.isfinite(fw) and self._one_pick_branch[i, j]):
            nan = np.full((len(self.branches), nc), np.nan)
            return nan, nan, nan, nan
        out = []
        for T in (self.transfer, self.back):
            v = ((T[:, i, j] * (1 - fu) + T[:, i + 1, j] * fu) * (1 - fw)
                 + (T[:, i, j + 1] * (1 - fu) + T[:, i + 1, j + 1] * fu) * fw)  # (nb, nv); NaN: a node infeasible
            bad = ~(np.isfinite(v[:, :-1]) & np.isfinite(v[:, 1:]))
            out += [np.where(bad, np.nan, v[:, :-1]), np.where(bad, np.nan, v[:, 1:])]
        return out[0], out[1], out[2], out[3]

    @property
    def pick_map(self) -> TaskMap:
        """The pick part as a :class:`TaskMap` (approach; leave 0 where some place is feasible, the
        place's times come from this map): what the simulator's item intercept uses. Its branches
        are the pick's elbows (``pick_branch``), so a cell whose four pick nodes are not on one
        elbow is infeasible there too, as in this map: the intercept never proposes a pick this map
        cannot place. With ``approach_map`` it lies on that map's (finer) grid: its nodes inside
        this map's feasible cells, each on the cell's elbow, with the finer approach times."""
        if self.approach_map is not None:
            return self._fine_pick_map()
        ok = np.isfinite(self.approach) & np.isfinite(self.transfer + self.back).any(axis=(0, 3))
        P = self._pick_label()
        labels = tuple(int(x) for x in np.unique(P[ok])) or (-1,)
        A = np.stack([np.where(ok & (P == b), self.approach, np.nan) for b in labels])
        return self._as_task_map(self.du, self.w, labels, A)

    def _fine_pick_map(self) -> TaskMap:
        """A node of the finer grid holds, on each elbow, the finer t_A when a feasible pick cell
        of this map on that elbow touches it (a node on a cell border touches both cells)."""
        fm = self.approach_map
        du, w = fm.du[(fm.du >= self.du[0]) & (fm.du <= self.du[-1])], fm.w[(fm.w >= self.w[0]) & (fm.w <= self.w[-1])]
        U, Wm = np.meshgrid(du, w, indexing="ij")
        X = self.transfer + self.back
        cube = np.isfinite(X[:, :-1, :-1] + X[:, 1:, :-1] + X[:, :-1, 1:] + X[:, 1:, 1:])  # (nb, nu-1, nw-1, nv)
        ok = self._one_pick_branch & (cube[..., :-1] & cube[..., 1:]).any(axis=(0, 3))  # pick cells that place
        label = np.where(ok, self._pick_label()[:-1, :-1], -2)
        touching = []  # the labels of the feasible cells touching each node
        for side_u in ("right", "left"):
            i = np.clip(np.searchsorted(self.du, U, side=side_u) - 1, 0, self.du.size - 2)
            for side_w in ("right", "left"):
                j = np.clip(np.searchsorted(self.w, Wm, side=side_w) - 1, 0, self.w.size - 2)
                touching.append(label[i, j])
        labels = tuple(int(x) for x in np.unique(label[label > -2])) or (-1,)
        A = np.stack([np.where(np.any([t == b for t in touching], axis=0), fm.approach_on(b, U, Wm), np.nan)
                      for b in labels])
        return self._as_task_map(du, w, labels, A)

    def _as_task_map(self, du: np.ndarray, w: np.ndarray, labels: tuple, A: np.ndarray) -> TaskMap:
        C = np.where(np.isfinite(A), 0.0, np.nan)
        best = np.min(np.where(np.isfinite(A), A, np.inf), axis=0)
        a = np.where(np.isfinite(best), best, np.nan)
        return TaskMap(self.station, du, w, a, np.where(np.isfinite(a), 0.0, np.nan), self.track, 0.0, self.speed,
                       self.mass, branches=labels, branch_approach=A, branch_leave=C)


def _column(task: dict) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One ``du`` column: the pick planned once per ``w`` (on the rest configuration's elbow where it
    reaches), then placed at every ``dv`` on every place branch."""
    st, belt, trays, spec = task["station"], task["belt"], task["trays"], task["spec"]
    u_base = float(belt.to_belt(st.base_to_world[:3, 3])[0])
    v_base = float(trays.belt.to_belt(st.base_to_world[:3, 3])[0])
    q_rest = rest_configuration(st)
    nw, nv, labels = len(task["w"]), len(task["dv"]), task["branches"]
    fixtures = task_fixture_check(task)
    blocked = 0
    A, P = np.full(nw, np.nan), np.full(nw, -1)
    X, R = np.full((len(labels), nw, nv), np.nan), np.full((len(labels), nw, nv), np.nan)
    for j, w in enumerate(task["w"]):
        try:
            pick = plan_pick(st, belt, spec, u_base + task["du"], w, item_height=task["height"], mass=task["mass"],
                             q_rest=q_rest)
        except (UnreachableTarget, InfeasibleProblem, OptimError):
            continue  # no pick here: no place either
        for b, label in enumerate(labels):
            for k, dv in enumerate(task["dv"]):
                try:
                    p = plan_pick_to_tray(st, belt, trays, spec, u_base + task["du"], w, v_base + dv,
                                          item_height=task["height"], mass=task["mass"], q_rest=q_rest,
                                          place_branch=None if label < 0 else label, pick=pick)
                except (UnreachableTarget, InfeasibleProblem, OptimError):
                    continue
                verdict = "clear" if fixtures is None else fixtures.verdict(p.trajectory)
                if verdict != "clear":
                    blocked += verdict == "fixtures"
                    continue
                A[j], X[b, j, k], R[b, j, k] = p.times[0], p.times[2], p.times[4]
                P[j] = branch_label(st.robot, p.pieces[1].sample(np.array([0.0]))[0][0])
    return A, X, R, P, blocked


#: Half-width [m] of the place-grid cells around the place ending at the arm's home (:func:`_with_home_nodes`).
HOME_GAP = 0.03


def _with_home_nodes(dv: np.ndarray, station: Station, trays: TrayBelt, spec: TrackingSpec,
                     v_base: float) -> np.ndarray:
    """The place grid with nodes at and ``HOME_GAP`` either side of the place whose tracking ends
    just above the arm's home (its box point) when the tray belt passes there: the return time is
    V-shaped about it (0.16 s there, rising on both sides: linear interpolation across the V erred
    by up to 1.1 % of the task), and right at it the return (a path of almost no length starting at
    the tray's speed) has no feasible timing: the node there is infeasible and each side of the V is
    interpolated on its own."""
    home = trays.belt.to_belt(station.place.position)
    if abs(home[1] - trays.w) > 0.05 or abs(home[2] - trays.height - spec.lift) > 0.1:
        return dv  # the place does not pass the home point: no V
    kink = float(home[0]) - v_base - trays.belt.speed * (2.0 * spec.descend + spec.release)
    extra = [x for x in (kink - HOME_GAP, kink, kink + HOME_GAP) if dv[0] < x < dv[-1]]
    return np.unique(np.concatenate([dv, extra]))


def build_tray_map(station: Station, belt: Belt, trays: TrayBelt, spec: TrackingSpec = TrackingSpec(), *,
                   mass: float = 0.1, item_height: float = 0.04, margin: float = 0.025, nu: int = 10, nw: int = 3,
                   nv: int = 8, du_range: tuple[float, float] | None = None,
                   dv_range: tuple[float, float] | None = None, scheduler: Any = None,
                   approach_map: TaskMap | None = None, cell: Any = None, clearance: float = 0.01,
                   progress: Any = None) -> TrayMap:
    """Plan picks placed in trays exactly on a ``nu`` × ``nw`` × ``nv`` grid (module doc); ``du``
    and ``dv`` span the arm's sampled workspace over each belt (or the ranges given [m]).
    ``approach_map``: the same station's box :class:`TaskMap` on this belt (same speed and
    tracking spec; any item mass: the approach carries none), whose finer grid then gives t_A.
    ``progress(done, total)``: ``du`` columns planned. ``cell``, ``clearance``: as
    :func:`~.task_map_build.build_task_map`'s (the whole pick-to-tray
    trajectory kept ``clearance`` [m] from the cell's fixtures; ``TrayMap.fixture_infeasible``).

    Raises:
        BeltOutOfReach: the arm reaches no point of the item belt or of the tray belt (names the arm).
    """
    from pinarms.execution import map_chunks

    if not all(isinstance(n, int) and n >= 2 for n in (nu, nw, nv)):
        raise InvalidInput(f"nu, nw and nv must be integers >= 2, got {nu!r}, {nw!r}, {nv!r}")
    if approach_map is not None and not (isinstance(approach_map, TaskMap) and abs(approach_map.speed - belt.speed)
                                         <= 1e-9 * max(1.0, belt.speed)):
        raise InvalidInput(f"approach_map must be the station's TaskMap built at the belt's {belt.speed} m/s, got "
                           f"{getattr(approach_map, 'speed', type(approach_map).__name__)!r}")
    check_reach(station, belt, item_height)
    check_reach(station, trays.belt, trays.height)
    rest_configuration(station)
    if cell is not None:
        from pinarms.optim.line.fixtures import check_in_cell, fixture_check

        check_in_cell(cell, station)
        fixture_check(cell, station.name, clearance)
    start = time.perf_counter()
    lo, hi = belt_span(station, belt) if du_range is None else du_range
    vlo, vhi = belt_span(station, trays.belt) if dv_range is None else dv_range
    half = belt.width / 2.0 - margin
    if half <= 0.0:
        raise InvalidInput(f"margin {margin} m leaves no belt width (width {belt.width} m)")
    du, w = np.linspace(lo, hi, nu), np.linspace(-half, half, nw)
    v_base = float(trays.belt.to_belt(station.base_to_world[:3, 3])[0])
    dv = _with_home_nodes(np.linspace(vlo, vhi, nv), station, trays, spec, v_base)
    vv, zz = np.meshgrid(v_base + dv, np.linspace(-trays.belt.width / 2.0, trays.belt.width / 2.0, 3), indexing="ij")
    labels = ik_branch_labels(station, trays.belt.to_world(vv.ravel(), zz.ravel(), trays.height + spec.lift))
    task = {"station": station, "belt": belt, "trays": trays, "spec": spec, "w": w.tolist(), "dv": dv.tolist(),
            "mass": mass, "height": item_height, "seed": 0, "branches": labels, "cell": cell, "clearance": clearance}
    cols = map_chunks(_column, [{**task, "du": float(d)} for d in du], scheduler=scheduler, progress=progress)
    A, P = np.stack([c[0] for c in cols]), np.stack([c[3] for c in cols])
    X, R = (np.stack([c[n] for c in cols], axis=1) for n in (1, 2))
    place = spec.descend + spec.release + spec.descend
    return TrayMap(station.name, du, w, dv, A, X, R, spec.track_time, place, belt.speed, trays.belt.speed,
                   float(mass), time.perf_counter() - start, labels, P, approach_map, sum(c[4] for c in cols))


def tray_map_error(tray_map: TrayMap, station: Station, belt: Belt, trays: TrayBelt,
                   spec: TrackingSpec = TrackingSpec(), *, n: int = 30, item_height: float = 0.04,
                   seed: int = 0) -> MapError:
    """Interpolated vs exact task time (pick to tray) at ``n`` seeded random points (du, w, dv)
    where the map says feasible; ``points`` (n, 3)."""
    rng = np.random.default_rng(seed)
    u_base = float(belt.to_belt(station.base_to_world[:3, 3])[0])
    v_base = float(trays.belt.to_belt(station.base_to_world[:3, 3])[0])
    q_rest = rest_configuration(station)
    rel, pts, tries, start = [], [], 0, time.perf_counter()
    m = tray_map
    while len(rel) < n and tries < 50 * n:
        tries += 1
        du, w, dv = (rng.uniform(g[0], g[-1]) for g in (m.du, m.w, m.dv))
        tA, tX, tR = m.times(du, w, dv)
        if not np.isfinite(tA + tX + tR):
            continue
        try:
            p = plan_pick_to_tray(station, belt, trays, spec, u_base + du, w, v_base + dv, item_height=item_height,
                                  mass=m.mass, q_rest=q_rest, place_branch=m.branch_at(du, w, dv))
        except PinarmsError:
            continue
        approx = float(tA + tX + tR) + m.track + m.place
        rel.append(abs(approx - p.duration) / p.duration)
        pts.append((du, w, dv))
    return MapError(np.array(rel), np.array(pts).reshape(-1, 3), time.perf_counter() - start)
