"""The simulator against its own recorded outputs: every rule, shipped and custom lines, exactly.

The figures below were recorded from the simulator before its rules became objects and its loop
was compiled (the first commit of that work): per run the picks, misses, decisions, picks per arm,
neighbour checks, and a digest of every item's arm, rendezvous, pre-grasp point, start and finish
(floats at 10 significant digits, tray columns too when the line places in trays). A refactoring
or a faster loop must give the same runs; a change of behaviour shows here as a changed digest.
"""

import hashlib

import numpy as np
import pytest

from pinarms.optim.line.api import LineSpec, Stream, run_line
from pinarms.optim.line.belt import Belt, PlaceBox
from pinarms.optim.line.items import ItemType, poisson_items, regular_items
from pinarms.optim.line.rules import RULES, Rule
from pinarms.optim.line.simulate import SimArm, simulate
from pinarms.optim.line.station import Station, base_pose
from pinarms.optim.line.task_maps import TaskMap
from pinarms.optim.line.tracking import TrackingSpec
from pinarms.optim.line.tray_map import TrayMap
from pinarms.optim.line.tray_sim import SimPlace
from pinarms.optim.line.trays import TrayBelt

BELT = Belt((0.0, 0.0, 0.8), speed=0.2, width=0.3, length=4.0)


def fingerprint(r) -> tuple:
    """(picks, misses, decisions, picks per arm, checks, digest of every item's columns)."""
    h = hashlib.sha256(np.asarray(r.picked_by, np.int64).tobytes())
    columns = [r.meet, r.u_meet, r.start, r.finish]
    if r.tray is not None:
        h.update(np.asarray(r.tray, np.int64).tobytes())
        h.update(np.asarray(r.no_tray, bool).tobytes())
        columns += [r.u_place, r.place_time, r.place_wait]
    for c in columns:
        h.update(" ".join(f"{x:.10g}" for x in c).encode())
    per_arm = tuple(int(x) for x in np.bincount(r.picked_by[r.picked_by >= 0], minlength=len(r.arms)))
    return r.picks, r.misses, r.decisions, per_arm, tuple(r.checks), h.hexdigest()[:16]


def synthetic_map(name, t_a, leave, du=np.linspace(-0.3, 0.3, 13)):
    """A map whose leave time grows across the belt (``leave`` at w = ±0.15 m), holes at its ends."""
    a = np.full((du.size, 2), float(t_a))
    a[0, 0] = np.nan  # the upstream corner is out of reach
    c = np.tile(np.asarray(leave, float), (du.size, 1))
    return TaskMap(name, du, np.array([-0.15, 0.15]), a, c, 0.5, 0.1, BELT.speed, 0.1)


def custom_spec(rule: Rule) -> tuple[LineSpec, dict]:
    """Three arms of seed 000's SCARA (robot only: synthetic maps), two item types, overlapping windows."""
    from pinarms import robots

    robot = robots.load("scara_mushroom")
    stations = tuple(Station(f"s{k}", robot, base_pose(0.8 + 0.45 * k, 0.3, 0.78),
                             PlaceBox((0.6 + 0.45 * k, 0.45, 0.93))) for k in range(3))
    types = (ItemType("small", 0.1, (0.06, 0.05, 0.04)), ItemType("large", 0.3, (0.1, 0.08, 0.05)))
    maps = {s.name: (synthetic_map(f"{s.name} small", 0.4 + 0.05 * k, [0.3, 1.4]),
                     synthetic_map(f"{s.name} large", 0.5, [0.6, 2.2]))
            for k, s in enumerate(stations)}
    spec = LineSpec(BELT, stations, Stream("poisson", 1.4, 200.0, types=types), TrackingSpec(), rule, seeds=(3, 4))
    return spec, maps


def _preset(name: str, rule: Rule):
    from dataclasses import replace

    from pinarms.studies.line import gantry_line, maps_for, scara_line

    if name == "scara":
        spec = scara_line(4, 120.0, seeds=(0, 1), duration=240.0)
    else:
        spec = gantry_line(60.0, seeds=(0, 1), duration=240.0)
    spec = replace(spec, rule=rule)
    return spec, maps_for(spec, build=False)


#: The look-ahead's horizon on each line (8, the largest, on the shipped SCARAs).
HORIZON = {"scara": 8, "gantry": 5, "custom": 6}

RECORDED = {
    ('scara', 'first'): [
        (277, 212, 321, (73, 71, 69, 64), (0, 0), '5424061d0c650634'),
        (277, 204, 315, (73, 70, 69, 65), (0, 0), 'ca13849cd8fc6789'),
    ],
    ('scara', 'nearest'): [
        (269, 220, 305, (68, 68, 68, 65), (0, 0), 'a8aac7c72b785307'),
        (270, 211, 303, (71, 68, 67, 64), (0, 0), '99cf2496afb33bcc'),
    ],
    ('scara', 'shortest'): [
        (278, 211, 324, (73, 71, 70, 64), (0, 0), 'f7d52462b4c6990b'),
        (278, 203, 313, (73, 71, 69, 65), (0, 0), 'cb0bcbe5847a4a82'),
    ],
    ('scara', 'bands'): [
        (222, 267, 360, (46, 62, 63, 51), (0, 0), 'e847e79d4680f932'),
        (224, 257, 352, (46, 61, 62, 55), (0, 0), '4fc17e78a78157c2'),
    ],
    ('scara', 'split'): [
        (263, 226, 329, (66, 65, 66, 66), (0, 0), '3958f28247c68074'),
        (262, 219, 334, (67, 65, 64, 66), (0, 0), '6bb2961032d3e55c'),
    ],
    ('scara', 'lookahead'): [
        (278, 211, 320, (73, 71, 70, 64), (0, 0), 'bcf751775004a4fe'),
        (279, 202, 315, (73, 73, 69, 64), (0, 0), '1ba4ecf83e7afd04'),
    ],
    ('gantry', 'first'): [
        (153, 93, 164, (153,), (0, 0), 'b0d0c1e5ba6c0b92'),
        (144, 96, 163, (144,), (0, 0), 'e67e01029d7c251c'),
    ],
    ('gantry', 'nearest'): [
        (156, 90, 168, (156,), (0, 0), '57dc06d193ee5e86'),
        (152, 88, 173, (152,), (0, 0), 'a4b201a1ab6a2b32'),
    ],
    ('gantry', 'shortest'): [
        (158, 88, 177, (158,), (0, 0), '27e542ee7ababae4'),
        (153, 87, 177, (153,), (0, 0), '148fd51be4972941'),
    ],
    ('gantry', 'bands'): [
        (153, 93, 164, (153,), (0, 0), 'b0d0c1e5ba6c0b92'),
        (144, 96, 163, (144,), (0, 0), 'e67e01029d7c251c'),
    ],
    ('gantry', 'split'): [
        (153, 93, 164, (153,), (0, 0), 'b0d0c1e5ba6c0b92'),
        (144, 96, 163, (144,), (0, 0), 'e67e01029d7c251c'),
    ],
    ('gantry', 'lookahead'): [
        (162, 84, 167, (162,), (0, 0), 'dc466ff715992520'),
        (154, 86, 164, (154,), (0, 0), 'e496dee7a9a43636'),
    ],
    ('custom', 'first'): [
        (227, 25, 320, (94, 80, 53), (0, 0), '06324fc45aa5dc20'),
        (243, 72, 307, (91, 89, 63), (0, 0), '3cccd62edf23cf7e'),
    ],
    ('custom', 'nearest'): [
        (215, 37, 307, (85, 77, 53), (0, 0), 'd9b27aa1ca8a857a'),
        (230, 85, 286, (84, 82, 64), (0, 0), 'ac851b2718932997'),
    ],
    ('custom', 'shortest'): [
        (229, 23, 316, (105, 78, 46), (0, 0), 'd3cc50fa9f43b33a'),
        (255, 60, 313, (112, 85, 58), (0, 0), '48400112c0721afc'),
    ],
    ('custom', 'bands'): [
        (195, 57, 308, (75, 70, 50), (0, 0), 'a98d94c2a1fb8821'),
        (221, 94, 306, (80, 81, 60), (0, 0), '40f710df2ecdc74d'),
    ],
    ('custom', 'split'): [
        (229, 23, 344, (76, 76, 77), (0, 0), 'e6211f9db87af74a'),
        (247, 68, 326, (83, 82, 82), (0, 0), '319eece3bb4ba96e'),
    ],
    ('custom', 'lookahead'): [
        (230, 22, 307, (108, 78, 44), (0, 0), '7f2b3e3f536adc96'),
        (259, 56, 308, (112, 85, 62), (0, 0), '6e7b6b31ca8718f5'),
    ],
}


def _runs(line: str, rule: str) -> list:
    r = Rule(rule, HORIZON[line] if rule == "lookahead" else 4)
    spec, maps = custom_spec(r) if line == "custom" else _preset(line, r)
    return [fingerprint(x) for x in run_line(spec, maps=maps).runs]


@pytest.mark.parametrize("line", ["scara", "gantry", "custom"])
@pytest.mark.parametrize("rule", RULES)
def test_run_line_gives_the_recorded_runs(line, rule):
    assert _runs(line, rule) == RECORDED[(line, rule)]


def tray_map() -> TrayMap:
    """Two place branches whose transfer grows downstream on the tray belt, a gap on each branch."""
    du, w, dv = np.array([-0.2, 0.0, 0.2]), np.array([-0.1, 0.1]), np.linspace(-0.3, 0.3, 6)
    x = 0.8 + 0.5 * (dv + 0.3) + 0.2 * w[:, None] + 0.1 * du[:, None, None]
    X = np.stack([x, x[..., ::-1] + 0.15])
    R = 0.6 + 0.25 * np.abs(X - 1.0)
    X[0, :, :, 2], X[1, :, :, -1] = np.nan, np.nan
    R[np.isnan(X)] = np.nan
    A = 1.0 + 0.3 * np.abs(du)[:, None] + 0.1 * w[None, :]
    return TrayMap("t", du, w, dv, A, X, R, 0.5, 0.5, BELT.speed, 0.1, 0.1, branches=(0, 1),
                   pick_branch=np.zeros((du.size, w.size), int))


def _tray_runs() -> list:
    """Two arms placing in trays (a map with holes and two place branches), first in window and nearest."""
    trays = TrayBelt(Belt((0.0, 0.6, 0.8), speed=0.1, width=0.2, length=4.0), pitch=0.3, capacity=2, phase=0.137)
    tm = tray_map()
    arms = [SimArm(n, u, (tm.pick_map,), place=SimPlace(tm, trays, v)) for n, u, v in (("a", 1.0, 1.0), ("b", 1.5, 1.5))]
    out = []
    for rule in ("first", "nearest", "shortest"):
        items = poisson_items(BELT, 0.8, 150.0, seed=7)
        r = simulate(arms, items, BELT.speed, rule, duration=150.0)
        out.append(fingerprint(r) + (r.trays_seen, r.trays_unfilled, f"{r.tray_fill:.10g}", r.unplaced))
    return out


RECORDED_TRAYS: list = [
    (72, 52, 136, (39, 33), (0, 0), '2551e4a45fbaf7d9', 46, 26, '0.6956521739', 0),
    (71, 53, 134, (39, 32), (0, 0), '98951d72f04806a9', 46, 26, '0.6956521739', 0),
    (72, 52, 136, (39, 33), (0, 0), 'fddc395c6d1c1edd', 46, 26, '0.6956521739', 0),
]


def test_trays_give_the_recorded_runs():
    assert _tray_runs() == RECORDED_TRAYS


def near_guard(pick: tuple, other: tuple) -> bool:
    """A guard by rendezvous alone: two picks are clear when their rendezvous are 1 s apart or more
    (the simulator's contract: ``guard(pick, other) -> bool`` with the picks as it passes them)."""
    assert len(pick) == len(other) == 7
    return abs(pick[3] - other[3]) >= 1.0 or abs(pick[4] - other[4]) >= 0.25


def _guard_runs() -> list:
    """Three arms with overlapping windows, a guard that blocks close rendezvous, every simple rule."""
    arms = [SimArm(f"a{k}", 1.0 + 0.4 * k, (synthetic_map("m", 0.4, [0.3, 1.2]),), rest=(0.8 + 0.4 * k, 0.3))
            for k in range(3)]
    out = []
    for rule in ("first", "nearest", "shortest", "bands", "split"):
        items = regular_items(BELT, 0.7, 120.0, seed=2)
        r = simulate(arms, items, BELT.speed, rule, duration=120.0, width=BELT.width, guard=near_guard)
        out.append(fingerprint(r))
    return out


RECORDED_GUARD: list = [
    (172, 0, 246, (69, 52, 51), (293, 88), '12a8e752b642b8c8'),
    (171, 1, 230, (65, 66, 40), (221, 22), '6c53f5d7a19b78ac'),
    (171, 1, 228, (77, 57, 37), (227, 30), 'f9ce5d8f07743591'),
    (144, 28, 211, (53, 55, 36), (151, 24), '2a9dee49d4d4598e'),
    (172, 0, 339, (58, 57, 57), (206, 0), '96f2e858fea30535'),
]


def test_guarded_neighbours_give_the_recorded_runs():
    assert _guard_runs() == RECORDED_GUARD
