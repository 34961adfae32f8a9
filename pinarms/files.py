"""Atomic file writes, the one writer of the project: a temporary file in the target's folder, then ``os.replace``.

Part of the floor every package may import (with :mod:`pinarms.execution` and
:mod:`pinarms.units`): it imports nothing of pinarms but the error classes.

A crash or an exception while writing never leaves a partial file at the target path (an
existing file there stays untouched until the new one is complete). The temporary file is
``.<name>.<random>.part`` beside the target, locked (``flock``) while it is written. A
process killed mid-write (SIGKILL, power loss) cannot remove its own; the next save of the
same target removes every such leftover that no live writer holds and that is older than
:data:`STALE_AFTER_S`.

Whole folders (exports) are written the same way: :func:`publish_folder` fills a new folder
beside the target and renames it into place; inside it, :func:`write_new_file` and
:func:`copy_new_file` create each file new at a path :func:`path_inside` proved inside the
folder, and :func:`safe_file_name` turns a received name into a plain file name. Folders get
the umask's permissions (:func:`folder_mode`).
"""

from __future__ import annotations

import os
import re
import shutil
import stat
import tempfile
import time
from pathlib import Path
from typing import BinaryIO, Callable

from pinarms.errors import InvalidInput

try:  # POSIX; elsewhere leftovers are recognised by age alone
    import fcntl
except ImportError:  # pragma: no cover - Windows
    fcntl = None  # type: ignore[assignment]

__all__ = ["atomic_write", "write_text", "temporary_for", "publish", "discard", "clean_leftovers", "STALE_AFTER_S"]

STALE_AFTER_S = 2.0
"""A ``.part`` file is a leftover once unlocked and unmodified for this long (s); without flock: 1 hour."""


def _umask() -> int:
    """The process's umask, read from ``/proc/self/status`` (Linux): setting it to read it, as
    ``os.umask`` must, would leave a moment in which another thread creates files with umask 0."""
    try:
        with open("/proc/self/status", encoding="ascii") as status:
            for line in status:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError, IndexError):
        pass
    umask = os.umask(0o077)  # elsewhere: the strictest value for the moment it takes
    os.umask(umask)
    return umask


def _default_mode() -> int:
    """Permissions a plain ``open(path, "w")`` would give (0o666 minus the umask)."""
    return 0o666 & ~_umask()


def _is_part_of(entry: str, name: str) -> bool:
    """Whether ``entry`` is a temporary file of :func:`atomic_write` for target ``name``."""
    prefix = f".{name}."
    if not (entry.startswith(prefix) and entry.endswith(".part")):
        return False
    middle = entry[len(prefix): -len(".part")]
    return 0 < len(middle) <= 16 and "." not in middle and "/" not in middle


def clean_leftovers(target: str | os.PathLike, *, keep: str | None = None) -> list[Path]:
    """Remove the ``.<name>.*.part`` files a crashed save of ``target`` left; return those removed.

    A file is removed only when no process holds its lock (its writer is gone) and it is
    older than :data:`STALE_AFTER_S`; ``keep`` names one to leave alone (the caller's own).
    """
    target = Path(target)
    folder = target.parent if str(target.parent) else Path(".")
    removed: list[Path] = []
    try:
        entries = list(os.scandir(folder))
    except OSError:
        return removed
    now = time.time()
    for e in entries:
        if e.name == keep or not _is_part_of(e.name, target.name):
            continue
        try:
            if not e.is_file(follow_symlinks=False):
                continue
            fd = os.open(e.path, os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0))
        except OSError:
            continue
        try:
            st = os.fstat(fd)
            if fcntl is not None:
                try:
                    fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                except OSError:
                    continue  # a live writer holds it
                if now - st.st_mtime < STALE_AFTER_S:
                    continue
            elif now - st.st_mtime < 3600:  # pragma: no cover - Windows
                continue
            os.unlink(e.path)
            removed.append(Path(e.path))
        except OSError:
            continue
        finally:
            os.close(fd)
    return removed


def _target(path: str | os.PathLike) -> Path:
    """``path`` as a writable target: a file name in an existing folder (else :class:`InvalidInput`)."""
    if not isinstance(path, (str, os.PathLike)):
        raise InvalidInput(f"a file path must be a str or a path, got {type(path).__name__}")
    target = Path(path)
    if "\x00" in str(target) or not target.name or target.name in (".", ".."):
        raise InvalidInput(f"cannot write {str(target)!r}: not a file name")
    folder = target.parent if str(target.parent) else Path(".")
    if not folder.is_dir():
        raise InvalidInput(f"cannot write {str(target)!r}: folder {str(folder)!r} does not exist; create it first")
    if target.is_dir():
        raise InvalidInput(f"cannot write {str(target)!r}: it is a folder; give a file name")
    return target


def temporary_for(path: str | os.PathLike) -> tuple[Path, str]:
    """``(target, temporary path)`` for a writer that needs a file *name* (HDF5): write the
    temporary, then :func:`publish` it, or remove it on failure. Same checks as :func:`atomic_write`."""
    target = _target(path)
    folder = target.parent if str(target.parent) else Path(".")
    fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".part", dir=folder)
    os.close(fd)
    return target, tmp


def publish(tmp: str | os.PathLike, target: str | os.PathLike) -> Path:
    """Make the finished temporary file ``tmp`` the target: flushed to disk, the usual permissions, renamed."""
    with open(tmp, "rb+") as f:
        os.fsync(f.fileno())
    os.chmod(tmp, _default_mode())
    os.replace(tmp, target)
    return Path(target)


def discard(tmp: str | os.PathLike) -> None:
    """Remove an unfinished temporary file (gone already: nothing to do)."""
    try:
        os.unlink(tmp)
    except FileNotFoundError:
        pass


# --------------------------------------------------------------------------- whole folders (exports)
# A folder of files is written as one: filled under a temporary name beside the target, then
# renamed into place (publish_folder). Inside the folder being filled, every file is new
# (write_new_file, copy_new_file) and its path is proven to lie inside the folder.

_SAFE_NAME = re.compile(r"(?:[^A-Za-z0-9_.-]|\.{2,})+")
MAX_NAME_LENGTH = 100
"""Longest file name :func:`safe_file_name` returns (characters), suffixes excluded."""


def folder_mode() -> int:
    """Permissions a plain ``os.mkdir`` would give (0o777 minus the umask)."""
    return 0o777 & ~_umask()


def safe_file_name(text: str, fallback: str) -> str:
    """``text`` as one file name: each run of characters outside ``A-Z a-z 0-9 _ . -`` (and of ``..``)
    becomes one ``_``, leading ``.`` and ``-`` are dropped, the rest cut to :data:`MAX_NAME_LENGTH`; ``fallback`` when
    nothing is left. ``"../other/evil"`` → ``"_other_evil"``, ``"/tmp/x"`` → ``"_tmp_x"``."""
    name = _SAFE_NAME.sub("_", str(text)).lstrip(".-")[:MAX_NAME_LENGTH]
    return name or fallback


def output_folder(path: str | os.PathLike) -> Path:
    """The real folder a whole-folder writer fills for ``path``: symbolic links in it followed (a link to
    a folder is that folder, written through and kept as a link).

    Raises:
        InvalidInput: ``path`` is a file, a NUL byte, or a symbolic link to nothing.
    """
    text = os.fspath(path)
    if not isinstance(text, str) or "\x00" in text or not text:
        raise InvalidInput(f"cannot write the folder {text!r}: not a folder name")
    if os.path.islink(text) and not os.path.exists(text):
        raise InvalidInput(f"folder {text!r} is a symbolic link to {os.readlink(text)!r}, which does not exist; "
                           "create that folder or give another one")
    real = Path(os.path.realpath(text))
    if real.exists() and not real.is_dir():
        raise InvalidInput(f"folder {text!r} is a file; give a folder path")
    return real


def path_inside(folder: str | os.PathLike, relative: str) -> Path:
    """``folder/relative``, proven to lie inside ``folder``: ``relative`` is a POSIX path of plain names
    (no absolute path, no ``.`` or ``..``, no empty or hidden part, no control character), and its
    longest existing part, symbolic links resolved, lies inside ``folder`` resolved.

    Raises:
        InvalidInput: naming ``relative`` and the folder.
    """
    parts = str(relative).split("/")
    if any(not p or p.startswith(".") or any(ord(c) < 32 for c in p) for p in parts):
        raise InvalidInput(f"cannot write {str(relative)!r} into {os.fspath(folder)!r}: not a path of plain names")
    root = Path(os.path.realpath(folder))
    target = root.joinpath(*parts)
    existing = target
    while not os.path.lexists(existing):
        existing = existing.parent
    if not Path(os.path.realpath(existing)).is_relative_to(root):
        raise InvalidInput(f"cannot write {str(relative)!r} into {str(root)!r}: it resolves outside that folder")
    return target


def write_new_file(folder: str | os.PathLike, relative: str, data: bytes) -> Path:
    """Write ``data`` as the new file ``folder/relative`` (:func:`path_inside`; its folders created with the
    umask's permissions); an existing entry there, a link included, is an error, never followed."""
    target = path_inside(folder, relative)
    target.parent.mkdir(parents=True, exist_ok=True)
    path_inside(folder, relative)  # its folders, now made, still inside
    flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_CLOEXEC", 0)
    fd = os.open(target, flags, 0o666)  # the umask applies
    with os.fdopen(fd, "wb") as f:
        f.write(data)
    return target


def copy_new_file(folder: str | os.PathLike, relative: str, source: str | os.PathLike, max_bytes: int,
                  transform: Callable[[bytes], bytes] | None = None) -> Path:
    """Copy the regular file ``source`` (its last part not a link) of at most ``max_bytes`` to the new file
    ``folder/relative`` (:func:`write_new_file`), through ``transform(data)`` when given.

    Raises:
        InvalidInput: ``source`` is not a regular file (a link, a device, a FIFO) or is larger than ``max_bytes``.
    """
    flags = os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0)
    try:
        fd = os.open(source, flags)
    except OSError as exc:
        raise InvalidInput(f"cannot copy {os.fspath(source)!r}: {exc.strerror or exc}") from exc
    with os.fdopen(fd, "rb") as f:
        st = os.fstat(f.fileno())
        if not stat.S_ISREG(st.st_mode):
            raise InvalidInput(f"cannot copy {os.fspath(source)!r}: not a regular file")
        if st.st_size > max_bytes:
            raise InvalidInput(f"cannot copy {os.fspath(source)!r}: {st.st_size} bytes, above the limit of {max_bytes}")
        data = f.read(max_bytes + 1)
    if len(data) > max_bytes:
        raise InvalidInput(f"cannot copy {os.fspath(source)!r}: above the limit of {max_bytes} bytes")
    return write_new_file(folder, relative, data if transform is None else transform(data))


def publish_folder(out: str | os.PathLike, fill: Callable[[Path], None]) -> Path:
    """Fill a new temporary folder beside ``out`` with ``fill(tmp)``, then rename it to ``out``; return ``out``.

    ``out`` is taken through :func:`output_folder` (a link to a folder: that folder, the link kept).
    The new folder gets the umask's permissions. A failure leaves no half-written folder and
    ``out`` untouched; an existing ``out`` is replaced only once the new one is complete (and put
    back if the rename fails), and nothing of it is left beside ``out``.
    """
    real = output_folder(out)
    real.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{real.name}.", suffix=".partial", dir=real.parent))
    try:
        os.chmod(tmp, folder_mode())  # mkdtemp makes it 0700
        fill(tmp)
        old = None
        if real.exists():
            old = Path(tempfile.mkdtemp(prefix=f".{real.name}.", suffix=".old", dir=real.parent))
            os.rmdir(old)
            os.rename(real, old)
        try:
            os.rename(tmp, real)
        except OSError:
            if old is not None:
                os.rename(old, real)  # put the previous folder back
            raise
        if old is not None:
            shutil.rmtree(old, ignore_errors=True)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    return real


__all__ += ["folder_mode", "safe_file_name", "output_folder", "path_inside", "write_new_file", "copy_new_file",
            "publish_folder", "MAX_NAME_LENGTH"]


def atomic_write(path: str | os.PathLike, write: Callable[[BinaryIO], None]) -> Path:
    """Write ``path`` through ``write(fileobj)`` atomically; return the path.

    Leftover temporary files of earlier crashed saves of the same target are removed
    (see :func:`clean_leftovers`).

    Raises:
        InvalidInput: the target's folder does not exist or the target is a folder.
    """
    target = _target(path)
    folder = target.parent if str(target.parent) else Path(".")
    fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".part", dir=folder)
    try:
        with os.fdopen(fd, "wb") as f:
            if fcntl is not None:
                fcntl.flock(f.fileno(), fcntl.LOCK_EX)  # held until the file is closed: marks a live writer
            clean_leftovers(target, keep=os.path.basename(tmp))
            write(f)
            f.flush()
            os.fsync(f.fileno())
            os.chmod(tmp, _default_mode())
            os.replace(tmp, target)
    except BaseException:
        discard(tmp)
        raise
    return target


def write_text(path: str | os.PathLike, text: str) -> Path:
    """Write ``text`` (UTF-8, ``\n`` line ends) to ``path`` atomically (:func:`atomic_write`); return the path."""
    data = text.encode("utf-8")
    return atomic_write(path, lambda f: f.write(data))


# ----------------------------------------------------------------- reading: regular files only, size-bounded
def open_regular(path: str | os.PathLike, what: str = "file", *, error: type[Exception] = InvalidInput,
                 missing: type[Exception] | None = None) -> BinaryIO:
    """``path`` opened for binary reading, only when it is a regular file (links followed).

    The file is opened with ``O_NONBLOCK`` (a FIFO with no writer then opens at once instead of
    waiting) and checked with ``fstat`` on the open descriptor, so what is checked is what is read:
    a FIFO, a device (``/dev/zero``), a socket or a folder is refused before a byte is read.

    Raises:
        error: not a path, not a regular file, or unreadable (the message names ``what`` and the path).
        missing: the file does not exist (default: ``error``).
    """
    if not isinstance(path, (str, os.PathLike)):
        raise error(f"{what} must be given as a path, got {type(path).__name__}")
    name = os.fspath(path)
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0) | getattr(os, "O_NOCTTY", 0)
    try:
        fd = os.open(name, flags)
    except FileNotFoundError:
        raise (missing or error)(f"cannot read {what} {name!r}: it does not exist") from None
    except (OSError, ValueError) as exc:  # ValueError: a NUL byte in the path
        reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
        raise error(f"cannot read {what} {name!r}: {reason}") from None
    try:
        mode = os.fstat(fd).st_mode
        if not stat.S_ISREG(mode):
            raise error(f"{what} {name!r} is not a regular file ({_kind_of(mode)}): give the path of a file")
        if fcntl is not None:  # back to blocking reads for the caller
            fcntl.fcntl(fd, fcntl.F_SETFL, fcntl.fcntl(fd, fcntl.F_GETFL) & ~getattr(os, "O_NONBLOCK", 0))
        return os.fdopen(fd, "rb")
    except BaseException:
        os.close(fd)
        raise


def _kind_of(mode: int) -> str:
    """What a non-regular file is, in words."""
    for test, word in ((stat.S_ISDIR, "a folder"), (stat.S_ISFIFO, "a FIFO"), (stat.S_ISCHR, "a character device"),
                       (stat.S_ISBLK, "a block device"), (stat.S_ISSOCK, "a socket")):
        if test(mode):
            return word
    return "not a file"


def check_regular(path: str | os.PathLike, what: str = "file", *, error: type[Exception] = InvalidInput,
                  missing: type[Exception] | None = None, limit: int | None = None) -> int:
    """The size [bytes] of ``path`` after :func:`open_regular`'s checks, for a file another
    library or process opens by name (HDF5, xacro); ``error`` above ``limit`` bytes."""
    with open_regular(path, what, error=error, missing=missing) as fh:
        size = os.fstat(fh.fileno()).st_size
    if limit is not None and size > limit:
        raise error(f"{what} {os.fspath(path)!r} is {size} bytes; the limit is {limit} bytes")
    return size


def read_bounded(path: str | os.PathLike, limit: int, what: str = "file", *, error: type[Exception] = InvalidInput,
                 missing: type[Exception] | None = None, too_large: type[Exception] | None = None) -> bytes:
    """The bytes of the regular file ``path`` (:func:`open_regular`), at most ``limit`` of them:
    sized by ``fstat`` first, then read up to ``limit + 1`` bytes only (a file that grows while it
    is read is refused too). ``too_large`` (default ``error``) when over the limit."""
    with open_regular(path, what, error=error, missing=missing) as fh:
        size = os.fstat(fh.fileno()).st_size
        big = too_large or error
        if size > limit:
            raise big(f"{what} {os.fspath(path)!r} is {size} bytes; the limit is {limit} bytes "
                      f"(larger than that is refused unread)")
        try:
            data = fh.read(limit + 1)
        except OSError as exc:
            raise error(f"cannot read {what} {os.fspath(path)!r}: {exc.strerror or exc}") from None
    if len(data) > limit:
        raise big(f"{what} {os.fspath(path)!r} is larger than the limit of {limit} bytes")
    return data


def read_bounded_text(path: str | os.PathLike, limit: int, what: str = "file", *,
                      error: type[Exception] = InvalidInput, missing: type[Exception] | None = None,
                      too_large: type[Exception] | None = None) -> str:
    """:func:`read_bounded`, decoded as UTF-8 (a leading byte-order mark dropped); ``error`` when not UTF-8."""
    data = read_bounded(path, limit, what, error=error, missing=missing, too_large=too_large)
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise error(f"{what} {os.fspath(path)!r} is not UTF-8 text (byte {exc.start}): save it as UTF-8") from None


__all__ += ["open_regular", "check_regular", "read_bounded", "read_bounded_text"]
