"""The line: items on a moving belt, several arms picking on the fly, assignment, simulation, sizing.

- :mod:`~.belt` (:class:`Belt`, :class:`PlaceBox`), :mod:`~.items` (streams: Poisson, regular
  pitch, arrivals file), :mod:`~.station` (an arm beside the belt with its box and limits);
- :mod:`~.tracking` (:func:`plan_pick`: the rendezvous with a moving item, time-optimal),
  :mod:`~.trays` (:func:`plan_pick_to_tray`: the place as a second rendezvous, with a tray on a second belt),
  :mod:`~.tray_maps` (:class:`TrayMap`: pick-to-tray times), :mod:`~.tray_sim` (tray slots in the simulation),
  :mod:`~.windows` (each arm's pick window), :mod:`~.task_maps` (task times built once,
  interpolated, with their error against exact planning);
- :mod:`~.rules` (assignment rules, one class each), :mod:`~.simulate` (event-based simulation of N arms;
  its loops :mod:`~.sim_loop` and, compiled, :mod:`~._sim_kernel`),
  :mod:`~.report` (picks/min, miss rate with its interval, utilisation, waits);
- :mod:`~.api` (:func:`run_line`: one :class:`LineSpec` in, one :class:`LineResult` out),
  :mod:`~.sizing` (fewest arms, positions and belt speed for a flow);
- :mod:`~.schedule` keeps the time offsets of several arms cycling together (:func:`schedule_line`).
"""

from __future__ import annotations

from pinarms.lazy import lazy_exports

#: Where each public name is defined: loaded on first use (:func:`pinarms.lazy.lazy_exports`).
_EXPORTS = {
    "LineCurve": "pinarms.optim.line.api",
    "LineResult": "pinarms.optim.line.api",
    "LineSpec": "pinarms.optim.line.api",
    "LineStatus": "pinarms.optim.line.api",
    "Stream": "pinarms.optim.line.api",
    "build_maps": "pinarms.optim.line.api",
    "line_curve": "pinarms.optim.line.api",
    "run_line": "pinarms.optim.line.api",
    "Belt": "pinarms.optim.line.belt",
    "PlaceBox": "pinarms.optim.line.belt",
    "ArrivalsFileError": "pinarms.optim.line.errors",
    "BeltOutOfReach": "pinarms.optim.line.errors",
    "ItemType": "pinarms.optim.line.items",
    "Items": "pinarms.optim.line.items",
    "poisson_items": "pinarms.optim.line.items",
    "read_arrivals": "pinarms.optim.line.items",
    "regular_items": "pinarms.optim.line.items",
    "LineFigures": "pinarms.optim.line.report",
    "summarise": "pinarms.optim.line.report",
    "RULES": "pinarms.optim.line.rules",
    "AssignmentRule": "pinarms.optim.line.rules",
    "Rule": "pinarms.optim.line.rules",
    "LineSchedule": "pinarms.optim.line.schedule",
    "schedule_line": "pinarms.optim.line.schedule",
    "SimArm": "pinarms.optim.line.simulate",
    "SimResult": "pinarms.optim.line.simulate",
    "simulate": "pinarms.optim.line.simulate",
    "Station": "pinarms.optim.line.station",
    "base_pose": "pinarms.optim.line.station",
    "MapRequest": "pinarms.optim.line.map_request",
    "TrayMapRequest": "pinarms.optim.line.map_request",
    "DeltaMapRequest": "pinarms.optim.line.map_request",
    "MapResult": "pinarms.optim.line.map_request",
    "MapStatus": "pinarms.optim.line.map_request",
    "build_task_map": "pinarms.optim.line.task_map_build",
    "measure_yaw": "pinarms.optim.line.task_map_build",
    "MapError": "pinarms.optim.line.task_map_error",
    "map_error": "pinarms.optim.line.task_map_error",
    "TaskMap": "pinarms.optim.line.task_maps",
    "PickPlan": "pinarms.optim.line.tracking",
    "TrackingSpec": "pinarms.optim.line.tracking",
    "plan_pick": "pinarms.optim.line.tracking",
    "TrayMap": "pinarms.optim.line.tray_map",
    "build_tray_map": "pinarms.optim.line.tray_maps",
    "tray_map_error": "pinarms.optim.line.tray_maps",
    "SimPlace": "pinarms.optim.line.tray_sim",
    "TrayBelt": "pinarms.optim.line.trays",
    "TrayPickPlan": "pinarms.optim.line.trays",
    "plan_pick_to_tray": "pinarms.optim.line.trays",
    "trays_beside": "pinarms.optim.line.trays",
    "PickWindow": "pinarms.optim.line.windows",
    "check_reach": "pinarms.optim.line.windows",
}

__all__ = [
    "LineSchedule", "schedule_line", "Belt", "PlaceBox", "ItemType", "Items", "poisson_items",
    "regular_items", "read_arrivals", "Station", "base_pose", "TrackingSpec", "PickPlan", "plan_pick",
    "PickWindow", "check_reach", "TaskMap", "build_task_map", "measure_yaw", "map_error", "MapError", "Rule",
    "RULES", "AssignmentRule", "SimArm", "SimResult", "simulate", "LineFigures", "summarise", "Stream",
    "LineSpec", "LineResult", "LineStatus", "run_line", "build_maps", "LineCurve", "line_curve",
    "BeltOutOfReach", "ArrivalsFileError", "TrayBelt", "TrayPickPlan", "plan_pick_to_tray", "TrayMap",
    "build_tray_map", "tray_map_error", "SimPlace", "trays_beside", "MapRequest", "TrayMapRequest",
    "DeltaMapRequest", "MapResult", "MapStatus",
]

__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
