"""A seccomp filter for the children that parse users' files: no network, no metadata changes, no process control.

Loaded by path (standard library only) by :mod:`pinarms.robots._sandbox`. The filter is a
classic BPF program built here with :mod:`ctypes` and installed with ``seccomp(2)``
(``SECCOMP_SET_MODE_FILTER``, all threads); once installed it can never be removed, and a
child of the process inherits it. It answers ``EPERM`` (``ENOSYS`` where noted) to:

- **network**: ``socket``, ``socketpair``, ``connect``, ``bind``, ``listen``, ``accept``,
  ``sendto``/``sendmsg``/``sendmmsg`` (the children talk to their parent over inherited pipes);
- **metadata changes**: the ``chmod``, ``chown``, ``utime`` and ``setxattr``/``removexattr``
  families, ``file_setattr`` and the ``FS_IOC_SETFLAGS``/``FS_IOC_FSSETXATTR`` ioctls (chattr);
- **writing files** (for kernels without Landlock): ``open``/``openat`` with a write, create,
  truncate, append or temporary-file flag, ``openat2`` (``ENOSYS``: its flags cannot be
  inspected), ``creat``, ``mkdir``, ``mknod``, ``link``, ``symlink``, ``rename``, ``unlink``,
  ``rmdir``, ``truncate``;
- **process control**: signals to any process but itself (``kill``, ``tgkill``,
  ``rt_sigqueueinfo`` aimed elsewhere, ``tkill``, ``pidfd_send_signal``), ``setpriority`` and
  the scheduler setters, ``prlimit64`` on another process, ``ptrace``, reading or writing
  another process's memory, ``fork``/``vfork``/``clone`` of a process (threads are allowed),
  ``clone3`` (``ENOSYS``, so the C library falls back to ``clone``), ``execve``,
  ``chroot``, ``mount`` and the new mount API, ``unshare``, ``setns``;
- **ways around a filter**: ``io_uring_*``, ``bpf``, ``perf_event_open``, ``userfaultfd``,
  the key ring, ``open_by_handle_at``;
- a system call of another ABI (x32 numbers); another architecture kills the process.

The numbers are those of x86_64 (``arch/x86/entry/syscalls/syscall_64.tbl`` of Linux 6.18);
on another architecture :func:`install` raises :class:`Unsupported` and the caller runs
without the filter (and says so).
"""

from __future__ import annotations

import ctypes
import errno
import os
import platform

__all__ = ["install", "Unsupported", "DENIED", "program"]

_AUDIT_ARCH_X86_64 = 0xC000003E
_X32_BIT = 0x40000000
_SYS_SECCOMP = 317
_SECCOMP_SET_MODE_FILTER, _SECCOMP_FILTER_FLAG_TSYNC = 1, 1
_RET_KILL_PROCESS, _RET_ERRNO, _RET_ALLOW = 0x80000000, 0x00050000, 0x7FFF0000
_LD_ABS_W, _JEQ, _JGE, _JSET, _RET = 0x20, 0x15, 0x35, 0x45, 0x06
_NR, _ARCH = 0, 4

#: x86_64 system calls answered EPERM whatever their arguments, by family.
DENIED = {
    "network": {"socket": 41, "connect": 42, "accept": 43, "sendto": 44, "sendmsg": 46, "bind": 49, "listen": 50,
                "socketpair": 53, "accept4": 288, "sendmmsg": 307},
    "metadata": {"chmod": 90, "fchmod": 91, "chown": 92, "fchown": 93, "lchown": 94, "utime": 132,
                 "setxattr": 188, "lsetxattr": 189, "fsetxattr": 190, "removexattr": 197, "lremovexattr": 198,
                 "fremovexattr": 199, "utimes": 235, "fchownat": 260, "futimesat": 261, "fchmodat": 268,
                 "utimensat": 280, "fchmodat2": 452, "setxattrat": 463, "removexattrat": 466, "file_setattr": 469},
    "files": {"truncate": 76, "rename": 82, "mkdir": 83, "rmdir": 84, "creat": 85, "link": 86, "unlink": 87,
              "symlink": 88, "mknod": 133, "mkdirat": 258, "mknodat": 259, "unlinkat": 263, "renameat": 264,
              "linkat": 265, "symlinkat": 266, "renameat2": 316, "name_to_handle_at": 303,
              "open_by_handle_at": 304},
    "processes": {"fork": 57, "vfork": 58, "execve": 59, "ptrace": 101, "setpriority": 141, "sched_setparam": 142,
                  "sched_setscheduler": 144, "pivot_root": 155, "chroot": 161, "mount": 165, "umount2": 166,
                  "tkill": 200, "ioprio_set": 251, "migrate_pages": 256, "unshare": 272, "move_pages": 279,
                  "setns": 308, "process_vm_readv": 310, "process_vm_writev": 311, "kcmp": 312,
                  "sched_setattr": 314, "execveat": 322, "pidfd_send_signal": 424, "open_tree": 428,
                  "move_mount": 429, "fsopen": 430, "fsconfig": 431, "fsmount": 432, "fspick": 433,
                  "pidfd_open": 434, "pidfd_getfd": 438, "process_madvise": 440, "mount_setattr": 442,
                  "process_mrelease": 448, "open_tree_attr": 467},
    "bypass": {"add_key": 248, "request_key": 249, "keyctl": 250, "perf_event_open": 298, "bpf": 321,
               "userfaultfd": 323, "io_uring_setup": 425, "io_uring_enter": 426, "io_uring_register": 427},
}
_OPEN, _OPENAT, _OPENAT2, _CLONE, _CLONE3, _IOCTL = 2, 257, 437, 56, 435, 16
_KILL, _TGKILL, _RT_SIGQUEUEINFO, _RT_TGSIGQUEUEINFO, _PRLIMIT64 = 62, 234, 129, 297, 302
# O_WRONLY | O_RDWR | O_CREAT | O_TRUNC | O_APPEND | __O_TMPFILE
_WRITE_FLAGS = 0o1 | 0o2 | 0o100 | 0o1000 | 0o2000 | 0o20000000
_CLONE_THREAD = 0x10000
# FS_IOC_SETFLAGS, FS_IOC32_SETFLAGS, FS_IOC_FSSETXATTR, TIOCSTI (pushing input into a terminal)
_DENIED_IOCTLS = (0x40086602, 0x40046602, 0x401C5820, 0x5412)


class Unsupported(Exception):
    """This machine's architecture or kernel has no filter here (the message says which)."""


class _Filter(ctypes.Structure):
    _fields_ = [("code", ctypes.c_uint16), ("jt", ctypes.c_uint8), ("jf", ctypes.c_uint8), ("k", ctypes.c_uint32)]


class _Program(ctypes.Structure):
    _fields_ = [("len", ctypes.c_ushort), ("filter", ctypes.POINTER(_Filter))]


def _arg(i: int, high: bool = False) -> int:
    """Offset of argument ``i`` (its low or high 32 bits, little-endian) in ``struct seccomp_data``."""
    return 16 + 8 * i + (4 if high else 0)


class _Assembler:
    """BPF instructions with named jump targets, resolved to relative offsets at the end."""

    def __init__(self) -> None:
        self.code: list[tuple[int, object, object, int]] = []
        self.labels: dict[str, int] = {}

    def op(self, code: int, k: int, jt: object = 0, jf: object = 0) -> None:
        self.code.append((code, jt, jf, k))

    def label(self, name: str) -> None:
        self.labels[name] = len(self.code)

    def resolve(self) -> list[tuple[int, int, int, int]]:
        out = []
        for i, (code, jt, jf, k) in enumerate(self.code):
            jumps = [self.labels[j] - i - 1 if isinstance(j, str) else j for j in (jt, jf)]
            if any(not 0 <= j <= 255 for j in jumps):
                raise ValueError(f"BPF jump out of range at instruction {i}")
            out.append((code, jumps[0], jumps[1], k))
        return out


def program(pid: int) -> list[tuple[int, int, int, int]]:
    """The filter as ``(code, jt, jf, k)`` instructions; signals and ``prlimit64`` are allowed on ``pid`` only."""
    a = _Assembler()
    deny, allow = "deny", "allow"
    a.op(_LD_ABS_W, _ARCH)
    a.op(_JEQ, _AUDIT_ARCH_X86_64, 1, 0)
    a.op(_RET, _RET_KILL_PROCESS)
    a.op(_LD_ABS_W, _NR)
    a.op(_JGE, _X32_BIT, deny, 0)
    for nr in sorted(nr for family in DENIED.values() for nr in family.values()):
        a.op(_JEQ, nr, deny, 0)
    checks = {_OPEN: "open", _OPENAT: "openat", _OPENAT2: "enosys", _CLONE3: "enosys", _CLONE: "clone",
              _IOCTL: "ioctl", _KILL: "own", _TGKILL: "own", _RT_SIGQUEUEINFO: "own", _RT_TGSIGQUEUEINFO: "own",
              _PRLIMIT64: "self_or_own"}
    for nr, target in checks.items():
        a.op(_JEQ, nr, target, 0)
    a.op(_RET, _RET_ALLOW)
    for name, index in (("open", 1), ("openat", 2)):  # flags
        a.label(name)
        a.op(_LD_ABS_W, _arg(index))
        a.op(_JSET, _WRITE_FLAGS, deny, allow)
    a.label("clone")  # flags in the first argument: threads only
    a.op(_LD_ABS_W, _arg(0))
    a.op(_JSET, _CLONE_THREAD, allow, deny)
    a.label("ioctl")
    a.op(_LD_ABS_W, _arg(1))
    for request in _DENIED_IOCTLS:
        a.op(_JEQ, request, deny, 0)
    a.op(_RET, _RET_ALLOW)
    a.label("self_or_own")  # prlimit64(0, ...) is this process
    a.op(_LD_ABS_W, _arg(0))
    a.op(_JEQ, 0, "high_zero", 0)
    a.label("own")  # the first argument (a pid) must be this process's
    a.op(_LD_ABS_W, _arg(0))
    a.op(_JEQ, pid, 0, deny)
    a.label("high_zero")
    a.op(_LD_ABS_W, _arg(0, high=True))
    a.op(_JEQ, 0, allow, deny)
    a.label(deny)
    a.op(_RET, _RET_ERRNO | errno.EPERM)
    a.label("enosys")
    a.op(_RET, _RET_ERRNO | errno.ENOSYS)
    a.label(allow)
    a.op(_RET, _RET_ALLOW)
    return a.resolve()


def install() -> str:
    """Install the filter on every thread of this process; what was installed (``"seccomp"``).

    Raises:
        Unsupported: not x86_64, or the kernel refuses seccomp filters (the message says which).
    """
    machine = platform.machine()
    if machine not in ("x86_64", "AMD64"):
        raise Unsupported(f"no seccomp filter for {machine} (x86_64 only)")
    code = program(os.getpid())
    filters = (_Filter * len(code))(*(_Filter(c, jt, jf, k) for c, jt, jf, k in code))
    prog = _Program(len(code), ctypes.cast(filters, ctypes.POINTER(_Filter)))
    libc = ctypes.CDLL(None, use_errno=True)
    libc.syscall.restype = ctypes.c_long
    if libc.syscall(ctypes.c_long(_SYS_SECCOMP), ctypes.c_uint(_SECCOMP_SET_MODE_FILTER),
                    ctypes.c_uint(_SECCOMP_FILTER_FLAG_TSYNC), ctypes.byref(prog)) != 0:
        err = ctypes.get_errno()
        raise Unsupported(f"the kernel refused the seccomp filter ({os.strerror(err)})")
    return "seccomp"
