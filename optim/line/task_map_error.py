"""How far a :class:`~.task_maps.TaskMap` is from exact planning: :func:`map_error`, by item yaw.

At seeded random points where the map says a pick is feasible (pre-grasp ``du``, ``w`` and the
item's yaw uniform in [-π, π)), the task time (approach + tracking + leave + release) read from
the map is compared with :func:`~.tracking.plan_pick` on the branch the map names. The result
(:class:`MapError`) gives the relative errors with their points and yaws, and
:meth:`MapError.by_yaw`: the same figures in bins of the tool yaw (the item's yaw reduced by the
gripper's symmetry), which is where a map that ignores yaw is wrong.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from pinarms.optim.line.belt import Belt
from pinarms.optim.line.station import Station
from pinarms.optim.line.task_maps import TaskMap
from pinarms.optim.line.tracking import PickRequest, TrackingSpec, plan_pick, rest_configuration, tool_yaw
from pinarms.errors import InvalidInput, PinarmsError

__all__ = ["MapError", "map_error", "MAP_ERROR_TARGET"]

#: The relative error of the task time a map aims at (95th percentile, against exact planning).
MAP_ERROR_TARGET = 0.01


@dataclass(frozen=True, repr=False)
class MapError:
    """Interpolated vs exact task time at random feasible points: ``relative`` (n,) errors of
    the task time (approach + tracking + leave + release), ``max``, ``mean``, ``p95``, ``points``
    (n, 2) (``du``, ``w`` [m]); ``yaws`` (n,) the tool yaw [rad] of each point (None: not recorded)
    and ``yaw_period`` [rad] the gripper's symmetry they were reduced by."""

    relative: np.ndarray
    points: np.ndarray
    planning_seconds: float
    yaws: np.ndarray | None = None
    yaw_period: float = float(np.pi)

    @property
    def max(self) -> float:
        return float(np.max(self.relative)) if self.relative.size else float("nan")

    @property
    def mean(self) -> float:
        return float(np.mean(self.relative)) if self.relative.size else float("nan")

    @property
    def p95(self) -> float:
        """95th percentile of the relative error (NaN without points)."""
        return float(np.percentile(self.relative, 95)) if self.relative.size else float("nan")

    def by_yaw(self, bins: int = 6) -> list[tuple[float, float, int, float, float, float]]:
        """Per bin of tool yaw over [-period/2, period/2): ``(low, high [rad], points, mean, p95, max)``
        of the relative error (NaN figures in an empty bin).

        Raises:
            InvalidInput: ``bins`` not an integer >= 1, or the points' yaws were not recorded.
        """
        if not (isinstance(bins, int) and bins >= 1):
            raise InvalidInput(f"bins must be an integer >= 1, got {bins!r}")
        if self.yaws is None:
            raise InvalidInput("this MapError holds no yaws (a tray map's): no figures per yaw")
        edges = np.linspace(-self.yaw_period / 2.0, self.yaw_period / 2.0, bins + 1)
        k = np.clip(np.searchsorted(edges, self.yaws, side="right") - 1, 0, bins - 1)
        out = []
        for b in range(bins):
            r = self.relative[k == b]
            figs = (float(r.mean()), float(np.percentile(r, 95)), float(r.max())) if r.size else (np.nan,) * 3
            out.append((float(edges[b]), float(edges[b + 1]), int(r.size), *figs))
        return out

    def table(self, bins: int = 6) -> str:
        """:meth:`by_yaw` as text, one bin a line (yaw in degrees, errors in per cent)."""
        lines = ["  tool yaw [deg]     points   mean %    p95 %    max %"]
        for lo, hi, n, mean, p95, mx in self.by_yaw(bins):
            lines.append(f"  {np.degrees(lo):+7.1f} .. {np.degrees(hi):+6.1f}  {n:6d}  {100 * mean:7.2f}  "
                         f"{100 * p95:7.2f}  {100 * mx:7.2f}")
        return "\n".join(lines)

    def __repr__(self) -> str:
        """One line: how many points, the max, mean and 95th percentile of the relative error [%]."""
        if not self.relative.size:
            return f"MapError(0 points, {self.planning_seconds:.1f} s of planning)"
        return (f"MapError({self.relative.size} points, max {100 * self.max:.2f} %, mean {100 * self.mean:.2f} %, "
                f"p95 {100 * self.p95:.2f} %, {self.planning_seconds:.1f} s of planning)")


def map_error(task_map: TaskMap, station: Station, belt: Belt, spec: TrackingSpec = TrackingSpec(), *,
              n: int = 30, item_height: float = 0.04, seed: int = 0) -> MapError:
    """Exact re-planning at ``n`` seeded random points where the map says feasible (module doc), each
    item at a random yaw, read from the map at that yaw (a map without a yaw coordinate holds at
    every yaw)."""
    rng = np.random.default_rng(seed)
    u_base = float(belt.to_belt(station.base_to_world[:3, 3])[0])
    q_rest = rest_configuration(station)
    rel, pts, yaws = [], [], []
    tries = 0
    start = time.perf_counter()
    while len(rel) < n and tries < 50 * n:
        tries += 1
        du = rng.uniform(task_map.du[0], task_map.du[-1])
        w = rng.uniform(task_map.w[0], task_map.w[-1])
        yaw = rng.uniform(-np.pi, np.pi)
        tA, tC = task_map.times(du, w, yaw)
        if not (np.isfinite(tA) and np.isfinite(tC)):
            continue
        try:
            plan = plan_pick(PickRequest(station, belt, spec, u_base + du, w, item_height=item_height,
                    mass=task_map.mass, q_rest=q_rest, branch=task_map.branch_at(du, w, yaw), yaw=yaw))
        except PinarmsError:
            continue
        approx = float(tA + tC) + task_map.track + task_map.release
        rel.append(abs(approx - plan.duration) / plan.duration)
        pts.append((du, w))
        yaws.append(tool_yaw(station, spec, yaw))
    return MapError(np.array(rel), np.array(pts).reshape(-1, 2), time.perf_counter() - start, np.array(yaws),
                    spec.yaw_period)
