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

from pinarms.optim.line.api import (LineCurve, LineResult, LineSpec, LineStatus, Stream, build_maps, line_curve,
                                    run_line)
from pinarms.optim.line.belt import Belt, PlaceBox
from pinarms.optim.line.errors import ArrivalsFileError, BeltOutOfReach
from pinarms.optim.line.items import ItemType, Items, poisson_items, read_arrivals, regular_items
from pinarms.optim.line.report import LineFigures, summarise
from pinarms.optim.line.rules import RULES, AssignmentRule, Rule
from pinarms.optim.line.schedule import LineSchedule, schedule_line
from pinarms.optim.line.simulate import SimArm, SimResult, simulate
from pinarms.optim.line.station import Station, base_pose
from pinarms.optim.line.task_map_build import build_task_map, measure_yaw
from pinarms.optim.line.task_map_error import MapError, map_error
from pinarms.optim.line.task_maps import TaskMap
from pinarms.optim.line.tracking import PickPlan, TrackingSpec, plan_pick
from pinarms.optim.line.tray_maps import TrayMap, build_tray_map, tray_map_error
from pinarms.optim.line.tray_sim import SimPlace
from pinarms.optim.line.trays import TrayBelt, TrayPickPlan, plan_pick_to_tray, trays_beside
from pinarms.optim.line.windows import PickWindow, check_reach

__all__ = [
    "LineSchedule", "schedule_line",
    "Belt", "PlaceBox", "ItemType", "Items", "poisson_items", "regular_items", "read_arrivals",
    "Station", "base_pose", "TrackingSpec", "PickPlan", "plan_pick", "PickWindow", "check_reach",
    "TaskMap", "build_task_map", "measure_yaw", "map_error", "MapError", "Rule", "RULES", "AssignmentRule",
    "SimArm", "SimResult", "simulate",
    "LineFigures", "summarise", "Stream", "LineSpec", "LineResult", "LineStatus", "run_line", "build_maps", "LineCurve", "line_curve",
    "BeltOutOfReach", "ArrivalsFileError", "TrayBelt", "TrayPickPlan", "plan_pick_to_tray",
    "TrayMap", "build_tray_map", "tray_map_error", "SimPlace", "trays_beside",
]
