"""The parent's side of the bounded map reader: start :mod:`pinarms.robots.reach._reach_worker`, limit it, read its frames.

The child runs ``python -I _reach_worker.py`` with an almost empty environment (one BLAS
thread), in a new session, with its address space, CPU time, file size, core dumps (and,
when not root, new processes) limited through ``prlimit`` before it is told which file to
open. Every read of its output has a wall-clock deadline; on expiry the child is killed.
Frames are copied straight into arrays the parent allocated from sizes it checked: nothing
the child sends is unpickled or evaluated.
"""

from __future__ import annotations

import fcntl
import json
import os
import resource
import select
import signal
import struct
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

__all__ = ["ReaderChild", "ChildTimeout", "ChildGone"]

_WORKER = Path(__file__).resolve().parent / "_reach_worker.py"
_ENV = {"OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1", "HDF5_USE_FILE_LOCKING": "FALSE",
        "LC_ALL": "C.UTF-8"}


class ChildTimeout(Exception):
    """The child did not answer before the deadline (it has been killed)."""


class ChildGone(Exception):
    """The child's output ended early: ``args[0]`` is its exit status (negative: the signal)."""


class ReaderChild:
    """One reader process; use as a context manager (the process is always reaped)."""

    def __init__(self, memory_bytes: int, cpu_seconds: int) -> None:
        self.proc = subprocess.Popen(
            [sys.executable, "-I", str(_WORKER)], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
            stderr=subprocess.DEVNULL, env=_ENV, cwd="/", start_new_session=True, close_fds=True,
        )
        pid = self.proc.pid
        try:
            resource.prlimit(pid, resource.RLIMIT_AS, (memory_bytes, memory_bytes))
            resource.prlimit(pid, resource.RLIMIT_CPU, (cpu_seconds, cpu_seconds))
            resource.prlimit(pid, resource.RLIMIT_FSIZE, (0, 0))
            resource.prlimit(pid, resource.RLIMIT_CORE, (0, 0))
            if os.geteuid() != 0:
                resource.prlimit(pid, resource.RLIMIT_NPROC, (0, 0))
        except (ProcessLookupError, PermissionError, OSError, ValueError):
            self.close()
            raise
        self.fd = self.proc.stdout.fileno()
        try:  # fewer, larger reads for big maps (Linux caps unprivileged pipes at 1 MiB)
            fcntl.fcntl(self.fd, fcntl.F_SETPIPE_SZ, 1 << 20)
        except OSError:
            pass
        os.set_blocking(self.fd, False)
        self.poll = select.poll()
        self.poll.register(self.fd, select.POLLIN | select.POLLHUP | select.POLLERR)
        self.rusage: Any = None

    def __enter__(self) -> "ReaderChild":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    def send(self, request: dict) -> None:
        """Write the request (the child reads it only after its ready frame)."""
        try:
            self.proc.stdin.write(json.dumps(request).encode("utf-8"))
            self.proc.stdin.close()
        except BrokenPipeError:
            pass  # the child died; reading its frames reports it

    def read_into(self, view: memoryview, deadline: float) -> None:
        """Fill ``view`` (bytes) from the child before ``deadline`` (``time.monotonic()``)."""
        pos, n = 0, len(view)
        while pos < n:
            try:
                got = os.readv(self.fd, [view[pos:]])
            except BlockingIOError:
                left = deadline - time.monotonic()
                if left <= 0:
                    self.close()
                    raise ChildTimeout() from None
                self.poll.poll(max(1, int(left * 1000)))
                continue
            if got == 0:
                self.close()
                raise ChildGone(self.proc.returncode)
            pos += got

    def frame(self, deadline: float) -> tuple[bytes, int]:
        """The next frame's tag and payload length."""
        head = bytearray(5)
        self.read_into(memoryview(head), deadline)
        return bytes(head[:1]), struct.unpack("<I", head[1:])[0]

    def payload(self, length: int, cap: int, deadline: float) -> bytes:
        """A frame's payload of at most ``cap`` bytes (a longer one: :class:`ChildGone`)."""
        if length > cap:
            self.close()
            raise ChildGone("oversized")
        buf = bytearray(length)
        self.read_into(memoryview(buf), deadline)
        return bytes(buf)

    def close(self) -> None:
        """Kill the child if it still runs and reap it (its resource usage kept in :attr:`rusage`)."""
        if self.proc.returncode is not None:
            return
        try:
            os.killpg(self.proc.pid, signal.SIGKILL)
        except (ProcessLookupError, PermissionError):
            pass
        self._reap()

    def finish(self, deadline: float) -> None:
        """Wait for a child that sent its last frame to exit (killed at ``deadline``)."""
        while self.proc.returncode is None and time.monotonic() < deadline:
            pid, status, usage = os.wait4(self.proc.pid, os.WNOHANG)
            if pid:
                self._status(status, usage)
                return
            time.sleep(0.002)
        self.close()

    def _reap(self) -> None:
        for stream in (self.proc.stdout, self.proc.stdin):
            try:
                stream.close()
            except OSError:
                pass
        _, status, usage = os.wait4(self.proc.pid, 0)
        self._status(status, usage)

    def _status(self, status: int, usage: Any) -> None:
        self.rusage = usage
        self.proc.returncode = os.waitstatus_to_exitcode(status)
        for stream in (self.proc.stdout, self.proc.stdin):
            try:
                stream.close()
            except OSError:
                pass
