"""Where a sweep runs: the ``scheduler`` argument of the execution layer, checked and described.

:func:`pinarms.execution.map_chunks` takes ``scheduler=None`` (serial, this process),
``"processes"`` / ``"processes:N"`` (a local Dask cluster), a Dask scheduler address
``"tcp://HOST:8786"``, ``"env"`` (the address in ``DASK_SCHEDULER_ADDRESS``, read only when
asked for) or a ``distributed.Client``. :func:`parse_scheduler` turns that argument into a
kind and its value, or raises :class:`~pinarms.errors.InvalidInput` saying what to give;
:func:`describe_scheduler` names it in words. Part of the floor: imports the error classes (``pinarms.errors``) and no package above
it, Dask only when a client object must be recognised.
"""

from __future__ import annotations

import os
from typing import Any

from pinarms.errors import InvalidInput

__all__ = ["describe_scheduler", "parse_scheduler"]


def describe_scheduler(scheduler: Any = None) -> str:
    """A short text naming where :func:`~pinarms.execution.map_chunks` would run with this ``scheduler``."""
    kind, arg = parse_scheduler(scheduler)
    if kind == "serial":
        return "serial (this process)"
    if kind == "processes":
        return f"local Dask cluster, {arg} worker process{'es' if arg != 1 else ''}"
    if kind == "address":
        return f"Dask cluster at {arg}"
    return f"Dask client {getattr(arg, 'scheduler', None) and arg.scheduler.address}"


def parse_scheduler(scheduler: Any) -> tuple[str, Any]:
    """``(kind, value)`` of a ``scheduler`` argument: ``("serial", None)``, ``("processes", n_workers)``,
    ``("address", "scheme://HOST:PORT")`` or ``("client", client)``; :class:`InvalidInput` naming it otherwise."""
    if scheduler is None or scheduler == "serial":
        return "serial", None
    if isinstance(scheduler, str):
        text = scheduler.strip()
        if text == "env":
            address = os.environ.get("DASK_SCHEDULER_ADDRESS", "").strip()
            if not address:
                raise InvalidInput(
                    'scheduler="env" reads DASK_SCHEDULER_ADDRESS, which is not set: export '
                    "DASK_SCHEDULER_ADDRESS=tcp://HOST:8786 or pass the address itself"
                )
            return parse_scheduler(address)
        if text == "processes" or text.startswith("processes:"):
            count = text.partition(":")[2]
            if not count:
                return "processes", max(1, os.cpu_count() or 1)
            if not count.isdigit() or int(count) < 1:
                raise InvalidInput(f"scheduler {scheduler!r}: the worker count after 'processes:' must be a positive integer")
            return "processes", int(count)
        if "://" in text:
            return "address", _check_address(text, scheduler)
        raise InvalidInput(
            f"unknown scheduler {scheduler!r}: use None (serial), 'processes', 'processes:N', "
            "'tcp://HOST:8786', 'env' (DASK_SCHEDULER_ADDRESS) or a distributed.Client"
        )
    try:
        from distributed import Client
    except ImportError:  # pragma: no cover - dask[distributed] is a dependency
        Client = ()  # noqa: N806
    if Client and isinstance(scheduler, Client):
        return "client", scheduler
    raise InvalidInput(f"scheduler must be None, a string or a distributed.Client, got {type(scheduler).__name__}")


#: Transports a Dask scheduler address may name.
_SCHEMES = ("tcp", "tls", "ws", "wss", "ucx", "inproc")


def _check_address(text: str, scheduler: Any) -> str:
    """``scheme://HOST:PORT`` with a known scheme and a port 1-65535, else :class:`InvalidInput` naming it."""
    scheme, _, rest = text.partition("://")
    host, sep, port = rest.rpartition(":")
    if scheme == "inproc" and rest:
        return text
    if scheme not in _SCHEMES or not sep or not host.strip("[]") or not port.isdigit() or not 0 < int(port) < 65536:
        raise InvalidInput(
            f"scheduler address {scheduler!r} is not a Dask scheduler address: give scheme://HOST:PORT with a "
            f"scheme among {', '.join(_SCHEMES)} and a PORT from 1 to 65535, e.g. tcp://127.0.0.1:8786"
        )
    return text
