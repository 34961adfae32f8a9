"""The second wall of a child process that parses a user's file: write nothing, read only the allowed paths,
no capability, no network, no control of other processes.

Loaded by path (standard library only) by the children that parse users' files:
:mod:`pinarms.robots._xacro_worker` (xacro files; it reads them through its parent and
allows no folder) and :mod:`pinarms.robots.reach._reach_worker` (reachability maps). After
:func:`enter_wall` the calling process (and any child it could start) can, whatever code it
runs:

- read files and list folders only below the given paths and the interpreter's standard
  library and site-packages, read-only (Landlock);
- create, write, truncate, rename, link or remove nothing anywhere (files already open,
  such as the pipes to the parent, stay usable);
- execute no file, start no process, open no network socket, signal, renice or trace no
  other process, chroot or mount nothing, change no file's mode, owner, times or
  extended attributes (seccomp, :mod:`pinarms.robots._seccomp`; x86_64 only);
- use no capability: the bounding, effective, permitted, inheritable and ambient sets are
  emptied, ``no_new_privs`` is set, and root's special treatment at exec is locked off.

Landlock (kernel >= 5.13) is set through raw system calls. Without it (or with
``PINARMS_SANDBOX_NO_LANDLOCK=1`` in the environment: a switch for tests) a process running
as root drops to the user ``nobody`` with a process limit of 0 instead: it can then still
read world-readable files, no longer files only root may read (a caller opens what it needs
first, and imports every module it will use). :func:`enter_wall` says which steps were
taken; for xacro files the expression whitelist of :mod:`pinarms.robots.xacro_eval` is the
first wall in every case.
"""

from __future__ import annotations

import ctypes
import errno
import importlib.util
import os
import resource
import sysconfig
from pathlib import Path

__all__ = ["enter_wall", "python_roots", "capabilities"]

_SYS_CREATE_RULESET, _SYS_ADD_RULE, _SYS_RESTRICT_SELF = 444, 445, 446  # same on x86_64 and aarch64
_PR_SET_NO_NEW_PRIVS = 38
_PR_CAPBSET_READ, _PR_CAPBSET_DROP, _PR_SET_SECUREBITS, _PR_CAP_AMBIENT, _PR_CAP_AMBIENT_CLEAR_ALL = 23, 24, 28, 47, 4
# SECBIT_NOROOT and its lock, the setuid fix-up and keep-caps locked in their default (off: setuid clears
# capabilities), SECBIT_NO_CAP_AMBIENT_RAISE and its lock
_SECUREBITS_LOCKED_NOROOT = 0b11 | 0b1000 | 0b100000 | 0b11000000
_CAP_VERSION_3 = 0x20080522
_CREATE_RULESET_VERSION = 1
_RULE_PATH_BENEATH = 1
_READ_FILE, _READ_DIR = 1 << 2, 1 << 3
# every filesystem right a Landlock ABI version knows (v1: 13 rights, v2: refer, v3: truncate, v5: ioctl_dev)
_FS_RIGHTS = {1: (1 << 13) - 1, 2: (1 << 14) - 1, 3: (1 << 15) - 1, 4: (1 << 15) - 1, 5: (1 << 16) - 1}
_NET_BIND_CONNECT_TCP = 0b11  # v4
_SCOPE_UNIX_SIGNAL = 0b11  # v6


class _RulesetAttr(ctypes.Structure):
    _fields_ = [("handled_access_fs", ctypes.c_uint64), ("handled_access_net", ctypes.c_uint64),
                ("scoped", ctypes.c_uint64)]


class _PathBeneathAttr(ctypes.Structure):
    _pack_ = 1
    _fields_ = [("allowed_access", ctypes.c_uint64), ("parent_fd", ctypes.c_int32)]


def python_roots() -> list[str]:
    """Folders the interpreter reads from: its standard library and site-packages."""
    paths = sysconfig.get_paths()
    return sorted({os.path.realpath(paths[k]) for k in ("stdlib", "purelib", "platlib") if os.path.isdir(paths[k])})


def _landlock(read_roots: list[str]) -> str:
    libc = ctypes.CDLL(None, use_errno=True)
    libc.syscall.restype = ctypes.c_long
    abi = libc.syscall(ctypes.c_long(_SYS_CREATE_RULESET), None, ctypes.c_size_t(0),
                       ctypes.c_uint32(_CREATE_RULESET_VERSION))
    if abi < 1:
        raise OSError(ctypes.get_errno(), "Landlock is not available")
    attr = _RulesetAttr(_FS_RIGHTS[min(abi, 5)], _NET_BIND_CONNECT_TCP if abi >= 4 else 0,
                        _SCOPE_UNIX_SIGNAL if abi >= 6 else 0)
    size = 24 if abi >= 6 else 16 if abi >= 4 else 8
    ruleset = libc.syscall(ctypes.c_long(_SYS_CREATE_RULESET), ctypes.byref(attr), ctypes.c_size_t(size),
                           ctypes.c_uint32(0))
    if ruleset < 0:
        raise OSError(ctypes.get_errno(), "landlock_create_ruleset failed")
    try:
        for root in read_roots:
            fd = os.open(root, os.O_PATH | os.O_CLOEXEC)
            try:
                rights = _READ_FILE | (_READ_DIR if os.path.isdir(root) else 0)
                rule = _PathBeneathAttr(rights, fd)
                if libc.syscall(ctypes.c_long(_SYS_ADD_RULE), ctypes.c_int(ruleset), ctypes.c_int(_RULE_PATH_BENEATH),
                                ctypes.byref(rule), ctypes.c_uint32(0)) < 0:
                    raise OSError(ctypes.get_errno(), f"landlock_add_rule failed for {root}")
            finally:
                os.close(fd)
        if libc.syscall(ctypes.c_long(_SYS_RESTRICT_SELF), ctypes.c_int(ruleset), ctypes.c_uint32(0)) < 0:
            raise OSError(ctypes.get_errno(), "landlock_restrict_self failed")
    finally:
        os.close(ruleset)
    return f"landlock (ABI {abi})"


def _drop_to_nobody() -> str:
    # no new processes or threads once it is nobody (root is exempt from the limit; Landlock
    # needs none); seccomp refuses execve and fork besides
    resource.setrlimit(resource.RLIMIT_NPROC, (0, 0))
    os.setgroups([])
    os.setgid(65534)
    os.setuid(65534)
    return "user nobody (no Landlock)"


class _CapHeader(ctypes.Structure):
    _fields_ = [("version", ctypes.c_uint32), ("pid", ctypes.c_int)]


class _CapData(ctypes.Structure):
    _fields_ = [("effective", ctypes.c_uint32), ("permitted", ctypes.c_uint32), ("inheritable", ctypes.c_uint32)]


def _drop_bounding_set(libc) -> None:
    """Empty the bounding set and lock root's special treatment off (needs CAP_SETPCAP, which only root has)."""
    if libc.prctl(_PR_SET_SECUREBITS, _SECUREBITS_LOCKED_NOROOT, 0, 0, 0) != 0:
        if ctypes.get_errno() != errno.EPERM:
            raise OSError(ctypes.get_errno(), "prctl(PR_SET_SECUREBITS) failed")
        return  # no CAP_SETPCAP: an unprivileged process; exec can gain nothing under no_new_privs
    for cap in range(64):
        if libc.prctl(_PR_CAPBSET_DROP, cap, 0, 0, 0) != 0 and ctypes.get_errno() != errno.EINVAL:
            raise OSError(ctypes.get_errno(), f"prctl(PR_CAPBSET_DROP, {cap}) failed")


def _drop_capabilities(libc) -> None:
    """Clear the ambient, effective, permitted and inheritable sets of this thread."""
    if libc.prctl(_PR_CAP_AMBIENT, _PR_CAP_AMBIENT_CLEAR_ALL, 0, 0, 0) != 0 and ctypes.get_errno() != errno.EINVAL:
        raise OSError(ctypes.get_errno(), "prctl(PR_CAP_AMBIENT_CLEAR_ALL) failed")
    data = (_CapData * 2)()
    if libc.capset(ctypes.byref(_CapHeader(_CAP_VERSION_3, 0)), data) != 0:
        raise OSError(ctypes.get_errno(), "capset failed")


def capabilities() -> dict[str, int]:
    """This thread's capability sets as bit masks (``effective``, ``permitted``, ``inheritable``, ``bounding``)."""
    libc = ctypes.CDLL(None, use_errno=True)
    data = (_CapData * 2)()
    if libc.capget(ctypes.byref(_CapHeader(_CAP_VERSION_3, 0)), data) != 0:
        raise OSError(ctypes.get_errno(), "capget failed")
    out = {k: getattr(data[0], k) | getattr(data[1], k) << 32
           for k in ("effective", "permitted", "inheritable")}
    out["bounding"] = sum(1 << cap for cap in range(64) if libc.prctl(_PR_CAPBSET_READ, cap, 0, 0, 0) == 1)
    return out


def _load_seccomp():
    spec = importlib.util.spec_from_file_location(f"{__name__}_seccomp", Path(__file__).with_name("_seccomp.py"))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def enter_wall(read_roots: list[str]) -> str:
    """Restrict this process to reading ``read_roots`` (folders or files, and Python's own folders); which wall is up.

    The steps, in order: ``no_new_privs``; Landlock (unless the kernel lacks it, or
    ``PINARMS_SANDBOX_NO_LANDLOCK=1`` is in this process's environment: a switch for tests);
    the bounding set emptied (root); without Landlock a root process becomes ``nobody``;
    every capability dropped; the seccomp filter of :mod:`pinarms.robots._seccomp`.
    Everything the process will import must be imported before, and the process must have
    one thread (else ``OSError``, before any step: Landlock and capabilities bind only the
    calling thread).

    Returns the steps taken, e.g. ``"landlock (ABI 7), no capabilities, seccomp"``; the
    first part is ``"landlock (ABI n)"``, ``"user nobody (no Landlock)"`` or ``"resource
    limits only"``, the last ``"seccomp"`` or ``"no seccomp (reason)"``.
    """
    try:
        threads = len(os.listdir("/proc/self/task"))
    except OSError:  # no /proc: nothing to count with
        threads = 1
    if threads > 1:
        raise OSError(f"the wall needs a single-threaded process, this one has {threads} threads "
                      "(Landlock and capabilities bind only the calling thread)")
    roots = sorted({os.path.realpath(r) for r in (*read_roots, *python_roots()) if os.path.exists(r)})
    seccomp = _load_seccomp()
    libc = ctypes.CDLL(None, use_errno=True)
    if libc.prctl(_PR_SET_NO_NEW_PRIVS, 1, 0, 0, 0) != 0:
        raise OSError(ctypes.get_errno(), "prctl(PR_SET_NO_NEW_PRIVS) failed")
    wall = None
    if os.environ.get("PINARMS_SANDBOX_NO_LANDLOCK") != "1":
        try:
            wall = _landlock(roots)
        except (OSError, AttributeError):
            pass
    _drop_bounding_set(libc)
    if wall is None and os.geteuid() == 0:
        wall = _drop_to_nobody()
    _drop_capabilities(libc)
    try:
        filtered = seccomp.install()
    except seccomp.Unsupported as exc:
        filtered = f"no seccomp ({exc})"
    return f"{wall or 'resource limits only'}, no capabilities, {filtered}"
