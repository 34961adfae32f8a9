"""optim.motion.spline_proof: the smoothed spline proven on the compiled cover first, exactly where it is inconclusive.

The cell is tests/optim/data/aubo_wall.urdf.xacro (the AUBO-i3 by a wall, as in
test_motion_smoothing.py); the paths C² joint splines through seeded waypoints, some clear,
some through the wall. What the compiled route proves must be proven by the exact proof
(``prove_path(..., compiled=False)``: the ladder, coal where the cover is inconclusive) and
keep the margin on dense samples measured by coal; what it leaves open must hold every
sample closer than the margin.
"""

from __future__ import annotations

import numpy as np
import pytest

from pinarms.optim.motion import MotionChecker
from pinarms.optim.motion import _spline_kernel as kernel
from pinarms.optim.motion.smoothing import _travel_parts, prove_path, smooth_path
from pinarms.optim.motion.spline_proof import _group_weights, _outside_limits, open_ranges
from pinarms.planning import joint_spline

from tests.optim.test_motion_smoothing import checker  # noqa: F401 (fixture: the AUBO-i3 by the wall)


@pytest.fixture(scope="module")
def sides(checker):
    from tests.optim.test_motion import _tool_down

    qa, _ = _tool_down(checker.cell, [0.35, 0.3, 0.90])  # tool down 20 cm above the table, either side of the wall
    qb, _ = _tool_down(checker.cell, [0.35, -0.3, 0.90])
    return qa, qb


def _splines(checker, sides, count=10):
    """Seeded splines from one side of the wall: most stay on it (clear), some cross the wall."""
    qa, qb = sides
    rng = np.random.default_rng(11)
    out = []
    for k in range(count):
        end = qb if k % 3 == 0 else qa + rng.uniform(-0.3, 0.3, qa.size)
        mid = 0.5 * (qa + end) + rng.uniform(-0.1, 0.1, qa.size)
        W = np.clip(np.stack([qa, mid, end]), checker.lower + 0.05, checker.upper - 0.05)
        out.append(joint_spline(W))
    return out


def _ranges(checker, path):
    nodes, T, V = _travel_parts(checker, path)
    return open_ranges(checker, path, nodes, T, V)


def test_the_kernel_reads_the_path_and_the_bound_as_the_arrays_do(checker, sides):
    path = _splines(checker, sides, 2)[1]
    nodes, T, _ = _travel_parts(checker, path)
    x = np.empty(checker.n)
    coefs = np.ascontiguousarray(path.coefficients)
    for s in np.random.default_rng(3).uniform(0.0, path.length, 40).tolist() + list(path.breaks):
        kernel.q_at(np.asarray(path.breaks, dtype=float), coefs, s, x)
        np.testing.assert_allclose(x, path(s), rtol=0.0, atol=1e-12)
        assert kernel.bound_at(nodes, T, s) == pytest.approx(float(np.interp(s, nodes, T)), rel=1e-12, abs=1e-15)


def test_what_the_compiled_route_proves_the_exact_proof_proves(checker, sides):
    proven_alone = refused = 0
    for path in _splines(checker, sides):
        ranges = _ranges(checker, path)
        fast, _ = prove_path(checker, path)
        exact, _ = prove_path(checker, path, compiled=False)
        assert ranges is not None
        if fast.ok:
            assert exact.ok  # never clear where the exact proof is not
        proven_alone += int(ranges.shape[0] == 0)
        refused += int(not fast.ok)
        assert fast.ok == exact.ok
    assert proven_alone >= 2 and refused >= 2  # both routes were exercised


def test_a_spline_the_cover_proves_alone_keeps_the_margin_on_dense_samples(checker, sides):
    path = next(p for p in _splines(checker, sides) if _ranges(checker, p).shape[0] == 0)
    s = np.linspace(0.0, path.length, 301)
    excess, _, _ = checker.excess(checker.full(path(s)))
    assert excess.min() >= 0.0


def test_every_sample_too_close_lies_in_a_range_left_open(checker, sides):
    qa, qb = sides
    through = joint_spline(np.stack([qa, 0.5 * (qa + qb), qb]))
    ranges = _ranges(checker, through)
    assert ranges.shape[0] >= 1 and np.all(np.diff(ranges.ravel()) >= 0.0)  # sorted, disjoint
    s = np.linspace(0.0, through.length, 301)
    excess, _, _ = checker.excess(checker.full(through(s)))
    close = s[excess < 0.0]
    assert close.size > 0
    inside = ((close[:, None] >= ranges[None, :, 0]) & (close[:, None] <= ranges[None, :, 1])).any(axis=1)
    assert inside.all()
    verdict, piece = prove_path(checker, through)
    assert not verdict.ok and piece in (0, 1)


def test_a_piece_leaving_the_joint_limits_is_left_to_the_exact_proof(checker, sides):
    qa, _ = sides
    top = checker.upper.copy()
    W = np.stack([qa, qa, qa, qa])
    W[1:3, 0] = top[0] - 1e-3  # two waypoints just below the upper limit of joint 1: the spline bulges over it
    W[2, 1] += 0.2
    path = joint_spline(W)
    outside = _outside_limits(checker, path)
    from pinarms.optim.motion.spline_proof import _outside_limits_arrays

    assert np.array_equal(outside, _outside_limits_arrays(checker, path))  # compiled and piece_extrema agree
    assert outside.any() and float(path(np.linspace(0.0, path.length, 2001))[:, 0].max()) > top[0]
    ranges = _ranges(checker, path)
    k = int(np.flatnonzero(outside)[0])
    a, b = path.breaks[k], path.breaks[k + 1]
    assert ((ranges[:, 0] <= a) & (ranges[:, 1] >= b)).any()


def test_group_weights_bound_each_group_by_the_arm(checker, sides):
    from pinarms.optim.motion.fast import fast_check

    fc = fast_check(checker)
    path = _splines(checker, sides, 2)[1]
    nodes, T, V = _travel_parts(checker, path)
    s0 = np.linspace(0.0, path.length, 9)
    block, inv = _group_weights(fc.levers, fc.lam, nodes, V, s0)
    assert block.shape == (8,) and inv.shape[1] == fc.lam.shape[0]
    assert np.all(inv >= 1.0)  # a group never counts faster than the whole arm's bound
    # on a dense grid, each group's rate of change (its levers' bound, or the arm's if smaller) stays
    # within 1 / inv of the rate of the travel bound T on the part of T the point lies in
    s = np.linspace(0.0, path.length, 4001)
    _, dq, _ = path.sample(s)
    lam = np.where(np.isfinite(fc.lam), fc.lam, 0.0)
    arm_now = np.abs(dq) @ fc.levers
    group = np.minimum(np.abs(dq) @ lam.T, arm_now[:, None])  # (S, G)
    part = np.clip(np.searchsorted(nodes, s, side="right") - 1, 0, V.shape[0] - 1)
    rate = (V @ fc.levers)[part]
    b = np.clip(np.searchsorted(s0, s, side="right") - 1, 0, 7)
    assert np.all(group <= rate[:, None] / inv[block[b]] * (1.0 + 1e-9) + 1e-12)
    assert np.median(inv) > 1.0  # the weights do loosen most groups


@pytest.mark.parametrize("name", ["aubo_crate_guard", "panda_shelf"])
def test_benchmark_paths_smooth_the_same_with_or_without_the_compiled_route(name, monkeypatch):
    """Without the probe (the first open range proven exactly before the rest of the cover's proof) the
    smoothed paths are those of the exact proof alone; with it a refused spline may be refined at another
    failing piece, and the result is then still proven by the exact proof."""
    from pinarms.optim.motion import SCENES, fast_search, fast_shortcut, load_scene, scene_queries
    from pinarms.optim.motion import smoothing

    cell = load_scene(name)
    scene = SCENES[name]
    queries, hold = scene_queries(name, 2, seed=0, margin=0.01, cell=cell)
    checker = MotionChecker(cell, [scene.arm], margin=0.01, hold=hold)
    robot = cell.arm(scene.arm).robot
    for k, q in enumerate(queries):
        found = fast_search(checker, q.start, q.goal[None], time_limit=1.0, seed=k)
        assert found.path is not None
        P = fast_shortcut(checker, found.path, seed=k)
        exact, method_e, rounds_e = smooth_path(checker, P, robot, compiled=False)
        monkeypatch.setattr(smoothing, "PROBE", False)
        fast, method, rounds = smooth_path(checker, P, robot)
        assert (method, rounds) == (method_e, rounds_e)
        np.testing.assert_array_equal(fast.coefficients, exact.coefficients)
        monkeypatch.setattr(smoothing, "PROBE", True)
        probed, method, _ = smooth_path(checker, P, robot)
        if method == "cubic spline":
            assert prove_path(checker, probed, compiled=False)[0].ok
        else:  # refined at other pieces up to the fallback: the polyline, each edge proven exactly
            assert method == "polyline with stops"
            assert all(checker.edge_valid(P[i], P[i + 1]).ok for i in range(P.shape[0] - 1))


def test_the_compiled_travel_bound_and_limit_check_are_the_arrays_ones(checker, sides):
    from pinarms.optim.motion.smoothing import _travel_parts_arrays
    from pinarms.optim.motion.spline_proof import _outside_limits_arrays

    for path in _splines(checker, sides, 4):
        assert np.array_equal(_outside_limits(checker, path), _outside_limits_arrays(checker, path))
        got, want = _travel_parts(checker, path), _travel_parts_arrays(checker, path)
        for g, w in zip(got, want):
            assert g.shape == w.shape
            np.testing.assert_allclose(g, w, rtol=1e-12, atol=1e-15)
