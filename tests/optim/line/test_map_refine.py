"""Where a map needs more nodes: the yaw pass plans only the (du, w) nodes whose time bends along yaw and
interpolates the rest; whole du/w lines where a time bends (the test of the map build, on tables)."""

import numpy as np
import pytest

from pinarms.optim.line.map_refine import add_yaw_nodes, bent_lines, bent_nodes

EXTRA, TOL = 1.0, 0.005


def truth(yaw, du):
    """Approach time [s] over tool yaw and du: bends along yaw at du > 0 only (a slow wrist there)."""
    return 1.0 + np.where(du[None, :] > 0.0, 0.8 * np.abs(np.sin(yaw[:, None])) ** 1.5, 0.01 * yaw[:, None])


def tables(yaw, du):
    A = truth(yaw, du)[:, None, :, None] * np.ones((1, 1, 1, 2))  # (ny, nb=1, nu, nw=2)
    return A, np.ones_like(A)


def test_a_yaw_pass_plans_only_the_nodes_that_bend():
    du = np.array([-0.2, -0.1, 0.1, 0.2])
    yaw = np.linspace(-np.pi / 2, np.pi / 2, 5)
    A, C = tables(yaw, du)
    asked = []

    def plan(mid, need):
        asked.append(need.copy())
        PA, PC = tables(mid, du)
        return np.where(need[:, None], PA, np.nan), np.where(need[:, None], PC, np.nan)

    ys, A2, C2, added = add_yaw_nodes(yaw, A, C, EXTRA, TOL, plan)
    assert added == 4 and ys.size == 9 and np.all(np.diff(ys) > 0)
    need = asked[0]
    assert need[:, 2:].all() and not need[:, :2].any()  # planned where it bends (du > 0) only
    new = np.isin(ys, 0.5 * (yaw[:-1] + yaw[1:]))
    np.testing.assert_allclose(A2[new][:, 0, 2:, 0], truth(ys[new], du)[:, 2:], rtol=1e-15)  # planned: exact
    lin = 0.5 * (A2[np.flatnonzero(new) - 1] + A2[np.flatnonzero(new) + 1])
    np.testing.assert_array_equal(A2[new][:, :, :2], lin[:, :, :2])  # the rest: the interpolation it had
    np.testing.assert_allclose(A2[new][:, 0, :2, 0], truth(ys[new], du)[:, :2], rtol=1e-12)  # linear there: exact
    # passes until nothing bends: the interpolated map within the tolerance of the truth everywhere
    for _ in range(6):
        ys, A2, C2, added = add_yaw_nodes(ys, A2, C2, EXTRA, TOL, plan)
        if not added:
            break
    assert added == 0 and not bent_nodes(ys, A2, C2, EXTRA, TOL).any()
    fine = np.linspace(-np.pi / 2, np.pi / 2, 721)
    interp = np.stack([np.interp(fine, ys, A2[:, 0, i, 0]) for i in range(du.size)], axis=1)
    err = np.abs(interp - truth(fine, du)) / (truth(fine, du) + 1.0 + EXTRA)
    assert err.max() < 2 * TOL
    planned = sum(int(n.sum()) for n in asked)
    assert planned < (ys.size - 5) * du.size * 2  # fewer plans than whole layers


def test_lines_and_nodes_skip_infeasible_neighbours():
    du = np.linspace(0.0, 0.3, 7)
    A = np.full((1, 7, 2), 1.5)
    C = np.tile(1.0 + np.abs(du - 0.15)[None, :, None], (1, 1, 2))
    assert np.allclose(bent_lines(du, A, C, 0.6, TOL, 1), [0.125, 0.175])
    assert bent_lines(du[:2], A[:, :2], C[:, :2], 0.6, TOL, 1).size == 0
    yaw = np.linspace(-1.0, 1.0, 3)
    A3 = np.stack([np.full((1, 2, 2), v) for v in (1.0, 2.0, 1.0)])
    A3[2, 0, 0, 0] = np.nan
    mark = bent_nodes(yaw, A3, np.zeros_like(A3), 0.0, TOL)
    assert mark.shape == (2, 2, 2) and not mark[:, 0, 0].any() and mark[:, 1, 1].all()


@pytest.mark.parametrize("n", [1, 2])
def test_too_few_yaw_nodes_bend_nowhere(n):
    yaw = np.linspace(-1.0, 1.0, n)
    A = np.ones((n, 1, 2, 2))
    assert not bent_nodes(yaw, A, A, 0.0, TOL).any()
