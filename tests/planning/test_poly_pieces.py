"""Arrays of polynomial pieces: re-expansion about a new origin, padding, derivatives side by side."""

from __future__ import annotations

import numpy as np

from pinarms.planning.poly_pieces import derivative_stack, pad_degree, taylor_shift


def _values(coefs: np.ndarray, u: np.ndarray) -> np.ndarray:
    """(m, n) values of pieces (m, K+1, n) at local u (m,)."""
    return np.einsum("mkn,mk->mn", coefs, u[:, None] ** np.arange(coefs.shape[1]))


def test_taylor_shift_gives_the_same_polynomial_about_the_new_origin():
    rng = np.random.default_rng(3)
    coefs = rng.normal(size=(4, 6, 2))
    offset = rng.uniform(-1.0, 2.0, size=4)
    shifted = taylor_shift(coefs, offset)
    u = rng.uniform(-0.5, 0.5, size=4)
    np.testing.assert_allclose(_values(shifted, u), _values(coefs, offset + u), rtol=1e-12, atol=1e-12)
    np.testing.assert_array_equal(taylor_shift(coefs, np.zeros(4)), coefs)


def test_pad_degree_adds_zero_high_powers_and_derivative_stack_differentiates():
    coefs = np.array([[[1.0], [2.0], [3.0]]])  # 1 + 2τ + 3τ²
    padded = pad_degree(coefs, 5)
    assert padded.shape == (1, 5, 1) and np.all(padded[0, 3:] == 0.0)
    assert pad_degree(coefs, 3) is coefs
    stack = derivative_stack(padded)  # q, qd, qdd, qddd side by side
    np.testing.assert_array_equal(stack[0, :, 0], [1.0, 2.0, 3.0, 0.0, 0.0])
    np.testing.assert_array_equal(stack[0, :, 1], [2.0, 6.0, 0.0, 0.0, 0.0])
    np.testing.assert_array_equal(stack[0, :, 2], [6.0, 0.0, 0.0, 0.0, 0.0])
    np.testing.assert_array_equal(stack[0, :, 3], [0.0, 0.0, 0.0, 0.0, 0.0])
