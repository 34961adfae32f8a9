"""The rows of the TOPP-RA loops as bounds on x, and the compiled loops that reduce them."""

from __future__ import annotations

import numpy as np

from pinarms.optim.topp._profile_kernel import forward_pass, pair_states
from pinarms.optim.topp.row_bounds import row_bounds


def test_row_bounds_split_rows_by_the_sign_of_c():
    c = np.array([[2.0, -4.0, 0.0]])
    Su, Ou, Sl, Ol, Zs, Zo = row_bounds(c, np.array([[1.0, 2.0, 3.0]]), np.array([[4.0, 8.0, 5.0]]))
    np.testing.assert_array_equal(Su, [[0.5, 0.0, 0.0]])  # 2x <= y + 4 -> x <= 0.5 y + 2
    np.testing.assert_array_equal(Ou, [[2.0, np.inf, np.inf]])
    np.testing.assert_array_equal(Sl, [[0.0, -0.5, 0.0]])  # -4x <= 2y + 8 -> x >= -0.5 y - 2
    np.testing.assert_array_equal(Ol, [[-np.inf, -2.0, -np.inf]])
    np.testing.assert_array_equal(Zs, [[0.0, 0.0, 3.0]])  # 0 <= 3y + 5
    np.testing.assert_array_equal(Zo, [[np.inf, np.inf, 5.0]])


def _pairs_reference(a, b, lo, hi, L, U):
    """The pair inequalities of feasible_states written with numpy broadcasting (every pair at once)."""
    c = a[:, :, None] * b[:, None, :] - a[:, None, :] * b[:, :, None]
    d = a[:, :, None] * np.where(U, hi, 0.0)[:, None, :] - a[:, None, :] * np.where(L, lo, 0.0)[:, :, None]
    pair = L[:, :, None] & U[:, None, :]
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = d / c
    top = np.min(ratio, axis=(1, 2), initial=np.inf, where=pair & (c > 0.0))
    bottom = np.max(ratio, axis=(1, 2), initial=-np.inf, where=pair & (c < 0.0))
    empty = np.any(pair & (c == 0.0) & (d < 0.0), axis=(1, 2))
    return top, bottom, empty


def test_compiled_pair_states_equal_the_broadcast_formula_bit_for_bit():
    rng = np.random.default_rng(11)
    N, m = 300, 10
    a = np.abs(rng.normal(size=(N, m)))
    a[:, ::4] = 0.0  # rows without u take no part in the pairs
    b = rng.normal(size=(N, m))
    b[::7, 1] = 0.0
    lo, hi = -np.abs(rng.normal(size=(N, m))), np.abs(rng.normal(size=(N, m)))
    lo[::5, 2], hi[::3, 3] = -np.inf, np.inf
    L, U = (a != 0.0) & np.isfinite(lo), (a != 0.0) & np.isfinite(hi)
    xlo, xhi = np.zeros(N), np.full(N, 1e12)
    pair_states(a, b, lo, hi, L, U, xlo, xhi)
    top, bottom, empty = _pairs_reference(a, b, lo, hi, L, U)
    np.testing.assert_array_equal(xhi, np.minimum(1e12, top))
    np.testing.assert_array_equal(xlo, np.where(empty, np.inf, np.maximum(0.0, bottom)))


def test_compiled_forward_pass_follows_the_rows_and_the_sets():
    """One row u <= 1 (a = 1, b = 0) from rest on a unit grid inside wide sets: x grows by 2Δ each step."""
    N = 6
    delta = np.full(N, 0.5)
    K = np.column_stack([np.zeros(N + 1), np.full(N + 1, 4.0)])
    up_s, up_o = np.zeros((N + 1, 1)), np.ones((N + 1, 1))
    dn_s, dn_o = np.zeros((N + 1, 1)), np.full((N + 1, 1), -np.inf)
    xs, us = np.empty(N + 1), np.empty(N)
    forward_pass(up_s, up_o, dn_s, dn_o, delta, K, 0.0, 1e12, xs, us)
    np.testing.assert_array_equal(xs, [0.0, 1.0, 2.0, 3.0, 4.0, 4.0, 4.0])  # capped by K's upper ends
    np.testing.assert_array_equal(us, [1.0, 1.0, 1.0, 1.0, 0.0, 0.0])
