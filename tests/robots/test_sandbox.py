"""The map reader's second wall: code inside the reader child writes nothing and reads only the map.

The probes below run in the reader child's own setup (:class:`ReaderChild`: its interpreter,
environment, session and resource limits) and call the worker's :func:`enter_wall`, the same
step its ``main`` takes before h5py opens the map; only what follows it differs.
"""

from __future__ import annotations

import ctypes
import json
import os
import time
from pathlib import Path

import h5py
import numpy as np
import pytest

from pinarms import robots
from pinarms.robots.reach import _reach_child, reach_io
from pinarms.robots.reach.reach_io import load_reachability, save_reachability
from pinarms.robots.reach.reachability import ReachabilityRequest, reachability_map

WORKER = _reach_child._WORKER
SECRET = "not for the reader\n"


def _landlock_abi() -> int:
    """The kernel's Landlock ABI version (< 1: none), asked as the sandbox asks it."""
    libc = ctypes.CDLL(None, use_errno=True)
    libc.syscall.restype = ctypes.c_long
    return libc.syscall(ctypes.c_long(444), None, ctypes.c_size_t(0), ctypes.c_uint32(1))


LANDLOCK = _landlock_abi() >= 1

# Loads the real worker by path; optionally makes Landlock fail; then either runs the worker's
# main (a whole load) or enters its wall and tries things, answering in one ``M`` frame.
SCRIPT = r"""
import importlib.util, json, os, sys
spec = importlib.util.spec_from_file_location("reach_worker", {worker!r})
worker = importlib.util.module_from_spec(spec)
spec.loader.exec_module(worker)
if {no_landlock!r}:
    load = worker._load_sandbox
    def without_landlock():
        sandbox = load()
        def no_landlock(roots):
            raise OSError("Landlock is not available")
        sandbox._landlock = no_landlock
        return sandbox
    worker._load_sandbox = without_landlock
if {probe!r}:
    import h5py
    worker._send(b"R")
    req = json.loads(sys.stdin.buffer.read(1 << 20))
    wall, source = worker.enter_wall(req["path"])
    out = {{"wall": wall, "uid": os.getuid(), "source": "path" if isinstance(source, str) else "open file"}}
    def attempt(name, fn):
        try:
            out[name] = fn()
        except OSError as exc:
            out[name] = type(exc).__name__
    folder = os.path.dirname(req["path"])
    def read_map():
        with h5py.File(source, "r") as h5:
            return int(h5["voxels/reached"][()].sum())
    attempt("read_map", read_map)
    attempt("read_map_by_name", lambda: len(open(req["path"], "rb").read()) > 0)
    attempt("read_beside_map", lambda: open(os.path.join(folder, "notes.txt")).read())
    attempt("list_map_folder", lambda: len(os.listdir(folder)))
    attempt("read_sibling", lambda: open(req["sibling"]).read())
    attempt("read_passwd", lambda: len(open("/etc/passwd").read()) > 0)
    attempt("create_file", lambda: open(os.path.join(folder, "new.txt"), "w").close())
    attempt("create_dir", lambda: os.mkdir(os.path.join(folder, "new_dir")))
    def create_in_tmp():
        made = "/tmp/reader-was-here-" + str(os.getpid())
        os.mkdir(made)
        os.rmdir(made)
        return "done"
    attempt("create_in_tmp", create_in_tmp)
    attempt("remove_map", lambda: os.unlink(req["path"]))
    attempt("start_process", lambda: os.waitpid(os.posix_spawn("/bin/true", ["/bin/true"], {{}}), 0)[1])
    worker._send(b"M", json.dumps(out).encode())
else:
    worker.main()
    sys.stdout.flush()
    os._exit(0)
"""


@pytest.fixture(scope="module")
def small_map():
    return reachability_map(ReachabilityRequest(robots.load("aubo_i3"), 0.2, 8))


@pytest.fixture
def layout(small_map, tmp_path):
    """A map in its own folder beside a note, and a sibling folder holding a secret."""
    (tmp_path / "maps").mkdir()
    (tmp_path / "other").mkdir()
    (tmp_path / "maps" / "notes.txt").write_text(SECRET)
    (tmp_path / "other" / "secret.txt").write_text(SECRET)
    return save_reachability(small_map, tmp_path / "maps" / "aubo.h5"), tmp_path / "other" / "secret.txt"


def _script(tmp_path: Path, *, probe: bool, no_landlock: bool) -> Path:
    path = tmp_path / ("probe.py" if probe else "forced.py")
    path.write_text(SCRIPT.format(worker=str(WORKER), probe=probe, no_landlock=no_landlock))
    return path


def _probe(monkeypatch, tmp_path: Path, map_path: Path, sibling: Path, *, no_landlock: bool) -> dict:
    monkeypatch.setattr(_reach_child, "_WORKER", _script(tmp_path, probe=True, no_landlock=no_landlock))
    with _reach_child.ReaderChild(reach_io.READER_MEMORY, 30) as child:
        child.send({"path": str(map_path.resolve()), "sibling": str(sibling)})
        deadline = time.monotonic() + 60
        assert child.frame(deadline) == (b"R", 0)
        tag, size = child.frame(deadline)
        assert tag == b"M"
        return json.loads(child.payload(size, 1 << 16, deadline))


def test_a_valid_map_loads_behind_the_wall(small_map, layout):
    loaded = load_reachability(layout[0])
    assert loaded.identical(small_map) and len(loaded.solutions) == small_map.n_reached
    assert loaded.reader_wall.startswith(("landlock (ABI ", "user nobody", "resource limits only"))
    if LANDLOCK:
        assert loaded.reader_wall == f"landlock (ABI {_landlock_abi()}), no capabilities, seccomp"
    assert small_map.reader_wall == ""  # built here, not read


@pytest.mark.skipif(not LANDLOCK, reason="this kernel has no Landlock")
def test_inside_the_readers_wall_only_the_map_is_readable_and_nothing_writable(monkeypatch, tmp_path, small_map,
                                                                              layout):
    map_path, sibling = layout
    out = _probe(monkeypatch, tmp_path, map_path, sibling, no_landlock=False)
    assert out.pop("wall") == f"landlock (ABI {_landlock_abi()}), no capabilities, seccomp"
    assert out == {"uid": os.getuid(), "source": "path", "read_map": int(small_map.reached.sum()),
                   "read_map_by_name": True, "read_beside_map": "PermissionError",
                   "list_map_folder": "PermissionError", "read_sibling": "PermissionError",
                   "read_passwd": "PermissionError", "create_file": "PermissionError",
                   "create_dir": "PermissionError", "create_in_tmp": "PermissionError",
                   "remove_map": "PermissionError", "start_process": out["start_process"]}
    # executing is refused by the wall (a non-root reader may not even fork: its process limit is 0)
    assert out["start_process"] in ("PermissionError", "BlockingIOError")
    assert sorted(p.name for p in tmp_path.rglob("*")) == ["aubo.h5", "maps", "notes.txt", "other", "probe.py",
                                                            "secret.txt"]


@pytest.mark.skipif(not hasattr(os, "geteuid") or os.geteuid() != 0, reason="the fallback drops root's privileges")
def test_without_landlock_the_root_reader_drops_to_nobody_and_reads_the_open_map(monkeypatch, tmp_path, small_map,
                                                                                layout):
    map_path, sibling = layout
    os.chmod(map_path, 0o600)  # only root may open it by name; the folders above are private too
    out = _probe(monkeypatch, tmp_path, map_path, sibling, no_landlock=True)
    assert out == {"wall": "user nobody (no Landlock), no capabilities, seccomp", "uid": 65534, "source": "open file",
                   "read_map": int(small_map.reached.sum()), "read_map_by_name": "PermissionError",
                   "read_beside_map": "PermissionError", "list_map_folder": "PermissionError",
                   "read_sibling": "PermissionError", "read_passwd": True, "create_file": "PermissionError",
                   "create_dir": "PermissionError", "create_in_tmp": "PermissionError",
                   "remove_map": "PermissionError", "start_process": "PermissionError"}  # seccomp, before the process limit


def test_a_whole_load_with_landlock_made_unavailable(monkeypatch, tmp_path, small_map, layout):
    monkeypatch.setattr(_reach_child, "_WORKER", _script(tmp_path, probe=False, no_landlock=True))
    loaded = load_reachability(layout[0])
    assert loaded.identical(small_map)
    assert loaded.reader_wall == ("user nobody (no Landlock)" if os.geteuid() == 0 else "resource limits only") + (
        ", no capabilities, seccomp")


def test_a_map_that_is_not_a_regular_file_is_refused_before_h5py_opens_it(tmp_path):
    fifo = tmp_path / "map.h5"
    os.mkfifo(fifo)
    from pinarms.robots.reach._reach_worker import Refused, enter_wall

    with pytest.raises(Refused, match="not a regular file"):
        enter_wall(str(fifo))
    with pytest.raises(Refused, match="cannot be opened"):
        enter_wall(str(tmp_path / "missing.h5"))
