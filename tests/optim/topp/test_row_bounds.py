"""The rows of the TOPP-RA loops as bounds on x: pruning never changes a min or a max."""

from __future__ import annotations

import numpy as np

from pinarms.optim.topp.row_bounds import prune, row_bounds, stage_lists


def test_row_bounds_split_rows_by_the_sign_of_c():
    c = np.array([[2.0, -4.0, 0.0]])
    Su, Ou, Sl, Ol, Zs, Zo = row_bounds(c, np.array([[1.0, 2.0, 3.0]]), np.array([[4.0, 8.0, 5.0]]))
    np.testing.assert_array_equal(Su, [[0.5, 0.0, 0.0]])  # 2x <= y + 4 -> x <= 0.5 y + 2
    np.testing.assert_array_equal(Ou, [[2.0, np.inf, np.inf]])
    np.testing.assert_array_equal(Sl, [[0.0, -0.5, 0.0]])  # -4x <= 2y + 8 -> x >= -0.5 y - 2
    np.testing.assert_array_equal(Ol, [[-np.inf, -2.0, -np.inf]])
    np.testing.assert_array_equal(Zs, [[0.0, 0.0, 3.0]])  # 0 <= 3y + 5
    np.testing.assert_array_equal(Zo, [[np.inf, np.inf, 5.0]])


def test_pruned_rows_give_the_same_min_and_max_to_the_last_bit():
    rng = np.random.default_rng(5)
    slope, offset = rng.normal(size=(200, 12)), rng.normal(size=(200, 12))
    x_lo = rng.uniform(0.0, 1.0, 200)
    x_hi = x_lo + rng.uniform(0.0, 2.0, 200)
    y = x_lo + rng.uniform(0.0, 1.0, 200) * (x_hi - x_lo)
    for upper, reduce in ((True, np.min), (False, np.max)):
        kept = prune(slope, offset, x_lo, x_hi, upper)
        assert np.isinf(kept).sum() > 200  # most rows cannot bind
        np.testing.assert_array_equal(reduce(slope * y[:, None] + kept, axis=1),
                                      reduce(slope * y[:, None] + offset, axis=1))


def test_stage_lists_keep_the_finite_rows_of_each_point():
    slope = np.array([[1.0, 2.0], [3.0, 4.0]])
    offset = np.array([[np.inf, 5.0], [6.0, 7.0]])
    ((s, o, starts),) = stage_lists(slope, offset)
    assert s == [2.0, 3.0, 4.0] and o == [5.0, 6.0, 7.0] and starts == [0, 1, 3]
