"""One node of a task map, planned: the plan, the fixture verdict, and the blocked count, shared by every map.

Box maps (:mod:`~.task_map_build`) and tray maps (:mod:`~.tray_maps`) plan their nodes the same
way: a pick is planned exactly (:func:`~.tracking.plan_pick` or :func:`~.trays.plan_pick_to_tray`);
a node whose plan raises (out of reach, infeasible limits) has no time; with a cell given, a node
whose whole planned trajectory comes closer than the clearance to the cell's fixtures
(:class:`~.fixtures.FixtureCheck`) has no time either and is counted as *blocked*.
:func:`plan_node` is that rule, once.

A map is planned on the execution layer (:func:`pinarms.execution.map_chunks`), one task per
``du`` column (or column and yaw). A worker process receives the station pickled with every task;
:func:`task_station` keeps the first copy it sees per map (``task["key"]``) and reuses it for the
map's later tasks, so the arm's caches (its IK solver, the hand joints, the limits) are built once
per process, as in a serial build where every task shares the caller's station.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Callable, TypeVar

from pinarms.errors import UnreachableTarget
from pinarms.optim.errors import InfeasibleProblem, OptimError

if TYPE_CHECKING:
    from pinarms.optim.line.fixtures import FixtureCheck
    from pinarms.optim.line.station import Station

Plan = TypeVar("Plan")

__all__ = ["plan_node", "node_fixtures", "task_station", "map_key", "plan_yaw", "PLAN_FAILURES"]

#: What a node's planning may raise when the pick is not possible there (the node has no time).
PLAN_FAILURES = (UnreachableTarget, InfeasibleProblem, OptimError)

#: {map key: the station first received for it (and its fixture check)}, per process (module doc)
_STATIONS: dict[str, Any] = {}


def map_key() -> str:
    """A key naming one map build in its tasks (``task["key"]``), distinct across builds."""
    import uuid

    return uuid.uuid4().hex


def task_station(task: dict) -> Station:
    """The task's station, the same object for every task of one map in this process (module doc)."""
    key = task.get("key")
    if key is None:
        return task["station"]
    if len(_STATIONS) > 16:  # maps of other builds: drop them
        _STATIONS.clear()
    return _STATIONS.setdefault(str(key), task["station"])


def node_fixtures(task: dict) -> FixtureCheck | None:
    """The task's :class:`~.fixtures.FixtureCheck` for its station (None: no cell given), kept per map
    and process like :func:`task_station`."""
    if task.get("cell") is None:
        return None
    from pinarms.optim.line.fixtures import fixture_check

    key = task.get("key")
    if key is None:
        return fixture_check(task["cell"], task["station"].name, task["clearance"])
    known = _STATIONS.get(f"{key}:fixtures")
    if known is None:
        known = _STATIONS[f"{key}:fixtures"] = fixture_check(task["cell"], task["station"].name, task["clearance"])
    return known


def plan_node(plan: Callable[[], Plan], fixtures: FixtureCheck | None) -> tuple[Plan | None, bool]:
    """``(plan(), False)`` when the pick is possible and clear of the fixtures; ``(None, blocked)``
    otherwise, ``blocked`` True when the plan exists but comes closer than the clearance to the
    cell's fixtures (module doc)."""
    try:
        p = plan()
    except PLAN_FAILURES:
        return None, False
    verdict = "clear" if fixtures is None else fixtures.verdict(p.trajectory)  # type: ignore[attr-defined]
    if verdict != "clear":
        return None, verdict == "fixtures"
    return p, False


def plan_yaw(yaw: float, period: float) -> float:
    """The item yaw [rad] planned for tool-yaw node ``yaw``: the node itself, the last node
    (+period/2, the same grasp as -period/2 reached from the other side) just below it."""
    return min(float(yaw), period / 2.0 * (1.0 - 1e-9))
