"""The compiled exact extrema (next derivatives of degree <= 4) and multi-quintic peaks agree with the numpy route."""

from __future__ import annotations

import numpy as np

from pinarms import planning
from pinarms.planning.extrema import normalised_pieces, piece_extrema


def _pieces(rng, M, n, W):
    cn = rng.normal(size=(M, n, W)) * rng.choice([1e-3, 1.0, 1e3], size=(M, n, W))
    cn[0, 0, 2:] = 0.0  # a piece of degree 1: its next derivatives vanish (no root)
    if W > 3:
        cn[-1, -1, -1] = 1e-17 * np.abs(cn[-1, -1]).max()  # a negligible leading coefficient (degree dropped)
    return cn


def test_the_compiled_extrema_equal_the_numpy_route_and_bound_a_dense_sampling(monkeypatch):
    from pinarms.planning import extrema

    rng = np.random.default_rng(3)
    for W in (2, 4, 6, 7):
        for orders in ((1, 2, 3), (2,), (1, 3)):
            cn, h = _pieces(rng, 5, 4, W), rng.uniform(0.02, 2.0, 5)
            values, s = piece_extrema(cn, h, orders)  # the compiled loop
            monkeypatch.setattr(extrema, "COMPILED", False)
            wide, _ = piece_extrema(cn, h, orders)  # the numpy route (companion eigenvalues for W = 7)
            monkeypatch.setattr(extrema, "COMPILED", True)
            peak, peak_numpy = np.abs(values).max(axis=-1), np.abs(wide).max(axis=-1)
            np.testing.assert_allclose(peak, peak_numpy, rtol=1e-12 if W == 7 else 1e-13, atol=0.0)
            assert values.shape == (len(orders), 5, 4, 2 + max(W - 2, 1)) and np.all((s >= 0.0) & (s <= 1.0))
            # independent: the derivative sampled densely never exceeds the exact peak, and comes close to it
            grid = np.linspace(0.0, 1.0, 4001)
            P = np.polynomial.polynomial
            for a, r in enumerate(orders):
                for i in range(5):
                    for j in range(4):
                        sampled = np.abs(P.polyval(grid, P.polyder(cn[i, j], r))).max() * h[i] ** -r
                        assert sampled <= peak[a, i, j] * (1.0 + 1e-12) + 1e-300
                        assert sampled >= peak[a, i, j] * (1.0 - 1e-5)


def test_the_compiled_multi_quintic_peaks_are_those_of_the_built_trajectories():
    rng = np.random.default_rng(5)
    for m, n in ((1, 1), (3, 6), (5, 2)):
        q = np.cumsum(rng.normal(size=(m + 1, n)), axis=0)
        q[min(2, m)] = q[min(2, m) - 1]  # a joint standing still on one segment: slopes of sign 0
        t = np.concatenate([np.zeros((4, 1)), np.cumsum(rng.uniform(0.05, 2.0, (4, m)), axis=1)], axis=1)
        for velocities in ("heuristic", None):
            built = planning.peaks_batch(t, planning.multi_quintic_batch(t, q, velocities=velocities))
            fast = planning.multi_quintic_peaks_batch(t, q, velocities == "heuristic")
            np.testing.assert_array_equal(fast, built)  # the same operations: the same bits
            one = planning.multi_quintic(t[1], q, velocities=velocities).peaks()
            np.testing.assert_allclose(fast[1], np.stack([one.velocity, one.acceleration, one.jerk]), rtol=1e-12)
