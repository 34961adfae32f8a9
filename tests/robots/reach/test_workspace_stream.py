"""Streamed workspaces: the reductions of the in-memory samples, identical on a Dask cluster."""

from __future__ import annotations

import numpy as np
import pytest

from pinarms import robots
from pinarms.errors import InvalidInput
from pinarms.robots.reach.workspace import fit_sphere, hull_points, sample_workspace
from pinarms.robots.reach.workspace_stream import StreamGrid, stream_workspace

#: The scheduler's HTTP endpoint (health and metrics; no dashboard) on a free loopback port, not on
#: the fixed 8787 that every other LocalCluster of a parallel run tries first.
LOOPBACK_HTTP = {"dashboard_address": "127.0.0.1:0"}

pytestmark = pytest.mark.filterwarnings("ignore:Port .* is already in use:UserWarning")

N = 60_000


@pytest.fixture(scope="module")
def aubo():
    return robots.load("aubo_i3")


@pytest.fixture(scope="module")
def streamed(aubo):
    return stream_workspace(aubo, N, seed=5, frame="flange", task_samples=25_000, block=10_000, grid=StreamGrid(0.05))


@pytest.fixture(scope="module")
def in_memory(aubo):
    return sample_workspace(aubo, N, seed=5, frame="flange")


def test_sample_workspace_in_tasks_equals_one_piece(aubo, in_memory):
    tasks = sample_workspace(aubo, N, seed=5, frame="flange", task_samples=7_000)
    for name in ("q", "points", "manipulability", "inverse_condition"):
        assert np.array_equal(getattr(tasks, name), getattr(in_memory, name)), name
    with pytest.raises(InvalidInput, match="integer seed"):
        sample_workspace(aubo, 10, seed=np.random.default_rng(0), scheduler="processes")


def test_streamed_reductions_are_those_of_the_samples(streamed, in_memory):
    P, w, c = in_memory.points, in_memory.manipulability, in_memory.inverse_condition
    s = streamed.summary
    assert streamed.n_tasks == 3 and s.n == N
    assert np.array_equal(s.bbox_min, P.min(axis=0)) and np.array_equal(s.bbox_max, P.max(axis=0))
    assert s.manipulability_max == w.max()
    assert s.manipulability_mean == pytest.approx(w.mean(), rel=1e-12)
    assert s.singular_share == np.mean(c < 0.1)
    # voxels: samples per voxel of the global grid (voxel i spans [i s, (i+1) s)), exactly
    v = streamed.voxels
    ijk = np.floor(P / v.voxel_size).astype(np.int64)
    lo = ijk.min(axis=0)
    assert np.allclose(v.origin, lo * v.voxel_size)
    flat = np.ravel_multi_index((ijk - lo).T, v.shape)
    assert np.array_equal(v.count.reshape(-1), np.bincount(flat, minlength=v.count.size))
    wmin = np.full(v.count.size, np.inf)
    np.minimum.at(wmin, flat, w)
    occupied = v.count.reshape(-1) > 0
    assert np.array_equal(v.min_manipulability.reshape(-1)[occupied], wmin[occupied])
    busiest = np.argmax(v.count.reshape(-1))
    assert v.mean_manipulability.reshape(-1)[busiest] == pytest.approx(w[flat == busiest].mean(), rel=1e-12)
    assert v.count.sum() == N and np.all(v.margin[v.reachable] > 0)
    # hull sphere: the farthest sample per direction cell around the pilot's centre, then the fit
    idx = hull_points(P, streamed.centre, 2000)
    direct = fit_sphere(P[idx])
    assert s.sphere.radius == direct.radius and np.array_equal(s.sphere.centre, direct.centre)
    assert s.sphere.coverage > 0.95
    # radial profile around the same centre
    prof = in_memory.radial_profile(streamed.centre, width=0.05)
    k = prof.counts.size
    assert np.array_equal(s.profile.counts[:k], prof.counts) and not s.profile.counts[k:].any()


def test_streamed_on_a_cluster_equals_serial_bit_for_bit(aubo, streamed):
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1", dashboard_address=None,
        scheduler_kwargs=LOOPBACK_HTTP,
    ) as cluster, distributed.Client(cluster) as client:
        seen = []
        remote = stream_workspace(
            aubo, N, seed=5, frame="flange", task_samples=25_000, block=10_000, grid=StreamGrid(0.05),
            scheduler=client, progress=lambda d, t: seen.append((d, t)),
        )
        big = sample_workspace(aubo, 9_000, seed=2, task_samples=4_000, scheduler=client)
    assert seen[-1] == (3, 3)
    a, b = streamed.summary, remote.summary
    for name in ("bbox_min", "bbox_max"):
        assert getattr(a, name).tobytes() == getattr(b, name).tobytes()
    assert (a.manipulability_mean, a.manipulability_max, a.singular_share) == (
        b.manipulability_mean, b.manipulability_max, b.singular_share)
    assert a.sphere.centre.tobytes() == b.sphere.centre.tobytes() and a.sphere.radius == b.sphere.radius
    for name in ("count", "mean_manipulability", "min_manipulability", "margin"):
        assert getattr(streamed.voxels, name).tobytes() == getattr(remote.voxels, name).tobytes(), name
    assert a.profile.mean_manipulability.tobytes() == b.profile.mean_manipulability.tobytes()
    assert np.array_equal(big.points, sample_workspace(aubo, 9_000, seed=2).points)


def test_default_voxel_edge_and_bad_input(aubo):
    s = stream_workspace(aubo, 30_000, seed=1, task_samples=30_000)
    assert s.voxels.voxel_size >= 0.01  # never below 1 cm unless asked
    assert "voxel map" in s.text() and "30000 samples" in s.text()
    with pytest.raises(InvalidInput, match="integer seed"):
        stream_workspace(aubo, 10, seed=np.random.default_rng(0))
    with pytest.raises(InvalidInput, match="task_samples"):
        stream_workspace(aubo, 10, task_samples=0)
    with pytest.raises(InvalidInput, match="voxel_size"):
        stream_workspace(aubo, 10, grid=StreamGrid(voxel_size=-1.0))
    with pytest.raises(InvalidInput, match="shell width must be a positive length"):
        StreamGrid(width=0.0)
    with pytest.raises(InvalidInput, match="grid must be a robots.reach.workspace_stream.StreamGrid, got dict"):
        stream_workspace(aubo, 10, grid={"voxel_size": 0.05})
