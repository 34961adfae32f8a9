"""What a task map build is asked and what it answers: one frozen request in, one result with a status out.

The three map builds take the one shape of the project's big calls (:mod:`pinarms.optim.status`):

=======================================  =====================  ======================================
call                                     input                  result
=======================================  =====================  ======================================
:func:`~.task_map_build.build_task_map`  :class:`MapRequest`    :class:`MapResult` (a ``TaskMap``)
:func:`~.tray_maps.build_tray_map`       :class:`TrayMapRequest`  :class:`MapResult` (a ``TrayMap``)
:func:`~.delta_maps.build_delta_map`     :class:`DeltaMapRequest`  :class:`MapResult` (a ``TaskMap``)
=======================================  =====================  ======================================

Each request checks its own fields in ``__post_init__`` (:class:`~pinarms.errors.InvalidInput`
naming the field and its domain) before any planning; what needs the arm (its reach of the belt,
of its box, its place in a cell) is checked by the build, before its first plan. Where the work
runs (``scheduler``) and how it reports (``progress``) are keywords of the call.

The result's ``status`` (:class:`MapStatus`): ``built``; ``refine left`` (the refinement passes
asked for ran out while some node's time still bends more than the tolerance: the map holds, with
a larger interpolation error there; ``status_reason`` says where and what to raise); ``no feasible
node`` (every node planned and none is feasible: the map says so at every point).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Union

from pinarms.errors import InvalidInput
from pinarms.optim.line.belt import Belt
from pinarms.optim.line.station import Station
from pinarms.optim.line.tracking import TrackingSpec
from pinarms.optim.status import Status

if TYPE_CHECKING:
    from pinarms.optim.line.task_maps import TaskMap
    from pinarms.optim.line.tray_map import TrayMap
    from pinarms.optim.line.trays import TrayBelt
    from pinarms.robots.cell.cell import Cell

__all__ = ["MapRequest", "TrayMapRequest", "DeltaMapRequest", "MapResult", "MapStatus", "YAW_MODES",
           "TRAY_YAW_MODES"]

#: ``"auto"``: a yaw coordinate where the task time depends on yaw (measured); ``"axis"``: always
#: (arms that can turn their tool); ``"none"``: never, the spread not measured (the maps before).
YAW_MODES = ("auto", "axis", "none")
#: A tray map's: ``"auto"`` measures the yaw spread and stores it (no yaw coordinate: the map warns
#: above the tolerance); ``"none"``: not measured.
TRAY_YAW_MODES = ("auto", "none")


class MapStatus(Status):
    """How a map build ended (module doc)."""

    BUILT = "built"
    REFINE_LEFT = "refine left"
    NO_FEASIBLE = "no feasible node"


def _count(name: str, value: object, low: int) -> None:
    if isinstance(value, bool) or not isinstance(value, int) or value < low:
        raise InvalidInput(f"{name} must be an integer >= {low}, got {value!r}")


def _length(name: str, value: object, *, positive: bool = False) -> float:
    ok = isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(float(value))
    if not ok or float(value) < 0.0 or (positive and float(value) == 0.0):
        raise InvalidInput(f"{name} must be a finite number {'> 0' if positive else '>= 0'}, got {value!r}")
    return float(value)


def _span(name: str, value: object) -> None:
    """``value``: None or two finite numbers low < high [m]."""
    if value is None:
        return
    try:
        lo, hi = (float(v) for v in value)  # type: ignore[union-attr]
    except (TypeError, ValueError):
        raise InvalidInput(f"{name} must be two finite numbers, low < high [m], got {value!r}") from None
    if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
        raise InvalidInput(f"{name} must be two finite numbers, low < high [m], got {value!r}")


def _common(rq: "MapRequest | TrayMapRequest | DeltaMapRequest") -> None:
    """The fields every map request shares: station, belt, spec, mass, item height, margin."""
    if not isinstance(rq.station, Station):
        raise InvalidInput(f"station must be a Station (optim.line.Station), got {type(rq.station).__name__}")
    if not isinstance(rq.belt, Belt):
        raise InvalidInput(f"belt must be a Belt (optim.line.Belt), got {type(rq.belt).__name__}")
    if not isinstance(rq.spec, TrackingSpec):
        raise InvalidInput(f"spec must be a TrackingSpec, got {type(rq.spec).__name__}")
    _length("mass [kg]", rq.mass)
    _length("item_height [m]", rq.item_height)
    _length("margin [m]", rq.margin)
    if rq.belt.width / 2.0 - float(rq.margin) <= 0.0:
        raise InvalidInput(f"margin {rq.margin} m leaves no belt width (width {rq.belt.width} m)")
    _count("nu", rq.nu, 2)
    _count("nw", rq.nw, 2)


def _yaw_nodes(value: object) -> None:
    if isinstance(value, bool) or not isinstance(value, int) or value < 3 or value % 2 != 1:
        raise InvalidInput(f"yaw_nodes must be an odd integer >= 3 (0 is the middle node), got {value!r}")


def _cell(rq: "MapRequest | TrayMapRequest") -> None:
    if rq.cell is not None:
        from pinarms.optim.line.fixtures import check_in_cell, fixture_check

        check_in_cell(rq.cell, rq.station)
        fixture_check(rq.cell, rq.station.name, rq.clearance)  # a bad clearance: an error before any planning


@dataclass(frozen=True, eq=False)
class MapRequest:
    """One arm's box task map (:func:`~.task_map_build.build_task_map`).

    Attributes:
        station, belt, spec: the arm, the belt it picks from and how it picks.
        mass [kg], item_height [m]: the item's; margin [m]: kept free at each belt edge (``w``
            spans the belt's width less it).
        nu, nw: grid nodes along (``du``) and across (``w``) the belt (>= 2 each); du_range [m]:
            (low, high) of ``du`` from the arm's base (None: the span it reaches, sampled).
        refine: passes adding ``du`` columns and ``w`` rows where a time bends more than
            ``tolerance`` (relative) of the task time lets linear interpolation follow.
        cell, clearance [m]: a :class:`pinarms.robots.Cell` with the station as one of its arms:
            nodes whose planned pick comes closer than ``clearance`` to its fixtures are infeasible.
        yaw (:data:`YAW_MODES`), yaw_nodes (odd, >= 3), yaw_refine (passes): the item's yaw
            (:mod:`~.task_map_build`).

    Raises:
        InvalidInput: a field out of its domain (named), a cell without the station, a bad clearance.
    """

    station: Station
    belt: Belt
    spec: TrackingSpec = TrackingSpec()
    mass: float = 0.1
    item_height: float = 0.04
    margin: float = 0.025
    nu: int = 24
    nw: int = 7
    du_range: tuple[float, float] | None = None
    refine: int = 0
    tolerance: float = 0.005
    cell: Cell | None = None
    clearance: float = 0.01
    yaw: str = "auto"
    yaw_nodes: int = 9
    yaw_refine: int = 2

    def __post_init__(self) -> None:
        _common(self)
        _span("du_range", self.du_range)
        _count("refine", self.refine, 0)
        _length("tolerance", self.tolerance, positive=True)
        if self.yaw not in YAW_MODES:
            raise InvalidInput(f"yaw must be one of {YAW_MODES}, got {self.yaw!r}")
        _yaw_nodes(self.yaw_nodes)
        _count("yaw_refine", self.yaw_refine, 0)
        _cell(self)


@dataclass(frozen=True, eq=False)
class TrayMapRequest:
    """One arm's pick-to-tray map (:func:`~.tray_maps.build_tray_map`): fields as :class:`MapRequest`'s,
    with ``trays`` (the tray belt), ``nv`` place nodes along it (>= 2) over ``dv_range`` [m] (None:
    the span the arm reaches), ``approach_map`` (the same station's box ``TaskMap`` at the belt's
    speed, whose finer grid gives the approach time), and the item's yaw: ``yaw``
    (:data:`TRAY_YAW_MODES`) and ``yaw_nodes`` (the grid whose probe yaws measure it, :mod:`~.tray_maps`).

    Raises:
        InvalidInput: a field out of its domain (named), an approach map of another belt speed.
    """

    station: Station
    belt: Belt
    trays: TrayBelt
    spec: TrackingSpec = TrackingSpec()
    mass: float = 0.1
    item_height: float = 0.04
    margin: float = 0.025
    nu: int = 10
    nw: int = 3
    nv: int = 8
    du_range: tuple[float, float] | None = None
    dv_range: tuple[float, float] | None = None
    approach_map: TaskMap | None = None
    cell: Cell | None = None
    clearance: float = 0.01
    yaw: str = "auto"
    yaw_nodes: int = 5

    def __post_init__(self) -> None:
        from pinarms.optim.line.task_maps import TaskMap
        from pinarms.optim.line.trays import TrayBelt

        m, speed = self.approach_map, float(getattr(self.belt, "speed", float("nan")))
        if m is not None and not (isinstance(m, TaskMap) and abs(m.speed - speed) <= 1e-9 * max(1.0, speed)):
            raise InvalidInput(f"approach_map must be the station's TaskMap built at the belt's {speed} m/s, got "
                               f"{getattr(m, 'speed', type(m).__name__)!r}")
        _common(self)
        if not isinstance(self.trays, TrayBelt):
            raise InvalidInput(f"trays must be a TrayBelt (optim.line.TrayBelt), got {type(self.trays).__name__}")
        _count("nv", self.nv, 2)
        _span("du_range", self.du_range)
        _span("dv_range", self.dv_range)
        if self.yaw not in TRAY_YAW_MODES:
            raise InvalidInput(f"yaw of a tray map must be one of {TRAY_YAW_MODES}, got {self.yaw!r}")
        _yaw_nodes(self.yaw_nodes)
        _cell(self)


@dataclass(frozen=True, eq=False)
class DeltaMapRequest:
    """A delta's task map (:func:`~.delta_maps.build_delta_map`): fields as :class:`MapRequest`'s, with
    ``n`` TOPP grid intervals per move (>= 4) and ``yaw_nodes`` (odd, >= 3) tool-yaw layers where
    the fourth axis makes the time depend on yaw; ``cell``, ``clearance``: a cell whose delta the station
    is (docs/cells.md): nodes whose pick path is not proven ``clearance`` [m] clear of its fixtures are
    infeasible (checked by the build).

    Raises:
        InvalidInput: a field out of its domain (named), a station without a delta.
    """

    station: Station
    belt: Belt
    spec: TrackingSpec = TrackingSpec()
    mass: float = 0.0
    item_height: float = 0.04
    margin: float = 0.025
    nu: int = 12
    nw: int = 5
    n: int = 24
    yaw_nodes: int = 33
    cell: Cell | None = None
    clearance: float = 0.01

    def __post_init__(self) -> None:
        from pinarms.optim.line.delta_tracking import DeltaArm

        if isinstance(self.station, Station) and not isinstance(self.station.robot, DeltaArm):
            raise InvalidInput(f"station {self.station.name!r} holds no delta (optim.line.delta_tracking.DeltaArm)")
        _common(self)
        _count("n", self.n, 4)
        _yaw_nodes(self.yaw_nodes)


@dataclass(frozen=True, eq=False)
class MapResult:
    """A built map and how the build went (module doc): ``status`` (:class:`MapStatus`) and
    ``status_reason`` (empty when built); ``task_map`` (a ``TaskMap``, or a ``TrayMap`` from
    :func:`~.tray_maps.build_tray_map`); ``plans``: picks planned (nodes × IK branches; a delta's
    timed picks); ``blocked``: of them, too close to the cell's fixtures; ``seconds``: the build's
    wall time; ``plan_cpu_seconds``: the CPU time the plans took, summed over the processes that
    ran them (what the build costs whatever the load of the machine; NaN where not measured)."""

    status: MapStatus
    status_reason: str
    task_map: Union[TaskMap, TrayMap]
    plans: int
    blocked: int
    seconds: float
    plan_cpu_seconds: float = float("nan")

    def __repr__(self) -> str:
        reason = f" ({self.status_reason})" if self.status_reason else ""
        return (f"MapResult({self.status}{reason}, {self.plans} plans, {self.blocked} blocked, "
                f"{self.seconds:.1f} s wall, {self.plan_cpu_seconds:.1f} s CPU planning: {self.task_map!r})")
