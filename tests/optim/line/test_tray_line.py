"""Trays in the task maps and the simulation: a brute-force reference, FK at a simulated place, bad input."""

import numpy as np
import pytest

from pinarms.optim.line.belt import Belt
from pinarms.optim.line.items import regular_items
from pinarms.optim.line.simulate import NO_TRAY, SimArm, simulate
from pinarms.optim.line.tracking import TrackingSpec
from pinarms.optim.line.tray_map import TrayMap
from pinarms.optim.line.tray_sim import SimPlace, tray_counts
from pinarms.optim.line.trays import TrayBelt

BELT = Belt((0.0, 0.0, 0.8), speed=0.2, width=0.3, length=4.0)
TA, TRACK, TX, PLACE, TR = 0.5, 0.5, 0.7, 0.5, 0.6
U_BASE, U0, U1 = 1.0, 0.0, 0.01  # pick window u in [1.0, 1.01] m
V_BASE, V0, V1 = 1.0, 0.0, 0.02  # place window v in [1.0, 1.02] m


def const_tray_map(tray_speed):
    du, w, dv = np.array([U0, U1]), np.array([-0.15, 0.15]), np.array([V0, V1])
    return TrayMap("a", du, w, dv, np.full((2, 2), TA), np.full((1, 2, 2, 2), TX), np.full((1, 2, 2, 2), TR), TRACK,
                   PLACE, BELT.speed, tray_speed, 0.1)


def brute_force(t0, trays, duration):
    """One arm, first in window, constant times, written directly: each item in order is met at
    max(ready + t_A, entry) while in the window; its place is the first tray in order with a free
    slot passing the place window after the transfer, up to the first tray to enter it after."""
    V, p, ph, cap = trays.belt.speed, trays.pitch, trays.phase, trays.capacity
    v0, v1 = V_BASE + V0, V_BASE + V1
    ready, fill, tray_of = 0.0, {}, np.full(t0.size, NO_TRAY, dtype=np.int64)
    for i, t in enumerate(t0):
        meet = max(ready + TA, t + (U_BASE + U0) / BELT.speed)
        if meet > t + (U_BASE + U1) / BELT.speed + 1e-12:
            continue  # the arm is late: missed
        arrive = meet + TRACK + TX
        k = int(np.ceil((V * arrive - v1 + ph) / p - 1e-9))
        while True:
            t_entry, t_exit = (v0 - ph + k * p) / V, (v1 - ph + k * p) / V
            if fill.get(k, 0) < cap and t_exit >= arrive:
                break
            if t_entry >= arrive:  # the first tray to enter after the arm gets there is full too
                k = None
                break
            k += 1
        if k is None:
            continue
        fill[k] = fill.get(k, 0) + 1
        tray_of[i] = k
        ready = max(arrive, (v0 - ph + k * p) / V) + PLACE + TR
    lo = int(np.ceil((ph - v0) / p - 1e-9))
    hi = int(np.floor((V * duration - v1 + ph) / p))
    seen = [fill.get(k, 0) for k in range(lo, hi + 1)]
    return tray_of, len(seen), sum(n < cap for n in seen), sum(seen) / (cap * len(seen))


@pytest.mark.parametrize("pitch, capacity, tray_speed, item_pitch", [
    (0.4, 2, 0.1, 2.0), (0.4, 3, 0.1, 2.0), (0.3, 1, 0.1, 2.0), (0.8, 1, 0.1, 1.7), (0.25, 2, 0.05, 3.1),
    (0.9, 4, 0.15, 1.3)])
def test_one_arm_regular_trays_matches_brute_force(pitch, capacity, tray_speed, item_pitch):
    trays = TrayBelt(Belt((0.0, 0.6, 0.8), speed=tray_speed, width=0.2, length=4.0), pitch=pitch,
                     capacity=capacity, phase=0.137)
    tm = const_tray_map(tray_speed)
    N = 60
    items = regular_items(BELT, item_pitch, N * item_pitch, w=0.0)
    arm = SimArm("a", U_BASE, (tm.pick_map,), place=SimPlace(tm, trays, V_BASE))
    r = simulate([arm], items, BELT.speed, duration=N * item_pitch)
    tray_of, seen, unfilled, fill = brute_force(items.t0, trays, N * item_pitch)
    assert np.array_equal(r.tray, tray_of)
    assert np.array_equal(r.picked_by >= 0, tray_of != NO_TRAY)
    assert (r.trays_seen, r.trays_unfilled) == (seen, unfilled)
    assert r.tray_fill == pytest.approx(fill, abs=1e-12)
    assert r.picks > 0
    # every tray holds at most its capacity; a picked item's place is inside the window, on its tray
    done = r.picked_by >= 0
    assert np.max(np.unique(r.tray[done], return_counts=True)[1]) <= capacity
    assert np.all((r.u_place[done] >= V_BASE + V0 - 1e-9) & (r.u_place[done] <= V_BASE + V1 + 1e-9))
    assert np.allclose(trays.tray_u(r.tray[done], r.place_time[done]), r.u_place[done], atol=1e-9)
    assert np.allclose(r.finish[done], r.place_time[done] + PLACE + TR)


def test_enough_slots_fill_closed_form():
    # an item every 2 s, one tray every 4 s, an arm fast enough to place each item in the tray in
    # its window: every item is placed and, past the first and last trays used, every tray holds
    # exactly 2 items (4 s of items): full with 2 slots, half full with 4
    trays2 = TrayBelt(Belt((0.0, 0.6, 0.8), speed=0.1, width=0.2, length=4.0), pitch=0.4, capacity=2, phase=0.137)
    trays4 = TrayBelt(trays2.belt, pitch=0.4, capacity=4, phase=0.137)
    items = regular_items(BELT, 2.0, 120.0, w=0.0)
    tm = const_tray_map(0.1)
    # a place window as long as a tray pitch: some tray is always there (no hold)
    tm = TrayMap("a", tm.du, tm.w, np.array([0.0, 0.45]), tm.approach, np.full((1, 2, 2, 2), 0.3),
                 np.full((1, 2, 2, 2), 0.3), 0.3, 0.3, BELT.speed, 0.1, 0.1)
    for trays in (trays2, trays4):
        r = simulate([SimArm("a", U_BASE, (tm.pick_map,), place=SimPlace(tm, trays, V_BASE))], items, BELT.speed,
                     duration=120.0)
        assert r.misses == 0 and r.unplaced == 0
        k, n = np.unique(r.tray, return_counts=True)
        assert np.array_equal(k, np.arange(k[0], k[-1] + 1))  # no tray skipped
        assert np.all(n[1:-1] == 2) and n.sum() == len(items)
        assert np.all(np.abs(r.place_wait) < 1e-9)
        assert r.trays_seen >= 25 and 0.0 < r.tray_fill <= 2.0 / trays.capacity
        assert r.trays_unfilled == (r.trays_seen if trays.capacity == 4 else r.trays_unfilled)


def test_full_trays_leave_items_unplaced():
    # two arms, one tray every 8 s with one slot, an item every second: every slot within the
    # second arm's reach is promised to the first when it decides, so it refuses items it could
    # pick (counted as unplaced, missed), and no tray ever holds two
    trays = TrayBelt(Belt((0.0, 0.6, 0.8), speed=0.1, width=0.2, length=4.0), pitch=0.8, capacity=1, phase=0.137)
    tm = const_tray_map(0.1)
    items = regular_items(BELT, 1.0, 200.0, w=0.0)
    arms = [SimArm(n, u, (tm.pick_map,), place=SimPlace(tm, trays, V_BASE)) for n, u in (("a", U_BASE), ("b", 2.0))]
    r = simulate(arms, items, BELT.speed, duration=200.0)
    assert 0 < r.unplaced <= r.misses
    assert np.max(np.unique(r.tray[r.picked_by >= 0], return_counts=True)[1]) == 1
    assert r.picks <= 200.0 / 8.0 + 3
    assert r.tray_fill == pytest.approx(1.0, abs=0.05)


def test_tray_counts_without_arms_is_empty():
    assert tray_counts([None], {}, 10.0)[:2] == (0, 0)


def _tool(station, q):
    T = station.robot.fk(q)
    return T[..., :3, 3] @ station.base_to_world[:3, :3].T + station.base_to_world[:3, 3]


def _velocity(station, q, qd):
    J = station.robot.jacobian(q)[:, :3, :]
    return np.einsum("nij,nj->ni", J, qd) @ station.base_to_world[:3, :3].T


@pytest.fixture(scope="module")
def tray_scene(scara_line):
    belt, station = scara_line
    trays = TrayBelt(Belt((0.0, 0.52, 0.82), speed=0.1, width=0.2, length=3.0), pitch=0.3, capacity=2, height=0.02)
    from pinarms.optim.line.map_request import TrayMapRequest
    from pinarms.optim.line.tray_maps import build_tray_map

    # du from 0.05 m: at du = 0, w = 0.05 m the rest elbow's approach swings joint 1 past its limit
    # (plan_pick takes the other elbow there, and a cell on two elbows holds no pick)
    tm = build_tray_map(TrayMapRequest(station, belt, trays, mass=0.1, nu=2, nw=2, nv=3, margin=0.1,
                                       du_range=(0.05, 0.1), dv_range=(0.05, 0.25), yaw="none")).task_map
    return belt, station, trays, tm


@pytest.mark.slow
def test_simulated_place_tracks_its_tray_from_fk(tray_scene):
    # a placement chosen by the simulation, planned exactly (pick at its rendezvous, place at its
    # pre-place point on the branch the map chose), its release dwell put on the simulation's clock:
    # the tool is on the promised tray's place point and moves with it
    from pinarms.optim.line.trays import plan_pick_to_tray

    belt, station, trays, tm = tray_scene
    assert np.isfinite(tm.transfer[:, :, :, 1:]).all()  # both elbows reach the place for dv >= 0.15 m
    u_base = float(belt.to_belt(station.base_to_world[:3, 3])[0])
    v_base = float(trays.belt.to_belt(station.base_to_world[:3, 3])[0])
    items = regular_items(belt, 4.0, 40.0, w=0.0)
    r = simulate([SimArm("scara 1", u_base, (tm.pick_map,), place=SimPlace(tm, trays, v_base))], items, belt.speed,
                 duration=40.0)
    done = np.flatnonzero(r.picked_by >= 0)
    assert done.size >= 5
    i = int(done[np.argmin(r.place_wait[done])])  # a place met at a crossing (no hold) if any
    du, dv = r.u_meet[i] - u_base, r.u_place[i] - v_base
    plan = plan_pick_to_tray(station, belt, trays, TrackingSpec(), r.u_meet[i], 0.0, r.u_place[i], mass=0.1,
                             place_branch=int(r.place_branch[i]))
    approx = sum(tm.times(du, 0.0, dv)) + tm.track + tm.place
    assert approx == pytest.approx(plan.duration, rel=0.01)  # the map's time of this placement
    t_place_plan = sum(plan.times[:3])
    tau = np.linspace(*plan.release_window, 101)  # plan time
    q, qd = plan.trajectory.sample(tau)[:2]
    t_sim = r.place_time[i] + (tau - t_place_plan)  # the simulation's clock at the place
    slot = trays.belt.to_world(trays.tray_u(r.tray[i], t_sim), trays.w, trays.height)
    assert np.max(np.linalg.norm(_tool(station, q) - slot, axis=1)) < 1e-3
    rel = np.linalg.norm(_velocity(station, q, qd) - trays.belt.velocity, axis=1)
    assert np.max(rel) < 0.01 * trays.belt.speed


def test_bad_tray_input(scara_line):
    from pinarms.optim.line.api import LineSpec
    from pinarms.optim.line.map_request import TrayMapRequest
    from pinarms.optim.line.tray_maps import build_tray_map
    from pinarms.optim.line.trays import parse_trays
    from pinarms.optim.line.windows import BeltOutOfReach
    from pinarms.errors import InvalidInput

    belt, station = scara_line
    for bad in (0.0, -0.1, float("nan")):
        with pytest.raises(InvalidInput, match="speed"):
            TrayBelt(Belt((0.0, 0.52, 0.82), speed=bad, width=0.2))
    with pytest.raises(InvalidInput, match="capacity"):
        TrayBelt(Belt((0.0, 0.52, 0.82), speed=0.1, width=0.2), capacity=0)
    with pytest.raises(InvalidInput, match="slots per tray"):
        parse_trays("0.3,0.1,1.5")
    far = TrayBelt(Belt((0.0, 3.0, 0.82), speed=0.1, width=0.2), pitch=0.3)
    with pytest.raises(BeltOutOfReach, match="scara 1"):
        build_tray_map(TrayMapRequest(station, belt, far))
    ok = TrayBelt(Belt((0.0, 0.52, 0.82), speed=0.1, width=0.2))
    with pytest.raises(InvalidInput, match="not in the line"):
        LineSpec(belt, (station,), trays={"scara 9": ok})
    tm = const_tray_map(0.1)
    placing = [SimArm("a", U_BASE, (tm.pick_map,), place=SimPlace(tm, ok, V_BASE))]
    with pytest.raises(InvalidInput, match="'lookahead' rule does not plan tray places"):
        simulate(placing, regular_items(BELT, 2.0, 10.0, w=0.0), BELT.speed, "lookahead")
    with pytest.raises(InvalidInput, match="neighbour check does not plan tray places yet; use no cell"):
        simulate(placing, regular_items(BELT, 2.0, 10.0, w=0.0), BELT.speed, "first", guard=lambda a, b: True)


def test_line_spec_with_trays_reports_tray_figures(scara_line):
    from pinarms.optim.line.api import LineSpec, Stream, run_line

    belt, station = scara_line
    trays = TrayBelt(Belt((0.0, 0.52, 0.82), speed=0.1, width=0.2, length=3.0), pitch=0.4, capacity=2, phase=0.137)
    spec = LineSpec(belt, (station,), Stream("regular", rate_per_s=0.5, duration=60.0), seeds=(0, 1), trays=trays)
    res = run_line(spec, maps={station.name: (const_tray_map(0.1),)})
    f = res.figures
    assert f.tray_fill_rate is not None and 0.0 < f.tray_fill_rate <= 1.0
    assert f.trays_unfilled >= 0 and 0.0 <= f.unplaced_rate <= f.miss_rate
    assert "tray_fill_rate" in f.as_dict()
    assert all(r.tray is not None for r in res.runs)
    box = run_line(LineSpec(belt, (station,), Stream("regular", rate_per_s=0.5, duration=60.0), seeds=(0,)),
                   maps={station.name: (const_tray_map(0.1).pick_map,)})
    assert box.figures.tray_fill_rate is None and "tray_fill_rate" not in box.figures.as_dict()
