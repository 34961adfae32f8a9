"""pinarms' cell checks against an independent reference: plain Pinocchio + coal over every pair.

The reference (``_cells.Reference``) builds its own GeometryModel with every pair of the
cell's geometries but those allowed by design; it does not use the project's pair list,
bounds or broad phase. Tolerances: distances within 1e-6 m; a contact verdict at margin
``m`` is compared where the reference minimum is not within 1e-5 m of ``m`` (coal's contact
test, GJK/EPA, resolves to about its 1e-6 m tolerance); first contacts
within one step of a dense grid of 2e-4 s.
"""

from __future__ import annotations

import numpy as np
import pytest

from pinarms import planning
from pinarms.optim.motion.scenes import load_scene, scene_names
from pinarms.robots.cell import ArmMotion, cell_names, load_cell
from pinarms.robots.cell.motion import configurations

from _cells import Reference, facing_cell_text, make_cell, post_cell_text

MARGINS = (0.0, 0.005, 0.02, 0.05)
DENSE_STEP = 2e-4  # [s]


def _test_cells():
    return {"post": make_cell(post_cell_text(), "post"), "facing": make_cell(facing_cell_text(), "facing")}


def _near(cell, n, seed):
    """Random configurations, half of them pulled towards contact (bisection on the segment to a colliding one)."""
    rng = np.random.default_rng(seed)
    Q = cell.random_q(4 * n, seed=rng)
    hit = np.asarray(cell.in_collision(Q), dtype=bool)
    out = list(Q[~hit][:n])
    free, bad = Q[~hit], Q[hit]
    for k in range(min(n, len(free), len(bad))):
        a, b = free[k], bad[k]
        for _ in range(14):
            m = 0.5 * (a + b)
            a, b = (a, m) if cell.in_collision(m) else (m, b)
        out.append(a)
    return np.array(out)


def _compare(cell, Q):
    ref = Reference(cell)
    result = cell.clearance(Q)
    for i, q in enumerate(Q):
        d = ref.distances(q)
        assert abs(result.distance[i] - d.min()) <= 1e-6, (cell.name, i, result.pair_of(i), d.min())
        pair = result.pair_of(i)
        k = ref.names.index(frozenset((pair.geometry_a, pair.geometry_b)))
        assert abs(d[k] - d.min()) <= 1e-6  # the same pair (or one tied with it)
        for m in MARGINS:
            if abs(d.min() - m) > 1e-5:  # coal's contact test resolves to its GJK tolerance
                assert bool(cell.in_collision(q, margin=m)) == bool(d.min() <= m), (cell.name, i, m, d.min())
    # the batch path of in_collision agrees with the single one
    for m in MARGINS:
        expected = np.array([bool(cell.in_collision(q, margin=m)) for q in Q])
        assert np.array_equal(np.asarray(cell.in_collision(Q, margin=m)), expected)


@pytest.mark.parametrize("name", ["post", "facing"])
def test_test_cells_match_the_all_pairs_reference(name):
    cell = _test_cells()[name]
    _compare(cell, _near(cell, 12, seed=7))


@pytest.mark.parametrize("name", cell_names())
def test_shipped_cells_match_the_all_pairs_reference(name):
    cell = load_cell(name)
    _compare(cell, _near(cell, 6, seed=11))


@pytest.mark.slow
@pytest.mark.parametrize("name", scene_names())
def test_scene_cells_match_the_all_pairs_reference(name):
    cell = load_scene(name)
    _compare(cell, _near(cell, 4, seed=5))


def _dense(cell, motions, window):
    t = np.arange(window[0], window[1] + DENSE_STEP / 2, DENSE_STEP)
    Q = configurations(cell, motions, t, cell.neutral)
    return t, Reference(cell).minimum(Q)


def test_a_sweep_past_the_post_respects_dense_sampling():
    cell = _test_cells()["post"]
    motion = [ArmMotion("arm", planning.multi_quintic([0.0, 1.0], np.array([[-1.0, 0, 0, 0], [1.0, 0, 0, 0]])))]
    t, d = _dense(cell, motion, (0.0, 1.0))
    for clearance in (0.0, 0.01, 0.02):
        result = cell.check_motion(motion, margin=0.005, clearance=clearance)
        assert result.lower_bound <= d.min() + 1e-9
        if result.clear:
            assert d.min() >= clearance
        # always a distance (coal at a sample): between the proven bound and, up to the dense step, the truth
        assert result.min_clearance >= d.min() - 1e-9 and result.min_clearance_pair is not None
    assert not cell.check_motion(motion, margin=0.005, clearance=0.02).clear  # dense: 13 mm


def test_the_first_contact_of_two_facing_arms_is_bracketed_by_dense_sampling():
    cell = _test_cells()["facing"]
    swing = planning.multi_quintic([0.0, 1.0], np.array([[1.5, 0, 0, 0], [0.0, 0, 0, 0]]))
    hold = planning.multi_quintic([0.0, 1.0], np.array([[0.0, 0, 0, 0], [0.0, 0, 0, 0]]))
    motions = [ArmMotion("one", swing), ArmMotion("two", hold)]
    result = cell.check_motion(motions, margin=0.01)
    assert not result.collision_free and result.first_contact is not None
    t, d = _dense(cell, motions, (0.0, 1.0))
    first_dense = t[np.argmax(d <= 0.0)]
    assert abs(result.first_contact.time - first_dense) <= DENSE_STEP + 1e-6
    at = Reference(cell).minimum(configurations(cell, motions, np.array([result.first_contact.time]), cell.neutral))
    assert at[0] <= 1e-9
