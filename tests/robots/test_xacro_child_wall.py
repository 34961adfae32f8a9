"""The xacro child's wall as root (issue 35, items 6 and 7): no capability, no network, no metadata change,
no control of other processes, with Landlock and in the fallback (``nobody``), proven from inside the child.

The probe replaces the worker script but runs its real setup: the real parent side
(:func:`pinarms.robots._xacro_child.run_worker`, with the resource limits of
:func:`expand_xacro`), then the worker's own :func:`prepare` (imports, hooks, wall), then the attempts.
"""

from __future__ import annotations

import os
import select
import socket
import subprocess
from pathlib import Path

import pytest

from pinarms.robots import _xacro_child
from pinarms.robots.xacro_expand import XacroLimits, _limit_resources
from tests.robots.xacro_files import SCARA_ON_PEDESTAL, write

ROOT = hasattr(os, "geteuid") and os.geteuid() == 0

PROBE = r"""
import ctypes, encodings.idna, importlib.util, json, os, socket, sys  # what the attempts use, loaded before the wall
spec = importlib.util.spec_from_file_location("pinarms_xacro_worker_probe", {worker!r})
worker = importlib.util.module_from_spec(spec)
sys.modules[spec.name] = worker
spec.loader.exec_module(worker)
request = json.loads(sys.stdin.readline())
_, _, wall = worker.prepare(request)
sandbox = sys.modules["pinarms_xacro_child__sandbox"]
p = request["probe"]
libc = ctypes.CDLL(None)
out = {{"wall": wall, "uid": os.getuid(), "caps": sandbox.capabilities(),
        "no_new_privs": libc.prctl(39, 0, 0, 0, 0), "seccomp_mode": libc.prctl(21, 0, 0, 0, 0)}}
def attempt(name, fn):
    try:
        fn()
        out[name] = "done"
    except OSError as exc:
        out[name] = type(exc).__name__
def udp():
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.sendto(b"x", ("127.0.0.1", p["udp"]))
def tcp():
    with socket.create_connection(("127.0.0.1", p["tcp"]), timeout=2):
        pass
def unix(address):
    with socket.socket(socket.AF_UNIX, socket.SOCK_STREAM) as s:
        s.connect(address)
attempt("chmod", lambda: os.chmod(p["victim"], 0o777))
attempt("chown", lambda: os.chown(p["victim"], 65534, 65534))
attempt("utime", lambda: os.utime(p["victim"], (0, 0)))
attempt("setxattr", lambda: os.setxattr(p["victim"], "user.pinarms", b"x"))
attempt("udp_sendto", udp)
attempt("tcp_connect", tcp)
attempt("unix_path_connect", lambda: unix(p["unix"]))
attempt("unix_abstract_connect", lambda: unix(p["abstract"]))
attempt("setpriority_other", lambda: os.setpriority(os.PRIO_PROCESS, p["other"], 19))
attempt("kill_other", lambda: os.kill(p["other"], 15))
attempt("chroot", lambda: os.chroot(p["public"]))
attempt("create_in_public_folder", lambda: open(os.path.join(p["public"], "new.txt"), "w").close())
attempt("run_program", lambda: os.execv("/bin/true", ["/bin/true"]))
attempt("signal_itself", lambda: os.kill(os.getpid(), 0))
sys.stdout.write(json.dumps(out) + "\n")
"""

ATTEMPTS = ("chmod", "chown", "utime", "setxattr", "udp_sendto", "tcp_connect", "unix_path_connect",
            "unix_abstract_connect", "setpriority_other", "kill_other", "chroot", "create_in_public_folder",
            "run_program")


@pytest.fixture
def targets(tmp_path):
    """Things a hostile child would reach for, each with a way to see whether it was touched."""
    folder, outside, public = tmp_path / "cell", tmp_path / "outside", tmp_path / "public"
    for d in (folder, outside, public):
        d.mkdir()
    public.chmod(0o1777)  # world-writable, like /tmp
    victim = outside / "victim.txt"
    victim.write_text("keep me")
    victim.chmod(0o644)
    tcp = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    tcp.bind(("127.0.0.1", 0))
    tcp.listen(4)
    udp = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    udp.bind(("127.0.0.1", 0))
    unix = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    unix.bind(str(tmp_path / "control.sock"))
    unix.listen(4)
    abstract = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    abstract_name = f"\0pinarms-test-{os.getpid()}-{tmp_path.name}"
    abstract.bind(abstract_name)
    abstract.listen(4)
    other = subprocess.Popen(["sleep", "60"], start_new_session=True)
    listeners = {"tcp": tcp, "udp": udp, "unix": unix, "abstract": abstract}
    yield {"folder": folder, "victim": victim, "public": public, "other": other, "listeners": listeners,
           "probe": {"victim": str(victim), "public": str(public), "other": other.pid, "udp": udp.getsockname()[1],
                     "tcp": tcp.getsockname()[1], "unix": str(tmp_path / "control.sock"), "abstract": abstract_name}}
    other.kill()
    other.wait()
    for s in listeners.values():
        s.close()


def _probe(monkeypatch, tmp_path: Path, targets: dict) -> dict:
    script = tmp_path / "probe.py"
    script.write_text(PROBE.format(worker=str(_xacro_child._WORKER)))
    monkeypatch.setattr(_xacro_child, "_WORKER", script)
    folder = targets["folder"]
    request = {"path": str(write(folder, "arm.xacro", SCARA_ON_PEDESTAL)), "args": {}, "roots": [str(folder)],
               "packages": {}, "header": [], "probe": targets["probe"]}
    limits = XacroLimits()
    answer, _ = _xacro_child.run_worker(request, cwd=str(folder), timeout_s=30, output_bytes=1 << 20,
                                        preexec=_limit_resources(limits))
    return answer


def _untouched(targets: dict, before: os.stat_result) -> None:
    after = os.stat(targets["victim"])
    assert (after.st_mode, after.st_uid, after.st_gid, after.st_mtime_ns) == (
        before.st_mode, before.st_uid, before.st_gid, before.st_mtime_ns)
    assert os.listxattr(targets["victim"]) == []
    for name, s in targets["listeners"].items():
        assert select.select([s], [], [], 0)[0] == [], f"the {name} listener was reached"
    assert list(targets["public"].iterdir()) == []
    other = targets["other"]
    assert other.poll() is None and os.getpriority(os.PRIO_PROCESS, other.pid) == 0


@pytest.mark.skipif(not ROOT, reason="the test proves what a root child cannot do")
@pytest.mark.parametrize("fallback", [False, True], ids=["landlock", "nobody"])
def test_a_root_xacro_child_has_no_capability_no_network_and_changes_nothing_outside(monkeypatch, tmp_path, targets,
                                                                                     fallback):
    if fallback:
        monkeypatch.setenv("PINARMS_SANDBOX_NO_LANDLOCK", "1")
    before = os.stat(targets["victim"])
    out = _probe(monkeypatch, tmp_path, targets)
    _untouched(targets, before)
    assert out["caps"] == {"effective": 0, "permitted": 0, "inheritable": 0, "bounding": 0}
    assert (out["no_new_privs"], out["seccomp_mode"]) == (1, 2)  # 2: SECCOMP_MODE_FILTER
    assert out["signal_itself"] == "done"  # the filter lets a process signal itself (abort, timers)
    assert out["wall"].endswith(", no capabilities, seccomp")
    if fallback:
        assert out["wall"].startswith("user nobody (no Landlock)") and out["uid"] == 65534
    else:
        assert out["wall"].startswith("landlock (ABI ") and out["uid"] == 0
    assert {name: out[name] for name in ATTEMPTS} == {name: "PermissionError" for name in ATTEMPTS}


# ---- item 7: the fallback (no Landlock: a root child becomes nobody) expands what Landlock expands ----------

XACRO_DIR = Path(__file__).resolve().parents[2] / "robots" / "xacro"
SHIPPED = sorted([*XACRO_DIR.glob("*.xacro"), *XACRO_DIR.glob("cells/*.xacro")])


@pytest.mark.skipif(not ROOT, reason="the fallback drops root's privileges")
def test_in_the_fallback_a_file_in_a_folder_only_root_may_read_expands_with_its_includes(monkeypatch, tmp_path):
    from pinarms.robots.xacro_expand import expand_xacro

    folder = tmp_path / "private"
    folder.mkdir(mode=0o700)
    write(folder, "sizes.yaml", "height: 0.5\n")
    write(folder, "base.xacro", '<robot xmlns:xacro="http://www.ros.org/wiki/xacro">'
                                '<link name="base"><visual><geometry><box size="1 1 ${sizes.height}"/></geometry>'
                                '</visual></link></robot>')
    main = write(folder, "cell.urdf.xacro", '<robot name="c" xmlns:xacro="http://www.ros.org/wiki/xacro">'
                                            '<xacro:property name="sizes" value="${load_yaml(\'sizes.yaml\')}"/>'
                                            '<xacro:include filename="base.xacro"/></robot>')
    for p in folder.iterdir():
        p.chmod(0o600)
    monkeypatch.setenv("PINARMS_SANDBOX_NO_LANDLOCK", "1")
    result = expand_xacro(main)
    assert result.wall == "user nobody (no Landlock), no capabilities, seccomp"
    assert '<box size="1 1 0.5"/>' in result.urdf_text
    assert result.files == tuple(sorted(str(p.resolve()) for p in folder.iterdir()))


@pytest.mark.slow
@pytest.mark.skipif(not ROOT, reason="the fallback drops root's privileges")
def test_the_fallback_expands_every_shipped_xacro_as_landlock_does(monkeypatch):
    from pinarms.robots.xacro_expand import expand_xacro

    assert len(SHIPPED) >= 14
    walled = {p: expand_xacro(p) for p in SHIPPED}
    monkeypatch.setenv("PINARMS_SANDBOX_NO_LANDLOCK", "1")
    for path, expected in walled.items():
        got = expand_xacro(path)
        assert got.wall == "user nobody (no Landlock), no capabilities, seccomp", path.name
        assert (got.urdf_text, got.files, dict(got.declared)) == (expected.urdf_text, expected.files,
                                                                  dict(expected.declared)), path.name


def test_on_another_architecture_the_filter_is_refused_by_name(monkeypatch):
    import platform

    from pinarms.robots import _seccomp

    monkeypatch.setattr(platform, "machine", lambda: "aarch64")
    with pytest.raises(_seccomp.Unsupported, match=r"no seccomp filter for aarch64 \(x86_64 only\)"):
        _seccomp.install()
