"""The pick-and-place cycle: ``cycle``."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import click
import numpy as np

from pinarms.cli._common import (
    NUMBERS,
    cli,
    emit,
    fmt,
    load_robot,
    new_session,
    save_session,
)
from pinarms.cli.option_groups import Flag, LoadFlags, OutputFlags, TimingFlags, UnitFlags, flag, option_group


# --------------------------------------------------------------------------- cycle
@dataclass(frozen=True)
class CycleTask:
    """The pick and the place (base frame, user lengths), the transfer's via points, the lift (``None``:
    0.05 m) and the gripper's dwell [s]."""

    pick: tuple[float, float, float]
    place: tuple[float, float, float]
    via: tuple[tuple[float, float, float], ...] = ()
    lift: float | None = None
    dwell: float = 0.2

    FLAGS: ClassVar[tuple[Flag, ...]] = (
        flag("--pick", nargs=3, type=float, required=True, help="X Y Z of the pick point (base frame)."),
        flag("--place", nargs=3, type=float, required=True, help="X Y Z of the place point (base frame)."),
        flag("--via", nargs=3, type=float, multiple=True, help="X Y Z of a transfer via point (repeat, in order)."),
        flag("--lift", default=None, type=float, help="Vertical approach/retreat height [default 0.05 m, 50 mm]."),
        flag("--dwell", default=0.2, show_default=True, type=float, help="Gripper time at pick and at place [s]."),
    )

    def spec(self, scale: float):
        """The :class:`pinarms.optim.PickPlace` in SI, lengths typed times ``scale`` [m per unit]."""
        from pinarms import optim

        lift = 0.05 if self.lift is None else self.lift * scale
        return optim.PickPlace(np.array(self.pick) * scale, np.array(self.place) * scale, lift=lift, dwell=self.dwell,
                               via=[np.array(v) * scale for v in self.via])


@dataclass(frozen=True)
class ApproachFlags:
    """The approach and retreat: straight vertical lines (``straight``, with a tcp speed limit ``vtool``
    [user lengths / s]) or joint-space moves."""

    straight: bool = False
    vtool: float | None = None

    FLAGS: ClassVar[tuple[Flag, ...]] = (
        flag("--straight", is_flag=True,
             help="Straight vertical lines at pick and place, time-optimal along them (needs --amax); "
                  "the joint-space cycle's time is reported beside it."),
        flag("--vtool", default=None, type=float,
             help="With --straight: tcp speed limit on the lines [m/s, or mm/s with --mm]."),
    )


@cli.command("cycle", context_settings=NUMBERS)
@click.argument("robot")
@option_group(CycleTask, "task")
@option_group(UnitFlags, "units", only=("mm",), mm={"help": "Points, lift and the straightness deviation in millimetres."})
@option_group(TimingFlags, "timing")
@option_group(LoadFlags, "load", payload={"help": (
    "What the gripper carries from pick to place, e.g. 3kg or 800g (its centre of mass at the tcp); "
    "times both moves also under joint torque limits (--torque-max, default the URDF's efforts).")},
    torque={"help": "Also limit joint torques (the URDF's efforts), without a payload."})
@option_group(ApproachFlags, "approach")
@option_group(OutputFlags, "output", only=("session_path", "as_json"), session_path={
    "help": "Save the cycle (trajectory, via points, pick and place) into a session file."})
def cycle_cmd(robot: str, task: CycleTask, units: UnitFlags, timing: TimingFlags, load: LoadFlags,
              approach: ApproachFlags, output: OutputFlags) -> None:
    """Time-optimal pick-and-place cycle of ROBOT: pick, lift, transfer, lower, place, and back.

    Prints the time of each move, the cycle time, picks per minute and how far the tcp
    leaves the straight vertical approach/retreat lines (optim.plan_cycle; the tool points
    down on 6+ joint arms). Limits are SI per joint; --mm converts only lengths.

    With --payload (or --torque) both moves are also timed under joint torque limits, the
    move to place carrying the payload and the move back empty (robots' inverse dynamics,
    Pinocchio's RNEA).

    With --straight the tcp rises and lowers on straight vertical lines (within 0.1 mm),
    timed time-optimally along them; the arm stops at the lift points.

    Example: pinarms cycle aubo_i3 --pick 350 200 150 --place -100 400 100 --mm --payload 3kg
    """
    from pinarms import optim
    from pinarms.optim.cycle import CycleApproach, CycleLoad, CycleRequest, CycleTiming

    arm = load_robot(robot)
    scale = units.length
    lu = units.length_unit
    spec = task.spec(scale)
    lift_m, dwell, kind, method = spec.lift, spec.dwell, timing.kind, timing.method
    kg = load.kg
    cycle_timing = CycleTiming(kind, *timing.limits(np.ones(arm.nq)), method=method, seed=timing.seed)
    shape = CycleApproach("straight" if approach.straight else "joint",
                          None if approach.vtool is None else approach.vtool * scale)
    res = optim.plan_cycle(CycleRequest(arm, spec, timing=cycle_timing, load=CycleLoad(kg, load.torque_limits(arm.nq)),
                                        approach=shape)).raise_for_status()  # no cycle: one Error line saying why
    data = res.as_dict()
    data["units"] = {"lengths": "m", "times": "s", "limits": "rad or m per s^k", "given_points": lu}
    dev = res.line_deviation / scale
    lines = [
        (f"{arm.name}: pick-and-place cycle, {kind} ({method}), lift {lift_m / scale:g} {lu}, "
         f"dwell {dwell:g} s at pick and place"),
        f"  move to place: {res.move_times[0]:.4f} s  (segments {fmt(res.moves[0].durations, 4)} s)",
        f"  move to pick:  {res.move_times[1]:.4f} s  (segments {fmt(res.moves[1].durations, 4)} s)",
        f"cycle time {res.cycle_time:.4f} s, {res.picks_per_minute:.2f} picks per minute",
        "peak / limit: " + ", ".join(f"{k} {v.max():.4f}" for k, v in res.limit_ratios.items()),
        f"tcp off the vertical lines [{lu}]: "
        + ", ".join(f"{name} {d:.4g}" for name, d in zip(optim.cycle.LINE_NAMES, dev)),
        "IK: one branch for every waypoint" if res.one_branch else
        f"IK: branches {res.branches.tolist()} (the joint limits force a switch, or the arm is solved numerically)",
    ]
    if res.approach == "straight":
        lines.insert(4, f"straight lines: joint-space cycle {res.joint_cycle_time:.4f} s "
                        f"(straight {res.straight_cost:+.4f} s); the four lines take {res.line_cost:+.4f} s "
                        "beside joint-space lines between the same configurations")
    if res.torque_limit is not None:
        carried = "nothing" if res.payload is None else f"{res.payload.mass:g} kg"
        lines.insert(4, f"torque / limit (carrying {carried} to the place, empty back): "
                        + ", ".join(f"{n} {r:.3f}" for n, r in zip(arm.joint_names, res.torque_ratios)))
    if output.session_path:
        session = new_session(arm if res.payload is None else arm.with_payload(res.payload),
                              f"pick-and-place cycle of {arm.name}")
        session.add_trajectory("cycle", res.trajectory)
        session.add_points("cycle_via_points", res.waypoints[:, :3, 3], kind="via")
        place_m = res.waypoints[res.names.index("place"), :3, 3]
        session.add_points("pick_place", np.stack([res.waypoints[0, :3, 3], place_m]), kind="target")
        save_session(session, output.session_path, data, lines)
    emit(output.as_json, data, lines)


