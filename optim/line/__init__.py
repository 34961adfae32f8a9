"""The line: items on a moving belt, several arms picking on the fly, assignment, simulation, sizing.

- :mod:`~.belt` (:class:`Belt`, :class:`PlaceBox`), :mod:`~.items` (streams: Poisson, regular
  pitch, arrivals file), :mod:`~.station` (an arm beside the belt with its box and limits);
- :mod:`~.tracking` (:func:`plan_pick`: the rendezvous with a moving item, time-optimal),
  :mod:`~.trays` (:func:`plan_pick_to_tray`: the place as a second rendezvous, with a tray on a second belt),
  :mod:`~.tray_maps` (:class:`TrayMap`: pick-to-tray times), :mod:`~.tray_sim` (tray slots in the simulation),
  :mod:`~.windows` (each arm's pick window), :mod:`~.task_maps` (task times built once,
  interpolated, with their error against exact planning);
- :mod:`~.rules` (assignment rules), :mod:`~.simulate` (event-based simulation of N arms),
  :mod:`~.report` (picks/min, miss rate with its interval, utilisation, waits);
- :mod:`~.api` (:func:`run_line`: one :class:`LineSpec` in, one :class:`LineResult` out),
  :mod:`~.sizing` (fewest arms, positions and belt speed for a flow);
- :mod:`~.schedule` keeps the time offsets of several arms cycling together (:func:`schedule_line`).
"""

from __future__ import annotations

from pinarms.lazy import lazy_exports

#: Where each public name is defined: loaded on first use (:func:`pinarms.lazy.lazy_exports`).
_EXPORTS = {
    "LineCurve": ".api",
    "LineResult": ".api",
    "LineSpec": ".api",
    "Stream": ".api",
    "build_maps": ".api",
    "line_curve": ".api",
    "run_line": ".api",
    "Belt": ".belt",
    "PlaceBox": ".belt",
    "ArrivalsFileError": ".errors",
    "BeltOutOfReach": ".errors",
    "ItemType": ".items",
    "Items": ".items",
    "poisson_items": ".items",
    "read_arrivals": ".items",
    "regular_items": ".items",
    "LineFigures": ".report",
    "summarise": ".report",
    "RULES": ".rules",
    "Rule": ".rules",
    "LineSchedule": ".schedule",
    "schedule_line": ".schedule",
    "SimArm": ".sim_arm",
    "SimResult": ".simulate",
    "simulate": ".simulate",
    "Station": ".station",
    "base_pose": ".station",
    "MapError": ".task_maps",
    "TaskMap": ".task_maps",
    "build_task_map": ".task_maps",
    "map_error": ".task_maps",
    "PickPlan": ".tracking",
    "TrackingSpec": ".tracking",
    "plan_pick": ".tracking",
    "TrayMap": ".tray_maps",
    "build_tray_map": ".tray_maps",
    "tray_map_error": ".tray_maps",
    "SimPlace": ".tray_sim",
    "TrayBelt": ".trays",
    "TrayPickPlan": ".trays",
    "plan_pick_to_tray": ".trays",
    "trays_beside": ".trays",
    "PickWindow": ".windows",
    "check_reach": ".windows",
}

__all__ = [
    "LineSchedule", "schedule_line", "Belt", "PlaceBox", "ItemType", "Items", "poisson_items", "regular_items",
    "read_arrivals", "Station", "base_pose", "TrackingSpec", "PickPlan", "plan_pick", "PickWindow", "check_reach",
    "TaskMap", "build_task_map", "map_error", "MapError", "Rule", "RULES", "SimArm", "SimResult", "simulate",
    "LineFigures", "summarise", "Stream", "LineSpec", "LineResult", "run_line", "build_maps", "LineCurve",
    "line_curve", "BeltOutOfReach", "ArrivalsFileError", "TrayBelt", "TrayPickPlan", "plan_pick_to_tray", "TrayMap",
    "build_tray_map", "tray_map_error", "SimPlace", "trays_beside",
]

__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
