"""Reductions of a streamed workspace: two tasks merged in order hold what one pass over all samples holds."""

from __future__ import annotations

import numpy as np

from pinarms.robots.reach.stream_reduction import Reduction, ReductionSpec, add_block, merge, sparse_voxels


def _shipped(P, w, c, spec):
    part = Reduction()
    add_block(part, P, w, c, spec)
    part.vox_sparse = sparse_voxels(part)
    return part


def test_two_tasks_merged_in_order_equal_one_pass():
    rng = np.random.default_rng(7)
    P = rng.normal(scale=0.3, size=(4000, 3))
    w, c = rng.uniform(0.0, 0.05, 4000), rng.uniform(0.0, 1.0, 4000)
    spec = ReductionSpec(frame="tcp", voxel_size=0.1, centre=np.zeros(3), width=0.05, n_dir_bins=8,
                         singular_threshold=0.1, block=1000)
    whole = Reduction()
    add_block(whole, P, w, c, spec)
    acc = Reduction()
    for part in (_shipped(P[:1500], w[:1500], c[:1500], spec), _shipped(P[1500:], w[1500:], c[1500:], spec)):
        merge(acc, part)
    assert acc.n == whole.n == 4000 and acc.n_singular == whole.n_singular == int(np.sum(c < 0.1))
    np.testing.assert_array_equal(acc.bbox_min, P.min(axis=0))
    np.testing.assert_array_equal(acc.bbox_max, P.max(axis=0))
    np.testing.assert_array_equal(acc.vox_lo, whole.vox_lo)
    np.testing.assert_array_equal(acc.vox_count, whole.vox_count)
    np.testing.assert_array_equal(acc.vox_min, whole.vox_min)
    np.testing.assert_allclose(acc.vox_sum, whole.vox_sum, rtol=1e-12, atol=1e-15)
    np.testing.assert_array_equal(acc.shell_count, whole.shell_count)
    np.testing.assert_array_equal(acc.shell_singular, whole.shell_singular)
    np.testing.assert_array_equal(acc.hull_point, whole.hull_point)  # first sample kept on ties, as one pass
    np.testing.assert_array_equal(acc.hull_count, whole.hull_count)
