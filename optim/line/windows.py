"""Each arm's pick window on the belt, from its reach, and whether neighbours' windows overlap.

The window of an arm is the set of pre-grasp points (belt coordinates ``u``, ``w``) whose
whole pick (:func:`pinarms.optim.line.tracking.plan_pick`) is feasible: inside the reach with the
tool orientation the gripper needs and within the joint limits at the belt's speed. Its
extent along the belt is read from the arm's task-time map; before any planning,
:func:`check_reach` proves from a sampled workspace that the arm reaches the belt at all.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from pinarms.optim.line.belt import Belt
from pinarms.optim.line.errors import BeltOutOfReach
from pinarms.optim.line.station import Station

__all__ = ["PickWindow", "check_reach", "belt_span", "horizontal_reach", "windows_overlap", "REACH_SAMPLES"]

#: Seeded random configurations that sample an arm's workspace.
REACH_SAMPLES = 4000


@dataclass(frozen=True)
class PickWindow:
    """Where an arm picks: ``u_min``..``u_max`` [m] along the belt (pre-grasp points, any
    ``w``); ``u_base``: the arm's base projected on the belt [m]."""

    station: str
    u_min: float
    u_max: float
    u_base: float

    @property
    def length(self) -> float:
        return self.u_max - self.u_min


def _workspace_world(station: Station) -> np.ndarray:
    q = station.robot.random_q(REACH_SAMPLES, seed=0)
    p = station.robot.position(q)
    T = station.base_to_world
    return p @ T[:3, :3].T + T[:3, 3]


def horizontal_reach(station: Station) -> float:
    """Largest horizontal distance [m] of the tcp from the base axis (sampled workspace)."""
    q = station.robot.random_q(REACH_SAMPLES, seed=0)
    p = station.robot.position(q)
    return float(np.max(np.hypot(p[:, 0], p[:, 1])))


def belt_span(station: Station, belt: Belt, margin: float = 0.05) -> tuple[float, float]:
    """Range of ``du`` [m] (along the belt, from the base's projection) of sampled tcp points over
    the belt (across within its half width + ``margin``): where the map's grid is laid."""
    p = belt.to_belt(_workspace_world(station))
    u_base = float(belt.to_belt(station.base_to_world[:3, 3])[0])
    over = np.abs(p[:, 1]) <= belt.width / 2.0 + margin
    if not over.any():
        return (-horizontal_reach(station), horizontal_reach(station))
    return float(p[over, 0].min() - u_base), float(p[over, 0].max() - u_base)


def check_reach(station: Station, belt: Belt, grasp_height: float, tolerance: float = 0.02) -> None:
    """Raise :class:`BeltOutOfReach` when no sampled tcp point comes within ``tolerance`` [m] of the
    belt's grasp surface (``grasp_height`` above the belt); names the arm and the nearest belt point."""
    p = belt.to_belt(_workspace_world(station))
    u = np.clip(p[:, 0], 0.0, belt.length)
    w = np.clip(p[:, 1], -belt.width / 2.0, belt.width / 2.0)
    d = np.sqrt((p[:, 0] - u) ** 2 + (p[:, 1] - w) ** 2 + (p[:, 2] - grasp_height) ** 2)
    k = int(np.argmin(d))
    if d[k] > tolerance:
        near = belt.to_world(u[k], w[k], grasp_height)
        raise BeltOutOfReach(
            f"arm {station.name!r} ({station.robot.name}) cannot reach the belt: the belt point nearest to its reach is "
            f"u = {u[k]:.3f} m along, w = {w[k]:.3f} m across (world {np.round(near, 3).tolist()} m), "
            f"{d[k]:.3f} m away from the nearest tool point; move the arm closer or lower it")


def windows_overlap(a: PickWindow, b: PickWindow, margin: float = 0.0) -> bool:
    """Whether two windows share belt length (widened by ``margin`` [m])."""
    return a.u_min - margin < b.u_max and b.u_min - margin < a.u_max


def window_of(station: Station, belt: Belt, task_map: Any) -> PickWindow:
    """The arm's :class:`PickWindow` from its task map's feasible grid points."""
    u_base = float(belt.to_belt(station.base_to_world[:3, 3])[0])
    ok = np.isfinite(task_map.approach) & np.isfinite(task_map.leave)
    cols = np.flatnonzero(ok.any(axis=1))
    if cols.size == 0:
        check_reach(station, belt, 0.0, tolerance=0.0)
        raise BeltOutOfReach(f"arm {station.name!r}: no pick on the belt is feasible at {belt.speed} m/s "
                             "(reach, tool orientation or joint limits); slow the belt or move the arm")
    return PickWindow(station.name, u_base + float(task_map.du[cols[0]]), u_base + float(task_map.du[cols[-1]]), u_base)


__all__.append("window_of")
