"""The simulator's tray place search against a brute force written directly, on maps with holes.

The CLI's tray run (`belt run --arms 1 --rate 10 --trays 0.3,0.1,2`) missed 61 % of its items:
(1) the place search sampled the map at its ``dv`` nodes, and a node evaluates in the cell that
starts there, so the last cell of every feasible run (before a hole or the window's end) was
lost; (2) the item intercept proposed picks in cells whose four pick nodes are on two elbows,
which the tray map calls infeasible: every such item was refused ("no slot") although slots
were free. These tests pin both against independent references.
"""

import numpy as np
import pytest

from pinarms.optim.line.belt import Belt
from pinarms.optim.line.items import regular_items
from pinarms.optim.line.simulate import SimArm, simulate
from pinarms.optim.line.tray_map import TrayMap
from pinarms.optim.line.tray_sim import SimPlace, find_place
from pinarms.optim.line.trays import TrayBelt
from pinarms.errors import InvalidInput

BELT = Belt((0.0, 0.0, 0.8), speed=0.2, width=0.3, length=4.0)
DU, W, DV = np.array([-0.2, 0.0, 0.2]), np.array([-0.1, 0.0, 0.1]), np.linspace(-0.3, 0.3, 6)


def holey_map(seed: int) -> TrayMap:
    """Two place branches, smooth random times, infeasible nodes: a hole in the middle of the place
    window on branch 0, the window's last node on branch 1, random single nodes."""
    rng = np.random.default_rng(seed)
    nb, nu, nw, nv = 2, DU.size, W.size, DV.size
    X = 0.8 + 0.4 * rng.random((nb, nu, nw, nv)) + 0.3 * DV / 0.3
    R = 0.6 + 0.3 * rng.random((nb, nu, nw, nv))
    X[0, :, :, 2] = np.nan
    X[1, :, :, -1] = np.nan
    X[rng.random(X.shape) < 0.08] = np.nan
    R[np.isnan(X)] = np.nan
    A = 1.0 + 0.2 * rng.random((nu, nw))
    return TrayMap("a", DU, W, DV, A, X, R, 0.5, 0.5, BELT.speed, 0.1, 0.1, branches=(0, 1),
                   pick_branch=np.zeros((nu, nw), int))


def _trilinear(tm: TrayMap, T: np.ndarray, b: int, du: float, w: float, c: int, v: np.ndarray) -> np.ndarray:
    """T on branch b in dv cell c at dv = v, NaN unless all eight nodes of the cell are feasible."""
    i = min(int(np.searchsorted(tm.du, du, side="right")) - 1, tm.du.size - 2)
    j = min(int(np.searchsorted(tm.w, w, side="right")) - 1, tm.w.size - 2)
    cube = T[b, i:i + 2, j:j + 2, c:c + 2]
    if not np.isfinite(cube).all():
        return np.full(v.size, np.nan)
    fu = (du - tm.du[i]) / (tm.du[i + 1] - tm.du[i])
    fw = (w - tm.w[j]) / (tm.w[j + 1] - tm.w[j])
    fv = (v - tm.dv[c]) / (tm.dv[c + 1] - tm.dv[c])
    uw = np.array([[(1 - fu) * (1 - fw), (1 - fu) * fw], [fu * (1 - fw), fu * fw]])
    lo, hi = np.einsum("ij,ij->", uw, cube[..., 0]), np.einsum("ij,ij->", uw, cube[..., 1])
    return lo * (1 - fv) + hi * fv


def brute_place(tm: TrayMap, trays: TrayBelt, v_base: float, du: float, w: float, meet: float, fill: dict):
    """Trays in order; each free tray's earliest place over every cell and branch, sampled densely;
    no tray past the first to enter the window once the arm could be anywhere in it."""
    V, te = trays.belt.speed, meet + tm.track
    cells = [(b, c, np.linspace(tm.dv[c], tm.dv[c + 1], 601)) for b in range(2) for c in range(tm.dv.size - 1)]
    x = {(b, c): _trilinear(tm, tm.transfer, b, du, w, c, v) for b, c, v in cells}
    finite = [a[np.isfinite(a)] for a in x.values()]
    if not any(a.size for a in finite):
        return None
    x_max = max(a.max() for a in finite if a.size)
    k_first = int(np.floor((V * te - v_base - tm.dv[-1] + trays.phase) / trays.pitch))  # earlier ones have left
    for k in range(k_first, k_first + 1000):
        if fill.get(k, 0) < trays.capacity:
            best = np.inf
            for b, c, v in cells:
                t_k = (v_base + v - trays.phase + k * trays.pitch) / V
                ok = np.isfinite(x[b, c]) & (te + x[b, c] <= t_k)
                if ok.any():
                    best = min(best, float(t_k[ok].min()))
            if np.isfinite(best):
                return k, best
        if (v_base + tm.dv[0] - trays.phase + k * trays.pitch) / V > te + x_max:
            return None
    return None


@pytest.mark.parametrize("seed", range(6))
def test_find_place_matches_brute_force(seed):
    tm = holey_map(seed)
    trays = TrayBelt(Belt((0.0, 0.6, 0.8), speed=0.1, width=0.2, length=4.0), pitch=0.3, capacity=2, phase=0.11)
    p = SimPlace(tm, trays, 1.0)
    rng = np.random.default_rng(100 + seed)
    found = 0
    for _ in range(25):
        du, w, meet = rng.uniform(-0.19, 0.19), rng.uniform(-0.09, 0.09), rng.uniform(5.0, 50.0)
        fill = {k: int(rng.integers(0, 3)) for k in range(-10, 200)}  # some trays full
        got = find_place(p, du, w, meet, {(7, k): n for k, n in fill.items()}, 7)
        ref = brute_place(tm, trays, 1.0, du, w, meet, fill)
        assert (got is None) == (ref is None)
        if got is None:
            continue
        found += 1
        assert got.tray == ref[0]
        # the dense reference lands within one sample (0.12/600 m at 0.1 m/s) after the exact crossing
        assert ref[1] - 2.1e-3 <= got.time <= ref[1] + 1e-9
        assert trays.tray_u(got.tray, got.time) == pytest.approx(got.v, abs=1e-9)
        # the place is reachable on the branch it names: the map's transfer there gets the arm in time
        c = int(np.clip(np.searchsorted(tm.dv, got.v - 1.0 + 1e-12, side="right") - 1, 0, tm.dv.size - 2))
        b = tm.branches.index(got.branch)
        xs = [_trilinear(tm, tm.transfer, b, du, w, cc, np.array([got.v - 1.0]))[0] for cc in {c, max(c - 1, 0)}]
        xs = [x for x in xs if np.isfinite(x)]  # a place on a node belongs to the cells on both sides
        assert any(meet + tm.track + x <= got.time + 1e-9
                   and got.wait == pytest.approx(got.time - meet - tm.track - x, abs=1e-9) for x in xs)
    assert found >= 8


def test_last_cell_before_a_hole_is_used():
    # the place window is dv in [-0.3, 0.06] (branch 0 only, node 0.18 infeasible): a tray reachable
    # only in the last cell [-0.06, 0.06] is found there (sampling the nodes saw none in that cell)
    du, w, dv = np.array([0.0, 0.1]), np.array([-0.1, 0.1]), np.array([-0.3, -0.18, -0.06, 0.06, 0.18])
    X = np.full((1, 2, 2, 5), 1.0)
    X[..., 4] = np.nan
    tm = TrayMap("a", du, w, dv, np.full((2, 2), 1.0), X, np.where(np.isnan(X), np.nan, 0.5), 0.5, 0.5,
                 BELT.speed, 0.1, 0.1)
    trays = TrayBelt(Belt((0.0, 0.6, 0.8), speed=0.1, width=0.2, length=4.0), pitch=3.0, capacity=1)
    p = SimPlace(tm, trays, 1.0)
    # the arm can be anywhere in the window at te + 1 = 11 s; tray 4 is at v = -12 + 0.1 t: at
    # v = 0.94 (dv = -0.06) at 129.4 s... choose meet so that only the last cell is still ahead:
    # tray k's place point reaches dv = -0.06 (v = 0.94) at t = (0.94 + 3k) / 0.1
    k = 4
    meet = (0.94 + 3.0 * k) / 0.1 - 0.5 - 1.0 + 0.4  # arrives 0.4 s after the tray passed dv = -0.06
    got = find_place(p, 0.05, 0.0, meet, {}, 0)
    assert got is not None and got.tray == k
    assert -0.06 < got.v - 1.0 <= 0.06 + 1e-12
    assert got.time == pytest.approx(meet + 0.5 + 1.0, abs=1e-9)  # a crossing: the transfer meets the tray
    assert got.wait == pytest.approx(0.0, abs=1e-9)


def test_pick_map_refuses_cells_on_two_pick_elbows():
    # the pick's elbow changes between du nodes 1 and 2: the tray map cannot place from that cell,
    # and the simulator's item intercept must not propose picks there
    du, w, dv = np.array([0.0, 0.05, 0.10]), np.array([-0.1, 0.1]), np.array([-0.3, 0.3])
    P = np.array([[0, 0], [0, 0], [1, 1]])
    tm = TrayMap("a", du, w, dv, np.full((3, 2), 1.0), np.full((1, 3, 2, 2), 1.0), np.full((1, 3, 2, 2), 0.5), 0.5,
                 0.5, BELT.speed, 0.1, 0.1, pick_branch=P)
    pm = tm.pick_map
    assert np.isfinite(pm.times(0.025, 0.0)[0])
    assert np.isnan(pm.times(0.075, 0.0)[0])
    assert np.isnan(tm.times(0.075, 0.0, 0.0)[0])  # the tray map agrees
    assert np.all(np.isnan(tm.place_cells(0.075, 0.0)[0]))
    # an item every 2 s for an arm busy 3.5 s per item: items it is too late for in the first cell
    # are missed, never refused for want of a slot (slots are always free: 4 per tray every 3 s)
    trays = TrayBelt(Belt((0.0, 0.6, 0.8), speed=0.1, width=0.2, length=4.0), pitch=0.3, capacity=4)
    items = regular_items(BELT, 2.0, 60.0, w=0.0)
    r = simulate([SimArm("a", 1.0, (pm,), place=SimPlace(tm, trays, 1.0))], items, BELT.speed, duration=60.0)
    assert r.picks >= 10 and r.misses > 0
    assert not r.no_tray.any() and r.unplaced == 0
    done = r.picked_by >= 0
    assert np.all(r.u_meet[done] - 1.0 <= 0.05 + 1e-9)


def test_approach_from_a_finer_box_map():
    # the tray map's t_A read from the station's box map on the pick's elbow (its finer grid),
    # the simulator's pick part on that grid, never beyond the tray map's feasible pick cells
    from pinarms.optim.line.task_maps import TaskMap

    du, w, dv = np.array([0.0, 0.1, 0.2]), np.array([-0.1, 0.1]), np.array([-0.3, 0.3])
    P = np.array([[0, 0], [0, 0], [1, 1]])  # cell [0.1, 0.2] on two elbows: infeasible
    tm = TrayMap("a", du, w, dv, np.full((3, 2), 1.0), np.full((1, 3, 2, 2), 1.0), np.full((1, 3, 2, 2), 0.5), 0.5,
                 0.5, BELT.speed, 0.1, 0.1, pick_branch=P)
    fdu, fw = np.linspace(0.0, 0.2, 9), np.linspace(-0.1, 0.1, 5)
    U, Wm = np.meshgrid(fdu, fw, indexing="ij")
    A = np.stack([1.2 + U ** 2 + Wm, 2.0 + U + Wm ** 2])  # two elbows, curved (bilinear on 3 nodes misses it)
    box = TaskMap("a", fdu, fw, A.min(axis=0), np.full(U.shape, 1.0), 0.5, 0.1, BELT.speed, 0.1, branches=(0, 1),
                  branch_approach=A, branch_leave=np.ones_like(A))
    from dataclasses import replace

    fine = replace(tm, approach_map=box)
    x, y = 0.037, 0.023
    assert fine.times(x, y, 0.0)[0] == pytest.approx(box.approach_on(0, x, y), abs=1e-12)
    exact = 1.2 + x ** 2 + y
    assert abs(fine.times(x, y, 0.0)[0] - exact) < abs(tm.times(x, y, 0.0)[0] - exact)  # closer than the coarse
    assert np.isnan(fine.times(0.15, y, 0.0)[0])  # still infeasible on two elbows
    pm = fine.pick_map
    assert np.array_equal(pm.du, fdu) and np.array_equal(pm.w, fw)
    assert pm.times(x, y)[0] == pytest.approx(box.approach_on(0, x, y), abs=1e-12)
    assert np.isnan(pm.times(0.15, y)[0]) and np.isnan(pm.times(0.12, y)[0])
    assert pm.times(0.09, y)[0] == pytest.approx(box.approach_on(0, 0.09, y), abs=1e-12)  # up to the border
    assert pm.branch_at(x, y) == 0
    with pytest.raises(InvalidInput, match="approach_map"):
        from pinarms.optim.line.map_request import TrayMapRequest

        TrayMapRequest(None, BELT, None, approach_map=replace(box, speed=0.3))
