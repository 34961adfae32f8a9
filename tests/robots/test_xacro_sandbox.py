"""The xacro child's second wall (robots/_sandbox.py): code inside it writes nothing, reads only the
allowed folders and runs no program; without Landlock a root child drops to nobody."""

from __future__ import annotations

import ctypes
import os
import subprocess
import sys
from pathlib import Path

import pytest

from pinarms import robots
from pinarms.robots.xacro_expand import XacroLimits, expand_xacro
from tests.robots.xacro_files import SCARA_ON_PEDESTAL, SECRET, write


# ---- issue 29: the sandbox (the second wall) ---------------------------------------------------------

PROBE = r"""
import importlib.util, json, os, sys
spec = importlib.util.spec_from_file_location("sandbox", sys.argv[1])
sandbox = importlib.util.module_from_spec(spec)
spec.loader.exec_module(sandbox)
allowed, sibling = sys.argv[2], sys.argv[3]
out = {"wall": sandbox.enter_wall([allowed])}
def attempt(name, fn):
    try:
        fn()
        out[name] = "done"
    except OSError as exc:
        out[name] = type(exc).__name__
attempt("read_allowed", lambda: open(os.path.join(allowed, "part.txt")).read())
attempt("list_allowed", lambda: os.listdir(allowed))
attempt("read_sibling", lambda: open(os.path.join(sibling, "secret.txt")).read())
attempt("read_passwd", lambda: open("/etc/passwd").read())
attempt("create_file", lambda: open(os.path.join(allowed, "new.txt"), "w").close())
attempt("create_dir", lambda: os.mkdir(os.path.join(allowed, "new_dir")))
attempt("create_elsewhere", lambda: os.mkdir(os.path.join(os.path.dirname(allowed), "new_dir")))
attempt("remove_file", lambda: os.unlink(os.path.join(allowed, "part.txt")))
attempt("run_program", lambda: os.execv("/bin/true", ["/bin/true"]))
sys.stdout.write(json.dumps(out))
"""


def test_code_inside_the_sandbox_writes_nothing_and_reads_only_the_allowed_folder(tmp_path):
    from pinarms.robots.xacro_expand import _limit_resources

    allowed, sibling = tmp_path / "cell", tmp_path / "other"
    allowed.mkdir()
    sibling.mkdir()
    (allowed / "part.txt").write_text("part")
    (sibling / "secret.txt").write_text(SECRET)
    sandbox = Path(robots.__file__).resolve().parent / "_sandbox.py"
    done = subprocess.run([sys.executable, "-I", "-B", "-c", PROBE, str(sandbox), str(allowed), str(sibling)],
                          capture_output=True, text=True, timeout=60, env={},
                          preexec_fn=_limit_resources(XacroLimits()))
    assert done.returncode == 0, done.stderr
    out = __import__("json").loads(done.stdout)
    if not out["wall"].startswith("landlock"):
        pytest.skip(f"this kernel has no Landlock (wall: {out['wall']})")
    assert out.pop("wall").startswith("landlock (ABI ")
    assert out == {"read_allowed": "done", "list_allowed": "done", "read_sibling": "PermissionError",
                   "read_passwd": "PermissionError", "create_file": "PermissionError",
                   "create_dir": "PermissionError", "create_elsewhere": "PermissionError",
                   "remove_file": "PermissionError", "run_program": "PermissionError"}
    assert sorted(p.name for p in tmp_path.rglob("*")) == ["cell", "other", "part.txt", "secret.txt"]


FALLBACK = r"""
import importlib.util, json, os, sys
spec = importlib.util.spec_from_file_location("sandbox", sys.argv[1])
sandbox = importlib.util.module_from_spec(spec)
spec.loader.exec_module(sandbox)
def no_landlock(roots):
    raise OSError("Landlock is not available")
sandbox._landlock = no_landlock
out = {"wall": sandbox.enter_wall([sys.argv[2]]), "uid": os.getuid(), "gid": os.getgid()}
try:
    os.mkdir(os.path.join(sys.argv[2], "new_dir"))
    out["create_dir"] = "done"
except OSError as exc:
    out["create_dir"] = type(exc).__name__
sys.stdout.write(json.dumps(out))
"""


@pytest.mark.skipif(not hasattr(os, "geteuid") or os.geteuid() != 0, reason="the fallback drops root's privileges")
def test_without_landlock_a_root_child_drops_to_nobody(tmp_path):
    folder = tmp_path / "cell"
    folder.mkdir(mode=0o755)
    sandbox = Path(robots.__file__).resolve().parent / "_sandbox.py"
    done = subprocess.run([sys.executable, "-I", "-B", "-c", FALLBACK, str(sandbox), str(folder)],
                          capture_output=True, text=True, timeout=60, env={})
    assert done.returncode == 0, done.stderr
    assert __import__("json").loads(done.stdout) == {"wall": "user nobody (no Landlock), no capabilities, seccomp",
                                                     "uid": 65534, "gid": 65534,
                                                     "create_dir": "PermissionError"}
    assert list(folder.iterdir()) == []


def test_expansions_report_the_wall_they_ran_behind(tmp_path):
    result = expand_xacro(write(tmp_path, "pedestal.xacro", SCARA_ON_PEDESTAL))
    assert result.wall.startswith(("landlock", "user nobody", "resource limits only"))
    libc = ctypes.CDLL(None, use_errno=True)
    libc.syscall.restype = ctypes.c_long
    abi = libc.syscall(ctypes.c_long(444), None, ctypes.c_size_t(0), ctypes.c_uint32(1))  # landlock_create_ruleset
    if abi >= 1:  # the kernel offers Landlock: the child must be behind it
        assert result.wall == f"landlock (ABI {abi}), no capabilities, seccomp"


THREADED = r"""
import importlib.util, json, sys, threading
spec = importlib.util.spec_from_file_location("sandbox", sys.argv[1])
sandbox = importlib.util.module_from_spec(spec)
spec.loader.exec_module(sandbox)
stop = threading.Event()
threading.Thread(target=stop.wait).start()
try:
    sandbox.enter_wall([])
    out = "walled"
except OSError as exc:
    out = str(exc)
stop.set()
sys.stdout.write(json.dumps({"out": out, "caps": sandbox.capabilities()["effective"] != 0 or __import__("os").getuid() != 0}))
"""


def test_a_process_with_a_second_thread_is_refused_before_any_step(tmp_path):
    sandbox = Path(robots.__file__).resolve().parent / "_sandbox.py"
    done = subprocess.run([sys.executable, "-I", "-B", "-c", THREADED, str(sandbox)],
                          capture_output=True, text=True, timeout=60, env={})
    assert done.returncode == 0, done.stderr
    out = __import__("json").loads(done.stdout)
    assert out == {"out": "the wall needs a single-threaded process, this one has 2 threads (Landlock and "
                          "capabilities bind only the calling thread)", "caps": True}
