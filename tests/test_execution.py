"""The execution layer: the same results whatever runs the tasks, named failures.

A real Dask ``LocalCluster`` on 127.0.0.1 (two worker processes, one thread each, no
dashboard) runs the same seeded tasks as the serial loop; the results must be equal bit
for bit. Task functions live at module level so worker processes can import them.
"""

from __future__ import annotations

import os

import numpy as np
import pytest

from pinarms import execution
from pinarms.execution import chunk_seeds, map_chunks
from pinarms.errors import ExecutionError, InvalidInput, PinarmsError

#: The scheduler's HTTP endpoint (health and metrics; no dashboard) on a free loopback port, not on
#: the fixed 8787 that every other LocalCluster of a parallel run tries first.
LOOPBACK_HTTP = {"dashboard_address": "127.0.0.1:0"}

# the scheduler's HTTP endpoint moves to a free port when another cluster holds 8787
pytestmark = pytest.mark.filterwarnings("ignore:Port .* is already in use:UserWarning")


def draw(task):
    """A seeded chunk: a few reductions of random numbers (what a sweep's chunk returns)."""
    rng = np.random.default_rng(task["seed"])
    x = rng.standard_normal((task["n"], 3))
    r = np.linalg.norm(x, axis=1)
    return {"sum": x.sum(axis=0), "hist": np.histogram(r, bins=16, range=(0, 8))[0], "max": r.max()}


def fail_on_chunk(task):
    if task["fail"]:
        raise ValueError(f"bad chunk payload {task['n']}")
    return task["n"] * 2


def die_on_chunk(task):
    if task["die"]:
        os._exit(3)  # the worker process dies without a Python exception
    return task["n"]


def _tasks(seed=7, n_chunks=6, n=2000):
    return [{"seed": s, "n": n} for s in chunk_seeds(seed, n_chunks)]


@pytest.fixture(scope="module")
def client():
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1", dashboard_address=None,
        scheduler_kwargs=LOOPBACK_HTTP,
    ) as cluster, distributed.Client(cluster) as c:
        yield c


def test_serial_results_in_task_order_with_progress():
    calls = []
    out = map_chunks(fail_on_chunk, [{"n": k, "fail": False} for k in range(5)], progress=lambda d, t: calls.append((d, t)))
    assert out == [0, 2, 4, 6, 8]
    assert calls == [(0, 5), (1, 5), (2, 5), (3, 5), (4, 5), (5, 5)]


def test_serial_failure_names_chunk_and_seed():
    tasks = [{"n": k, "fail": k == 2, "seed": 1000 + k} for k in range(4)]
    with pytest.raises(ExecutionError) as info:
        map_chunks(fail_on_chunk, tasks)
    err = info.value
    assert isinstance(err, PinarmsError)
    assert (err.chunk, err.seed) == (2, 1002)
    assert "chunk 2 (seed 1002)" in str(err) and "ValueError: bad chunk payload 2" in str(err)
    assert isinstance(err.__cause__, ValueError)


def test_cluster_equals_serial_bit_for_bit(client):
    tasks = _tasks()
    serial = map_chunks(draw, tasks)
    seen = []
    on_cluster = map_chunks(draw, tasks, scheduler=client, progress=lambda d, t: seen.append(d))
    assert len(on_cluster) == len(serial) == 6
    for a, b in zip(serial, on_cluster):
        assert a["sum"].tobytes() == b["sum"].tobytes()
        assert np.array_equal(a["hist"], b["hist"]) and a["hist"].sum() == 2000
        assert a["max"] == b["max"]
    assert seen == list(range(7))
    # different chunks really drew different numbers
    assert serial[0]["sum"].tobytes() != serial[1]["sum"].tobytes()
    # both workers took part (the work was spread, not run in the client)
    assert len(client.scheduler_info()["workers"]) == 2


def test_cluster_failure_names_chunk_and_seed_and_returns_nothing(client):
    tasks = [{"n": k, "fail": k == 3, "seed": 500 + k} for k in range(6)]
    with pytest.raises(ExecutionError) as info:
        map_chunks(fail_on_chunk, tasks, scheduler=client)
    assert (info.value.chunk, info.value.seed) == (3, 503)
    assert "ValueError: bad chunk payload 3" in str(info.value)
    # the cluster is still usable afterwards
    assert map_chunks(fail_on_chunk, [{"n": 1, "fail": False}], scheduler=client) == [2]


def test_a_dead_worker_is_a_named_error():
    distributed = pytest.importorskip("distributed")
    import dask

    with dask.config.set({"distributed.scheduler.allowed-failures": 0}):
        with distributed.LocalCluster(
            n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1", dashboard_address=None,
            scheduler_kwargs=LOOPBACK_HTTP,
        ) as cluster, distributed.Client(cluster) as c:
            tasks = [{"n": k, "die": k == 1, "seed": 90 + k} for k in range(3)]
            with pytest.raises(ExecutionError, match="chunk 1 \\(seed 91\\) lost its worker") as info:
                map_chunks(die_on_chunk, tasks, scheduler=c)
            assert info.value.chunk == 1


def test_map_chunks_checks_its_scheduler(monkeypatch):
    with pytest.raises(InvalidInput, match="unknown scheduler"):
        map_chunks(fail_on_chunk, [], scheduler="threads")
    with pytest.raises(InvalidInput, match="positive integer"):
        map_chunks(fail_on_chunk, [], scheduler="processes:0")
    monkeypatch.delenv("DASK_SCHEDULER_ADDRESS", raising=False)
    with pytest.raises(InvalidInput, match="DASK_SCHEDULER_ADDRESS"):
        map_chunks(fail_on_chunk, [], scheduler="env")
    # None never reads the variable: a library call stays on this machine
    monkeypatch.setenv("DASK_SCHEDULER_ADDRESS", "tcp://192.0.2.1:8786")
    assert map_chunks(fail_on_chunk, [{"n": 3, "fail": False}]) == [6]


def test_unreachable_scheduler_is_a_named_error():
    import dask
    import distributed  # noqa: F401  (its defaults in dask's config before the override: leaving the override
    #                                  restores the config as it was, without what a first import added inside it)

    # a closed port on this machine; Dask retries until its standard connect timeout
    with dask.config.set({"distributed.comm.timeouts.connect": "1s"}), pytest.raises(ExecutionError, match="cannot reach the Dask scheduler at tcp://127.0.0.1:9"):
        map_chunks(fail_on_chunk, [{"n": 1, "fail": False}], scheduler="tcp://127.0.0.1:9")


def draw_and_profiler(task):
    """``draw`` and whether the worker runs Dask's statistical profiler."""
    import dask

    return draw(task), bool(dask.config.get("distributed.worker.profile.enabled"))


def test_local_processes_scheduler_runs_the_same():
    tasks = _tasks(seed=3, n_chunks=3, n=500)
    serial = map_chunks(draw, tasks)
    local = map_chunks(draw_and_profiler, tasks, scheduler="processes:2")
    assert all(a["sum"].tobytes() == b["sum"].tobytes() for a, (b, _) in zip(serial, local))
    assert not any(profiler for _, profiler in local)  # off in the workers: it cost them 5-10 % of their CPU


def draw_and_pid(task):
    """``draw`` and the worker process's id."""
    import os

    return draw(task), os.getpid()


def test_a_session_starts_its_workers_once():
    from pinarms.execution import scheduler_session

    for plain in (None, "serial"):
        with scheduler_session(plain) as held:
            assert held == plain
    tasks = _tasks(seed=4, n_chunks=4, n=200)
    serial = map_chunks(draw, tasks)
    with scheduler_session("processes:2") as held:
        first = map_chunks(draw_and_pid, tasks, scheduler=held)
        second = map_chunks(draw_and_pid, tasks, scheduler=held)
    assert {pid for _, pid in second} <= {pid for _, pid in first}  # the same workers: started once
    assert os.getpid() not in {pid for _, pid in first}
    for a, (b, _), (c, _) in zip(serial, first, second):
        assert a["sum"].tobytes() == b["sum"].tobytes() == c["sum"].tobytes()


def test_importing_the_layer_loads_neither_dask_nor_the_robots():
    import subprocess
    import sys

    code = (
        "import sys, pinarms.execution as e; "
        "print(sorted(m for m in ('dask', 'distributed', 'pinocchio', 'pinarms.robots') if m in sys.modules))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


def test_reduce_chunks_folds_in_task_order(client):
    tasks = [{"n": k, "fail": False} for k in range(7)]
    fold = lambda acc, r: acc + [r]  # noqa: E731
    assert execution.reduce_chunks(fail_on_chunk, tasks, fold, []) == [0, 2, 4, 6, 8, 10, 12]
    assert execution.reduce_chunks(fail_on_chunk, tasks, fold, [], scheduler=client) == [0, 2, 4, 6, 8, 10, 12]
    with pytest.raises(InvalidInput, match="combine"):
        execution.reduce_chunks(fail_on_chunk, tasks, None, [])


@pytest.mark.slow
def test_a_dead_worker_is_blamed_on_the_chunk_that_killed_it():
    """Default retries (the killer is re-run on 4 workers in all): a chunk queued beside it on a dying
    worker is innocent and must not be named (chunk 2 was, for a killer at chunk 3)."""
    pytest.importorskip("distributed")
    tasks = [{"n": k, "die": k == 3, "seed": 40 + k} for k in range(12)]
    with pytest.raises(ExecutionError, match="chunk 3 \\(seed 43\\) lost its worker") as info:
        map_chunks(die_on_chunk, tasks, scheduler="processes:2")
    assert info.value.chunk == 3
