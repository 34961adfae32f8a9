"""Execution layer: one function applied to many tasks, here or on a Dask cluster.

Every sweep of pinarms (large workspaces, layout searches, multi-seed GA studies) is cut
into *tasks*, applied with :func:`map_chunks`. The same call runs

- ``scheduler=None`` (default): a serial loop in this process, no set-up;
- ``scheduler="processes"`` (or ``"processes:N"``): a local Dask cluster of ``N`` worker
  processes (one thread each, on 127.0.0.1, no dashboard), started and closed by the call;
- ``scheduler="tcp://HOST:8786"``: an existing Dask cluster (``dask scheduler`` +
  ``dask worker``), connected and disconnected by the call;
- ``scheduler=client``: a ``distributed.Client`` the caller owns (kept open);
- ``scheduler="env"``: the address in the standard ``DASK_SCHEDULER_ADDRESS`` variable
  (an error when it is unset). The variable is read **only** when asked for (here, or by the
  CLI's ``--scheduler`` option), so a library call never leaves the machine by surprise.

Results are identical whatever runs them: randomness enters a task only through its own
seed (:func:`chunk_seeds`; cutting a sweep into chunks is :mod:`pinarms.chunks`, the
``scheduler`` argument is checked and described by :mod:`pinarms.schedulers`; both names are
importable from here too), tasks are pure functions of their arguments, and results come
back in task order. A task that raises, or a worker that dies, gives
:class:`~pinarms.errors.ExecutionError` with the chunk index and its seed, and no
partial result (callers write files only after a complete result).

This module sits at the bottom of the one-way flow: it imports numpy at module level, Dask
lazily, and the error class (``pinarms.errors``) lazily when it raises; every package
(robots, planning, optim, viz, the CLI) may import it.

Threads: every task runs with the BLAS and OpenMP thread pools limited to one thread
(``threadpoolctl``), in the serial loop as on a worker. OpenBLAS's results depend on its
thread count in the last bits (a pick-and-place cycle time moved by 4e-16 s between one and
two BLAS threads), and Dask's workers start with one BLAS thread: one thread everywhere
makes a serial run and any cluster agree bit for bit (and two single-thread workers on two
cores do not fight over them).

Memory allocator: Dask's nanny starts workers with ``MALLOC_TRIM_THRESHOLD_=65536``, which
made numpy-heavy tasks 3–5 times slower on a worker than in a plain process (every large
temporary mapped and unmapped); a task run here undoes it once per worker (glibc
``mallopt``), see :func:`_tune_malloc`.

Cost model: the function and each task are pickled and shipped to a worker, the result
pickled back. Keep tasks small (seeds, counts, a few arrays) and results reduced (voxel
counts, tables), and make a task last about a second or more: a Dask task costs roughly
1 ms of scheduling overhead.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from typing import TYPE_CHECKING, Any, Union

import numpy as np

from pinarms.chunks import chunk_seeds, split_count
from pinarms.schedulers import describe_scheduler, parse_scheduler

if TYPE_CHECKING:
    from distributed import Client

#: Where tasks run (module docstring): None or ``"serial"``, ``"processes:N"``, a scheduler
#: address ``"tcp://host:port"``, or a ``distributed.Client``.
Scheduler = Union[str, "Client", None]

__all__ = [
    "Scheduler",
    "chunk_seeds",
    "split_count",
    "map_chunks",
    "reduce_chunks",
    "scheduler_session",
    "describe_scheduler",
    "task_threads",
    "ExecutionError",
]


def __getattr__(name: str):
    # ``pinarms.execution.ExecutionError`` without importing the robots package at import time.
    if name == "ExecutionError":
        from pinarms.errors import ExecutionError

        return ExecutionError
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def task_threads() -> int | None:
    """Threads a task may start itself: 1 inside a Dask worker (a worker per core already
    uses the cores), ``None`` (the caller's default) in this process. Never changes results."""
    import sys

    distributed = sys.modules.get("distributed")  # a worker has it imported; never import it here
    if distributed is None:
        return None
    try:
        distributed.get_worker()
    except ValueError:
        return None
    return 1


def _invalid(message: str) -> Exception:
    from pinarms.errors import InvalidInput

    return InvalidInput(message)


def _task_seed(task: Any) -> int | None:
    """The seed a task carries: its ``seed`` attribute or ``"seed"`` key, else ``None``."""
    seed = task.get("seed") if isinstance(task, Mapping) else getattr(task, "seed", None)
    return int(seed) if isinstance(seed, (int, np.integer)) and not isinstance(seed, bool) else None


def _failure(index: int, task: Any, what: str, cause: str):
    from pinarms.errors import ExecutionError

    seed = _task_seed(task)
    seed_text = f" (seed {seed})" if seed is not None else ""
    return ExecutionError(
        f"chunk {index}{seed_text} {what}: {cause}. Nothing was returned; re-run that chunk "
        "alone (same task, same seed) to reproduce it.",
        chunk=index,
        seed=seed,
        cause=cause,
    )


def _lost(client: Any, done: int, total: int, cause: str):
    """The error for a scheduler that went away mid-run (not a fault of any one chunk)."""
    from pinarms.errors import ExecutionError

    address = getattr(getattr(client, "scheduler", None), "address", None) or "its address"
    return ExecutionError(
        f"lost the connection to the Dask scheduler at {address} after {done} of {total} chunks (the scheduler "
        "stopped, or the network to it failed); nothing was returned. Check that the scheduler and its workers "
        "are running and run again, or run without a scheduler",
        cause=cause,
    )


def _one_line(exc: BaseException) -> str:
    text = str(exc).strip().splitlines()
    return f"{type(exc).__name__}: {text[0]}" if text else type(exc).__name__


def map_chunks(
    fn: Callable[[Any], Any],
    tasks: Sequence,
    *,
    scheduler: Scheduler = None,
    progress: Callable[[int, int], None] | None = None,
) -> list:
    """``[fn(task) for task in tasks]``, run serially or on Dask, results in task order.

    ``fn`` must be a picklable top-level function (a module-level ``def``, not a lambda or a
    closure) when a cluster runs it; it must not rely on global state. ``scheduler``: see the
    module docstring. ``progress(done, total)`` is called in this process each time a result
    arrives (and once with ``(0, total)`` before the first).

    Raises :class:`~pinarms.errors.ExecutionError` naming the failing chunk (its index
    in ``tasks``) and its seed (a task's ``seed`` attribute or ``"seed"`` key) when a task
    raises or its worker dies; the remaining tasks are cancelled and nothing is returned.
    """
    tasks = list(tasks)
    results: list = [None] * len(tasks)

    def keep(i, result):
        results[i] = result

    _run(fn, tasks, keep, scheduler, progress)
    return results


def reduce_chunks(
    fn: Callable[[Any], Any],
    tasks: Sequence,
    combine: Callable[[Any, Any], Any],
    initial: Any,
    *,
    scheduler: Scheduler = None,
    progress: Callable[[int, int], None] | None = None,
) -> Any:
    """``combine(... combine(combine(initial, fn(t0)), fn(t1)) ..., fn(tn))``, folded in task order.

    Like :func:`map_chunks`, but each result is folded into the accumulator as soon as the
    results of all earlier tasks are folded (a result that arrives early waits, and is
    dropped once folded), so the memory holds the accumulator and a few results rather than
    every result. The fold order is the task order whatever the scheduler: floating-point
    sums come out identical bit for bit. ``combine(acc, result)`` returns the new accumulator
    (it may update ``acc`` in place and return it) and runs in this process.
    """
    if not callable(combine):
        raise _invalid(f"combine must be callable, got {type(combine).__name__}")
    tasks = list(tasks)
    state = {"acc": initial, "next": 0}
    waiting: dict[int, Any] = {}

    def fold(i, result):
        waiting[i] = result
        while state["next"] in waiting:
            state["acc"] = combine(state["acc"], waiting.pop(state["next"]))
            state["next"] += 1

    _run(fn, tasks, fold, scheduler, progress)
    return state["acc"]


def _run(fn, tasks, on_result, scheduler, progress) -> None:
    if not callable(fn):
        raise _invalid(f"fn must be callable, got {type(fn).__name__}")
    kind, arg = parse_scheduler(scheduler)
    total = len(tasks)
    if progress is not None:
        progress(0, total)
    if kind == "serial" or total == 0:
        _map_serial(fn, tasks, on_result, progress)
    elif kind == "client":
        _map_client(arg, fn, tasks, on_result, progress)
    elif kind == "processes":
        _map_local_cluster(arg, fn, tasks, on_result, progress)
    else:
        _map_address(arg, fn, tasks, on_result, progress)


_MALLOC_TUNED = False


def _tune_malloc() -> None:
    """Undo the allocator setting Dask's nanny gives its workers (once per process).

    The nanny starts workers with ``MALLOC_TRIM_THRESHOLD_=65536``; setting it also pins
    glibc's mmap threshold at 128 kB, so every numpy temporary larger than that (a block of
    16 384 doubles) is mapped and unmapped again, page faults and all. A streamed-workspace
    task of 10⁶ AUBO-i3 samples took 3.3 s of CPU with the variable set against 0.8–1.3 s
    without. Raising the mmap threshold to 32 MiB and the trim threshold to 64 MiB
    (``mallopt``) gives the worker the speed of a plain process; elsewhere nothing is done.
    """
    global _MALLOC_TUNED
    if _MALLOC_TUNED:
        return
    _MALLOC_TUNED = True
    if "MALLOC_TRIM_THRESHOLD_" not in os.environ:
        return
    import ctypes
    import ctypes.util

    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6")
        libc.mallopt(-3, 32 * 1024 * 1024)  # M_MMAP_THRESHOLD
        libc.mallopt(-1, 64 * 1024 * 1024)  # M_TRIM_THRESHOLD
    except (OSError, AttributeError):  # not glibc: nothing to undo
        pass


def _one_thread(task, fn):
    """``fn(task)`` with the BLAS/OpenMP pools at one thread (see the module docstring)."""
    from threadpoolctl import threadpool_limits

    _tune_malloc()
    with threadpool_limits(limits=1):
        return fn(task)


def _map_serial(fn, tasks, on_result, progress):
    for index, task in enumerate(tasks):
        try:
            result = _one_thread(task, fn)
        except Exception as exc:
            raise _failure(index, task, "raised", _one_line(exc)) from exc
        on_result(index, result)
        if progress is not None:
            progress(index + 1, len(tasks))


@contextmanager
def scheduler_session(scheduler: Scheduler = None) -> Iterator[Scheduler]:
    """``scheduler`` held open for several :func:`map_chunks` calls: ``"processes:N"`` starts its local
    cluster once and yields a ``distributed.Client`` on it (closed with the cluster on exit), so a
    build that maps several waves of tasks (a task map's layers and refinement passes) starts its
    workers, and their imports and caches, once; any other scheduler is yielded as it is."""
    kind, arg = parse_scheduler(scheduler)
    if kind != "processes":
        yield scheduler
        return
    with _local_cluster(arg) as client:
        yield client


@contextmanager
def _local_cluster(n_workers: int) -> Iterator[Any]:
    import warnings

    from distributed import Client, LocalCluster

    import dask

    # the workers' statistical profiler (a thread sampling every 10 ms) took 5-10 % of their CPU
    # on the sizing sweep (benchmarks/line.py sizing): off, as it only feeds the dashboard
    # one task at a time per worker (the default saturation 1.1 sends a second one ahead): a worker
    # process that dies then takes only the chunk that killed it, and only that chunk is blamed
    # (with 1.1, a chunk queued beside the killer on each dying worker was retried as often and
    # could be named instead of it)
    settings = {"distributed.worker.profile.enabled": False, "distributed.scheduler.worker-saturation": 1.0}
    with warnings.catch_warnings(), dask.config.set(settings):
        # the scheduler's HTTP endpoint moves to a free port when 8787 is taken: not our concern
        warnings.filterwarnings("ignore", message="Port .* is already in use")
        cluster = LocalCluster(
            n_workers=n_workers,
            threads_per_worker=1,
            processes=True,
            host="127.0.0.1",
            dashboard_address=None,
        )
    with cluster, Client(cluster) as client:
        yield client


def _map_local_cluster(n_workers, fn, tasks, on_result, progress):
    with _local_cluster(min(n_workers, len(tasks))) as client:
        _map_client(client, fn, tasks, on_result, progress)


def _map_address(address, fn, tasks, on_result, progress):
    import dask
    from distributed import Client

    try:  # Dask's standard connect timeout (distributed.comm.timeouts.connect, 30 s by default)
        client = Client(address, timeout=dask.config.get("distributed.comm.timeouts.connect"))
    except ValueError as exc:  # an address Dask cannot parse after all
        raise _invalid(f"scheduler address {address!r} is not valid: {_one_line(exc)}") from exc
    except (OSError, TimeoutError) as exc:
        from pinarms.errors import ExecutionError

        raise ExecutionError(
            f"cannot reach the Dask scheduler at {address}: {_one_line(exc)}. Start one with "
            "`dask scheduler` and workers with `dask worker ADDRESS` (docs/sweeps.md), or run "
            "without a scheduler",
            cause=_one_line(exc),
        ) from exc
    with client:
        _map_client(client, fn, tasks, on_result, progress)


def _map_client(client, fn, tasks, on_result, progress):
    import uuid

    from distributed import as_completed
    from distributed.client import FutureCancelledError

    try:
        from distributed import KilledWorker
    except ImportError:  # pragma: no cover - older distributed
        from distributed.scheduler import KilledWorker

    total = len(tasks)
    token = uuid.uuid4().hex[:12]
    name = getattr(fn, "__name__", "task")
    keys = [f"pinarms-{name}-{token}-{i}" for i in range(total)]
    futures = client.map(_one_thread, tasks, fn=fn, key=keys, pure=False)
    index_of = {f.key: i for i, f in enumerate(futures)}
    done = 0
    try:
        for future in as_completed(futures):
            i = index_of[future.key]
            if future.status == "error" or future.status == "cancelled":
                try:
                    future.result()
                except KilledWorker as exc:
                    raise _failure(i, tasks[i], "lost its worker (the worker process died)", _one_line(exc)) from exc
                except FutureCancelledError as exc:
                    if "connection-lost" in str(getattr(exc, "reason", "")) or client.status != "running":
                        raise _lost(client, done, total, _one_line(exc)) from exc
                    raise _failure(i, tasks[i], "was cancelled by the cluster", _one_line(exc)) from exc
                except Exception as exc:
                    raise _failure(i, tasks[i], "raised", _one_line(exc)) from exc
                raise _failure(i, tasks[i], "failed", future.status)  # pragma: no cover
            result = future.result()
            future.release()
            on_result(i, result)
            done += 1
            if progress is not None:
                progress(done, total)
    finally:
        if done < total and client.status == "running":  # a lost scheduler has nothing left to cancel
            client.cancel([f for f in futures if not f.done()])
