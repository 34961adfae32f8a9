"""The MuJoCo re-check computes coal's exact distance only where a figure may depend on it
(pinarms/export/pair_distances.py): its bounds hold, and its reports are the ones every exact distance gives."""

from __future__ import annotations

import numpy as np
import pytest

from pinarms.export import pair_distances as pd
from pinarms.export import verify

CELL = "so101_table"


def _figures(d: np.ndarray, d_mj: np.ndarray, mesh: np.ndarray, distmax: float) -> dict:
    """What the re-check reports from coal's distances ``d``, computed here by its own route."""
    near = d < distmax
    on, off = near & mesh[None, :], near & ~mesh[None, :]
    k = int(np.argmin(d))
    return {"min": (d.flat[k], k), "contacts": int((d <= 0).sum()), "clear": (d > 0).tolist(),
            "near": near.tolist(), "excess": (d_mj - d)[on].max() if on.any() else None,
            "gap": (d - d_mj)[on].max() if on.any() else None,
            "primitives": np.abs(d_mj - d)[off].max() if off.any() else None}


@pytest.mark.parametrize("seed", range(20))
def test_settled_distances_give_every_figure_of_the_exact_ones(seed):
    rng = np.random.default_rng(seed)
    n, p, distmax = 30, 25, 0.5
    d = rng.uniform(-0.03, 0.9, (n, p))
    mesh = rng.random(p) < 0.8
    hull = np.where(mesh[None, :], rng.uniform(0.0, 0.01, (n, p)) * (rng.random((n, p)) < 0.4), 0.0)
    d_mj = np.minimum(d - hull + rng.normal(0.0, 1e-7, (n, p)), distmax)
    lower = np.where(d - hull > 0, d - hull - rng.uniform(0, 1e-9, (n, p)), -np.inf)
    upper = np.where(np.isfinite(lower), d + rng.uniform(0.0, 0.004, (n, p)) * (rng.random((n, p)) < 0.7), np.inf)
    asked = []

    def compute(which):
        asked.append(int(which.sum()))
        return np.where(which, d, np.nan)

    got = pd.settle(lower, upper, d_mj, mesh, distmax, compute)
    assert got.exact.sum() == sum(asked) and np.array_equal(got.value[got.exact], d[got.exact])
    assert np.all(got.value <= d)  # a lower bound where not exact
    assert _figures(got.value, d_mj, mesh, distmax) == _figures(d, d_mj, mesh, distmax)
    assert got.exact_share < 0.6, got.exact_share  # most entries settled by their bounds


@pytest.fixture(scope="module")
def so101(tmp_path_factory):
    from pinarms.export.cell import export_cell
    from pinarms.optim.motion.arm_macros import example_packages
    from pinarms.robots.cell import load_cell
    from pathlib import Path

    packages = {"example-robot-data": str(example_packages()["example-robot-data"])}
    cell = load_cell(Path(__file__).parent / "cells" / f"{CELL}.toml", packages=packages)
    mjcf = export_cell(cell, tmp_path_factory.mktemp("so101") / "cell", srdf=False, packages=packages).mjcf
    arm = cell.arm("arm")
    home, place = (cell.q_from_arms({"arm": arm.states[s]}) for s in ("home", "place"))
    qs = np.vstack([cell.random_q(1, seed=1), home + np.linspace(0.0, 1.0, 2)[:, None] * (place - home)])
    return cell, mjcf, qs


@pytest.mark.slow
def test_the_bounds_hold_and_the_reports_are_those_of_every_exact_distance(so101, monkeypatch):
    cell, mjcf, qs = so101
    pairs = verify.contact_pairs(cell)
    exact = pd.exact_distances(cell, pairs, qs, np.ones((len(qs), len(pairs)), dtype=bool))
    lower, upper = pd.pair_bounds(cell, pairs, qs)
    assert np.all(lower <= exact) and np.all(exact <= upper)
    assert np.isfinite(lower).mean() > 0.5  # the hulls are apart for most pairs: bounds, not exact calls
    settled = verify.compare_configurations_in_mujoco(cell, qs, mjcf=mjcf)

    def every_exact(cell_, pairs_, qs_, d_mujoco, mesh, distmax):
        assert np.array_equal(qs_, qs) and pairs_ == pairs
        return pd.PairDistances(exact, exact, exact, np.ones(exact.shape, dtype=bool))

    monkeypatch.setattr(verify, "pinarms_distances", every_exact)
    reference = verify.compare_configurations_in_mujoco(cell, qs, mjcf=mjcf)
    assert settled.as_dict() == reference.as_dict() and settled.lines() == reference.lines()


def test_closest_points_on_triangles_are_on_them_and_nearest():
    rng = np.random.default_rng(5)
    m, k = 200, 4
    tri = rng.normal(size=(m, k, 3, 3))
    tri[:, 0, 2] = tri[:, 0, 1]  # a degenerate triangle (two corners equal) in every row
    P = rng.normal(size=(m, 3)) * 2.0
    Q = pd.closest_on_triangles(P, tri)
    # nearest: no point of a fine barycentric sampling of the row's triangles is nearer
    g = np.linspace(0.0, 1.0, 41)
    u, v = np.meshgrid(g, g)
    keep = (u + v) <= 1.0
    u, v = u[keep], v[keep]
    samples = tri[:, :, None, 0] + u[None, None, :, None] * (tri[:, :, None, 1] - tri[:, :, None, 0]) \
        + v[None, None, :, None] * (tri[:, :, None, 2] - tri[:, :, None, 0])
    sampled = np.linalg.norm(samples - P[:, None, None, :], axis=-1).min(axis=(1, 2))
    got = np.linalg.norm(Q - P, axis=1)
    assert np.all(got <= sampled + 1e-12)
    # on a triangle: its distance to the nearest triangle (by a finer projection) is nil
    assert np.all(got >= sampled - 0.2)  # the sampling's spacing bounds how much nearer the exact point is
    back = pd.closest_on_triangles(Q, tri)
    np.testing.assert_allclose(back, Q, atol=1e-9)
