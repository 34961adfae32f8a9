"""The parent's side of the xacro child: start :mod:`pinarms.robots._xacro_worker`, serve the files it asks for, bound it.

The child reads no file of the request itself: it asks, one JSON line on its stdout at a
time, ``{"op": "read", "path", "what"}`` or ``{"op": "glob", "pattern"}``, and this side
answers one JSON line on its stdin after checking that the path (symbolic links resolved)
lies inside the allowed folders and is a regular file no larger than the output bound. So
the child's sandbox needs no read access to the user's folders, and a child that runs as
``nobody`` (no Landlock) still expands a file in a folder only root may read. Its last line
is the answer, ``{"ok": ...}`` without ``"op"``.

Every read of the child's output has the wall-clock deadline, and no line may exceed
``output_bytes``: the child is killed at the bound, before more is read.
"""

from __future__ import annotations

import glob
import json
import os
import select
import signal
import stat
import subprocess
import sys
import time
from pathlib import Path
from typing import Callable

__all__ = ["run_worker", "WorkerTimeout", "WorkerOutputTooLarge", "WorkerFailed"]

_WORKER = Path(__file__).resolve().parent / "_xacro_worker.py"
_MAGIC = set("*?[")
_MAX_GLOB = 10_000
_STDERR_KEPT = 1 << 16
#: environment variables handed on to the child (a switch for tests; see ``_sandbox.enter_wall``)
_FORWARDED = ("PINARMS_SANDBOX_NO_LANDLOCK",)


class WorkerTimeout(Exception):
    """The child did not answer before the deadline (it has been killed)."""


class WorkerOutputTooLarge(Exception):
    """The child wrote a line longer than the bound (it has been killed)."""


class WorkerFailed(Exception):
    """The child ended without an answer: ``args`` are its exit status and the end of its stderr."""


class _Files:
    """Answers the child's file requests: only regular files inside ``roots``, at most ``max_bytes`` each."""

    def __init__(self, roots: list[str], packages: list[str], max_bytes: int) -> None:
        self.roots, self.packages, self.max_bytes = roots, packages, max_bytes
        self.served: set[str] = set()

    def inside(self, real: str) -> bool:
        return any(real == r or real.startswith(r.rstrip(os.sep) + os.sep) for r in self.roots)

    def outside(self, what: str, path: str) -> dict:
        return {"forbidden": f"{what} '{path}' is outside the folders this file may read (its own folder and "
                             f"the packages given: {', '.join(sorted(self.packages)) or 'none'})"}

    def answer(self, request: dict) -> dict:
        name = str(request.get("pattern" if request.get("op") == "glob" else "path", ""))
        if "\0" in name:
            return {"errno": 22, "message": "the name holds a NUL character"}
        if request.get("op") == "glob":
            return self.glob(name)
        path, what = name, str(request.get("what", "file"))
        real = os.path.realpath(path)
        if not self.inside(real):
            return self.outside(what, path)
        try:
            fd = os.open(real, os.O_RDONLY | os.O_NONBLOCK | os.O_CLOEXEC)
        except OSError as exc:
            return {"errno": exc.errno, "message": exc.strerror}
        with os.fdopen(fd, "rb") as handle:
            info = os.fstat(fd)
            if not stat.S_ISREG(info.st_mode):
                return {"errno": 22, "message": "not a regular file"}
            data = handle.read(self.max_bytes + 1)
        if len(data) > self.max_bytes:
            return {"limit": f"{what} '{path}' is larger than the {self.max_bytes / 2**20:g} MiB allowed"}
        try:
            text = data.decode("utf-8")
        except UnicodeDecodeError as exc:
            return {"errno": 84, "message": f"not UTF-8 text (byte {exc.start})"}
        self.served.add(real)
        return {"text": text}

    def glob(self, pattern: str) -> dict:
        parts = Path(pattern).parts
        fixed = next((i for i, p in enumerate(parts) if _MAGIC & set(p)), len(parts))
        prefix = os.path.realpath(os.path.join(*parts[:fixed])) if fixed else os.sep
        if not os.path.isabs(pattern) or not self.inside(prefix):
            return self.outside("include pattern", pattern)
        names = sorted(glob.glob(pattern))
        if len(names) > _MAX_GLOB:
            return {"limit": f"include pattern '{pattern}' matches more than {_MAX_GLOB} files"}
        return {"names": names}


def run_worker(request: dict, *, cwd: str, timeout_s: float, output_bytes: int,
               preexec: Callable[[], None]) -> tuple[dict, list[str]]:
    """Run the worker on ``request``; its answer and the files served to it (resolved, sorted).

    Raises:
        WorkerTimeout, WorkerOutputTooLarge, WorkerFailed: see the classes.
    """
    files = _Files(list(request["roots"]), list(request.get("packages", {})), output_bytes)
    env = {k: os.environ[k] for k in _FORWARDED if k in os.environ}
    proc = subprocess.Popen([sys.executable, "-I", "-B", str(_WORKER)], stdin=subprocess.PIPE,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env, cwd=cwd,
                            preexec_fn=preexec, start_new_session=True)
    try:
        answer = _serve(proc, files, request, time.monotonic() + timeout_s, output_bytes)
    finally:
        if proc.poll() is None:
            try:
                os.killpg(proc.pid, signal.SIGKILL)
            except (ProcessLookupError, PermissionError):
                pass
        for stream in (proc.stdin, proc.stdout, proc.stderr):
            try:
                stream.close()
            except OSError:
                pass
        proc.wait()
    return answer, sorted(files.served)


def _serve(proc: subprocess.Popen, files: _Files, request: dict, deadline: float, output_bytes: int) -> dict:
    out_fd, err_fd, in_fd = proc.stdout.fileno(), proc.stderr.fileno(), proc.stdin.fileno()
    for fd in (out_fd, err_fd, in_fd):
        os.set_blocking(fd, False)
    pending = bytearray(json.dumps(request).encode("utf-8") + b"\n")
    parts, size, err = [], 0, bytearray()  # the pieces of the line being received, their size
    poller = select.poll()
    for fd in (out_fd, err_fd):
        poller.register(fd, select.POLLIN)
    poller.register(in_fd, select.POLLOUT)
    in_open, open_fds = True, {out_fd, err_fd}
    while out_fd in open_fds:
        left = deadline - time.monotonic()
        if left <= 0:
            raise WorkerTimeout()
        for fd, event in poller.poll(max(1, int(left * 1000))):
            if fd == in_fd:
                if event & (select.POLLERR | select.POLLHUP):  # the child closed its stdin
                    poller.unregister(in_fd)
                    in_open = False
                    continue
                try:
                    del pending[: os.write(in_fd, pending[: 1 << 16])]
                except BlockingIOError:
                    continue
                if not pending:
                    poller.modify(in_fd, 0)
                continue
            try:
                chunk = os.read(fd, 1 << 16)
            except BlockingIOError:
                continue
            if not chunk:
                open_fds.discard(fd)
                poller.unregister(fd)
            elif fd == err_fd:
                err = (err + chunk)[-_STDERR_KEPT:]
            else:
                end = chunk.find(b"\n")
                while end >= 0:  # only the new bytes are searched
                    if size + end > output_bytes:
                        raise WorkerOutputTooLarge(size + end)
                    message = _decode(b"".join(parts) + chunk[:end])
                    parts, size, chunk = [], 0, chunk[end + 1:]
                    if "op" not in message:
                        return message
                    if in_open:
                        pending += json.dumps(files.answer(message)).encode("utf-8") + b"\n"
                        poller.modify(in_fd, select.POLLOUT)
                    end = chunk.find(b"\n")
                if chunk:
                    parts.append(chunk)
                    size += len(chunk)
                if size > output_bytes:
                    raise WorkerOutputTooLarge(size)
    line = b"".join(parts)
    if line.strip():
        message = _decode(bytes(line))
        if "op" not in message:
            return message
    try:
        status = proc.wait(max(0.0, deadline - time.monotonic()))
    except subprocess.TimeoutExpired:
        raise WorkerTimeout() from None
    raise WorkerFailed(status, err.decode("utf-8", "replace"))


def _decode(line: bytes) -> dict:
    try:
        message = json.loads(line)
    except ValueError:
        raise WorkerFailed("unreadable answer", line[:200].decode("utf-8", "replace")) from None
    if not isinstance(message, dict):
        raise WorkerFailed("unreadable answer", line[:200].decode("utf-8", "replace"))
    return message
