"""Seed 001, the parts beyond the paper's table: a planned move around the station's boxes, a
layout search, straight-line moves (:func:`pinarms.studies.seed001.study_001` calls them)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from pinarms.papers import SEED001
from pinarms.report import Row
from pinarms.robots import conventions as conv

from pinarms.optim.cycle.vertical import segment_distance
from pinarms.studies.study import MM

if TYPE_CHECKING:
    from pinarms.optim.layout.result import LayoutSearch
    from pinarms.optim.topp.path_timing import PathTiming
    from pinarms.robots import Robot

__all__ = ["planned_move_001", "layout_search_001", "straight_lines_001", "tool_speed_plot", "unwrap_rows"]


def planned_move_001() -> tuple[list[Row], dict[str, Any]]:
    """The rows of the planned move in the AUBO-i3 food station with a crate under a guard, and what the
    study draws (``trajectory``, ``boxes`` in the arm's base frame, the ``plan``).

    The move is :func:`pinarms.optim.motion.crate_guard.crate_guard_move` (planned once per process):
    RRT-Connect (the compiled search on the proven cover, OMPL where it finds nothing), every edge
    proven to keep 10 mm, shortcut, spline proven again, time-optimal under the URDF's joint speed and
    torque limits; every clear IK branch of the goal pose searched and the fastest of
    :data:`~pinarms.optim.motion.crate_guard.SEEDS` seeded searches kept; the row's note gives the
    median over them. Beside it the unobstructed move: the straight joint-space move between the same
    configurations, timed the same way (it runs through the cell: the row names the pair it hits).
    """
    from pinarms.optim.motion.crate_guard import SEEDS, crate_guard_move

    move = crate_guard_move()
    plan, pair = move.plan, move.straight_pair
    rows = [
        Row("001", f"planned move food table → crate under the guard (RRT-Connect, fastest of {len(SEEDS)} seeds, "
            "10 mm, time-optimal)", None, round(plan.duration, 3), "s", None,
            f"seed {move.seed}, median of the {len(SEEDS)} {np.median(move.durations):.3f} s; {plan.smoothing}, proven clear "
            f"(min {plan.clearance.min_environment * 1e3:.1f} mm, {plan.clearance.min_pair[0]} – "
            f"{plan.clearance.min_pair[1]}); search {plan.states} states"),
        Row("001", "the unobstructed move (straight in joint space, same limits)", None, round(move.straight.duration, 3),
            "s", None, f"goes {move.straight_depth * 1e3:.0f} mm into {pair.body_b} ({pair.body_a}): the detour costs "
            f"{plan.duration - move.straight.duration:+.3f} s"),
    ]
    arm = plan.cell.arm("aubo")
    boxes = [(shape.geometry, shape.size, arm.to_base(shape.shape_to_world))
             for fixture in plan.cell.fixtures for shape in fixture.shapes if shape.kind == "box"]
    return rows, {"trajectory": plan.trajectory, "boxes": boxes, "plan": plan}


def layout_search_001(arm: Robot) -> tuple[list[Row], LayoutSearch]:
    """Where to bolt the AUBO-i3 for the station's pick P1 → place P4 (optim.search_layout, small grid).

    Line frame = the paper's frame, whose x and y are ours negated: the paper's own base is
    the placement (0, 0, 0, yaw 180°). Base positions on a 100 mm grid around it (3 × 3, the
    same with ``quick``: a few seconds), no refinement (the CLI and benchmarks/sweep.py refine).
    Returns the table rows and the search (for its plot).
    """
    from pinarms import optim

    paper = SEED001
    pick = np.array(paper.table2_p1_p2_mm[0]) * MM
    lift = (paper.table2_p1_p2_mm[1][2] - paper.table2_p1_p2_mm[0][2]) * MM
    place = np.array([42.0, 222.0, 244.0]) * MM  # Table 2's P4, printed "(42222244)"
    cand = optim.grid_candidates(x=(-0.1, 0.1, 0.1), y=(-0.1, 0.1, 0.1), z=0.0, yaw=np.pi)
    res = optim.search_layout(optim.LayoutRequest(arm, pick, place, cand, lift=lift, refine=0,
                                                  workspace_samples=50_000))
    what = f"layout search ({len(cand)} base positions on a 100 mm grid around the paper's; pick P1 → place P4)"
    rows = []
    at_paper = int(np.flatnonzero(np.all(np.isclose(cand[:, :2], 0.0), axis=1))[0])
    cycle_note = (f"time-optimal cycle under the joint speed limits, tool pointing down, lift {lift / MM:.0f} mm, "
                  "dwell 0.2 s (optim.plan_cycle)")
    if res.failure[at_paper]:
        rows.append(Row("001", f"{what}: cycle at the paper's placement", None, res.failure[at_paper].value, "", None,
                        res.reason[at_paper].split(" (no IK")[0] + " (our tcp, tool pointing down)"))
    else:
        rows.append(Row("001", f"{what}: picks/min at the paper's placement", None,
                        float(res.picks_per_minute[at_paper]), "1/min", None, cycle_note))
    if res.status is optim.LayoutStatus.NO_PLACEMENT:
        rows.append(Row("001", f"{what}: best placement", None, "none", "", None,
                        "; ".join(sorted(set(f.value for f in res.failure if f)))))
        return rows, res
    x, y = res.best_placement[:2]
    rows.append(Row("001", f"{what}: best picks/min", None, res.best_picks_per_minute, "1/min", None,
                    f"base moved by ({x / MM:.0f}, {y / MM:.0f}) mm; {int(res.ok.sum())} of {len(cand)} run the cycle; "
                    + cycle_note))
    from pinarms.optim.layout.search import points_in_base_frame

    b = points_in_base_frame(np.vstack([pick, place]), res.best_placement[None])[0]
    r = np.linalg.norm(b - np.array([0.0, 0.0, 0.16]), axis=1) / MM
    inside = bool(np.all((b[:, 2] > 0) & (r > paper.table_r_min_mm) & (r < paper.table_r_max_mm)))
    rows.append(Row("001", f"{what}: P1, P4 distance from (0, 0, 160) mm at the best placement",
                    f"{paper.table_r_min_mm:.0f} < r < {paper.table_r_max_mm:.0f}", tuple(float(v) for v in np.round(r, 0)), "mm", None,
                    f"{'inside' if inside else 'outside'} the paper's band (z {b[0, 2] / MM:.0f} mm > 0)"))
    return rows, res


def straight_lines_001(arm: Robot, table2: np.ndarray, times: np.ndarray) -> tuple[list[Row], dict[str, Any]]:
    """The P1→P2 lift and P3→P4 lowering as straight tcp lines beside the paper's joint-space quintics.

    The paper gives no acceleration limit, so the straight moves use the paper's own kind of
    time law, a rest-to-rest quintic in time (here along the line), as short as the 210 °/s
    joint speed limit allows; the joint-space quintic between the same points is timed the
    same way. Straightness is checked by FK at ten times the line's knot density.
    """
    from pinarms import optim, planning

    q = conv.aubo_mdh_to_joint(table2)  # robot joint values, each angle in (-π, π]
    traj = planning.multi_quintic(times, unwrap_rows(q))
    T = arm.fk(q)
    v = arm.velocity_limit
    rows: list[Row] = []
    lines: dict[str, Any] = {}
    for i, (a, b) in enumerate(((0, 1), (2, 3))):
        name = f"P{a + 1}→P{b + 1}"
        tt = np.linspace(times[a], times[b], 2001)
        p = arm.position(traj(tt))
        pa, pb = T[a, :3, 3], T[b, :3, 3]
        vertical = abs((pb - pa)[2]) / np.linalg.norm(pb - pa) > 0.999
        what = "vertical" if vertical else "straight segment"
        note = ("the paper's joint-space quintic over 1 s; FK of its joint values" if vertical else
                "in our FK of the paper's joints this 45 mm move is slanted (its printed Cartesian P3/P4 are unreadable)")
        rows.append(Row("001", f"{name} paper quintic: tcp off the {what}", None,
                        float(np.round(segment_distance(p, pa, pb).max() / MM, 3)), "mm", None, note))
        path = planning.cartesian_path(arm, T[[a, b]], q_start=q[a])
        s = np.linspace(0.0, path.length, 10 * (path.breaks.size - 1) + 1)
        off = segment_distance(arm.position(path(s)), pa, pb).max()
        rows.append(Row("001", f"{name} straight line: tcp off the {what}", None, float(np.round(off / MM, 4)), "mm",
                        None, f"Cartesian path, 0.1 mm tolerance; FK at 10x its {path.breaks.size} knots"))
        straight = optim.time_scaled(path, [planning.JointVelocityConstraint(v)], shape="quintic")
        joint = optim.time_scaled(planning.joint_spline(q[[a, b]]), [planning.JointVelocityConstraint(v)])
        rows.append(Row("001", f"{name} straight, quintic time law at 210 °/s", float(times[b] - times[a]),
                        float(np.round(straight.duration, 4)), "s", None,
                        f"the paper takes 1 s; the joint-space quintic at the same limit {joint.duration:.4f} s "
                        f"(straight costs {100 * (straight.duration / joint.duration - 1):.1f} %)"))
        lines[f"P{a + 1}-P{b + 1}_straight"] = straight
    return rows, lines


def tool_speed_plot(path: Path, timing: PathTiming, title: str) -> Path:
    """The tcp's linear and angular speed along ``timing`` over time, written to ``path``."""
    from pinarms.viz import plots as vplots

    t = np.linspace(0.0, timing.duration, 400)
    lin, ang = timing.tool_speed(t)
    return vplots.plot_tool_speed(path, t, lin, angular=ang, title=title)


def unwrap_rows(q: np.ndarray) -> np.ndarray:
    """Joint via points without 2π jumps between consecutive rows."""
    return np.unwrap(np.asarray(q, dtype=float), axis=0)
