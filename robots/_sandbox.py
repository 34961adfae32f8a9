"""The second wall of a child process that parses a user's file: write nothing, read only the allowed paths.

Loaded by path (standard library only) by the children that parse users' files:
:mod:`pinarms.robots._xacro_worker` (xacro files) and :mod:`pinarms.robots.reach._reach_worker`
(reachability maps). After :func:`enter_wall` the calling process (and any child it could
start) can, whatever code it runs:

- read files and list folders only below the given paths (folders, or single files: the
  xacro file's folder and the package folders; the one map file) and the interpreter's
  standard library and site-packages, read-only;
- create, write, truncate, rename, link or remove nothing anywhere (files already open,
  such as the pipes to the parent, stay usable);
- execute no file (so it cannot start another program), bind or connect no TCP socket,
  signal no process outside itself, reach no abstract Unix socket (as far as the kernel's
  Landlock version supports each of these).

The wall is Linux Landlock (kernel ≥ 5.13), set through raw system calls with
``no_new_privs``. Without Landlock a process running as root drops to the user ``nobody``
with a process limit of 0 instead (it can then still read world-readable files, no longer
files only root may read — a caller opens what it needs first — and start no new process);
otherwise only the parent's resource limits remain. :func:`enter_wall` says which wall is
up; for xacro files the expression whitelist of :mod:`pinarms.robots.xacro_eval` is the
first wall in every case.
"""

from __future__ import annotations

import ctypes
import os
import resource
import sysconfig

__all__ = ["enter_wall", "python_roots"]

_SYS_CREATE_RULESET, _SYS_ADD_RULE, _SYS_RESTRICT_SELF = 444, 445, 446  # same on x86_64 and aarch64
_PR_SET_NO_NEW_PRIVS = 38
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
        if libc.prctl(_PR_SET_NO_NEW_PRIVS, 1, 0, 0, 0) != 0:
            raise OSError(ctypes.get_errno(), "prctl(PR_SET_NO_NEW_PRIVS) failed")
        if libc.syscall(ctypes.c_long(_SYS_RESTRICT_SELF), ctypes.c_int(ruleset), ctypes.c_uint32(0)) < 0:
            raise OSError(ctypes.get_errno(), "landlock_restrict_self failed")
    finally:
        os.close(ruleset)
    return f"landlock (ABI {abi})"


def _drop_to_nobody() -> str:
    # no new processes or threads once it is nobody (root is exempt from the limit; Landlock
    # needs none); it could still execute a program in place, world-readable files only
    resource.setrlimit(resource.RLIMIT_NPROC, (0, 0))
    os.setgroups([])
    os.setgid(65534)
    os.setuid(65534)
    return "user nobody (no Landlock)"


def enter_wall(read_roots: list[str]) -> str:
    """Restrict this process to reading ``read_roots`` (folders or files, and Python's own folders); which wall is up.

    Returns ``"landlock (ABI n)"``, ``"user nobody (no Landlock)"`` or ``"resource limits only"``.
    """
    roots = sorted({os.path.realpath(r) for r in (*read_roots, *python_roots()) if os.path.exists(r)})
    try:
        return _landlock(roots)
    except (OSError, AttributeError):
        pass
    if os.geteuid() == 0:
        try:
            return _drop_to_nobody()
        except OSError:
            pass
    return "resource limits only"
