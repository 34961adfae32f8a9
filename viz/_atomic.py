"""Atomic file writes: a temporary file in the target's folder, then ``os.replace``.

A crash or an exception while writing never leaves a partial file at the target path (an
existing file there stays untouched until the new one is complete).
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path
from typing import BinaryIO, Callable

from pinarms.robots.errors import InvalidInput

__all__ = ["atomic_write"]


def _default_mode() -> int:
    """Permissions a plain ``open(path, "w")`` would give (0o666 minus the umask)."""
    umask = os.umask(0)
    os.umask(umask)
    return 0o666 & ~umask


def atomic_write(path: str | os.PathLike, write: Callable[[BinaryIO], None]) -> Path:
    """Write ``path`` through ``write(fileobj)`` atomically; return the path.

    Raises:
        InvalidInput: the target's folder does not exist or the target is a folder.
    """
    target = Path(path)
    folder = target.parent if str(target.parent) else Path(".")
    if not folder.is_dir():
        raise InvalidInput(f"cannot write {str(target)!r}: folder {str(folder)!r} does not exist; create it first")
    if target.is_dir():
        raise InvalidInput(f"cannot write {str(target)!r}: it is a folder; give a file name")
    fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".part", dir=folder)
    try:
        with os.fdopen(fd, "wb") as f:
            write(f)
            f.flush()
            os.fsync(f.fileno())
        os.chmod(tmp, _default_mode())
        os.replace(tmp, target)
    except BaseException:
        try:
            os.unlink(tmp)
        except FileNotFoundError:
            pass
        raise
    return target
