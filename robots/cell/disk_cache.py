"""Where the cells' computed tables are kept on disk, keyed by content and by the code that built them.

The folder: ``$PINARMS_CACHE_DIR`` when set, else ``$XDG_CACHE_HOME/pinarms`` (an absolute
``XDG_CACHE_HOME``), else ``~/.cache/pinarms``; each kind of table in its own subfolder
(``pair_tables/``). Never the package folder: an installed package may be read-only or
shared, and a file planted beside the code must not be taken for a build of it.

A file is named by a SHA-256 digest of what it depends on **and** of the source files of the
modules that built it (:func:`code_digest`): an edit, a branch switch or an upgrade of those
files gives new names, so a stale table is never found. Files are ``.npz`` archives read with
``allow_pickle=False``, only up to :data:`MAX_FILE_BYTES`, and written atomically
(:func:`pinarms.files.atomic_write`: a temporary file, then a rename); the folder is created
``0700``. What a file holds is still checked by its reader (structure and values) before it
is used: a cache only saves time, a bad or doubtful file is rebuilt. Any error reading or
writing only costs the build.
"""

from __future__ import annotations

import hashlib
import io
import os
import stat
from collections.abc import Sequence
from functools import lru_cache
from pathlib import Path

import numpy as np

__all__ = ["CACHE_ENV", "MAX_FILE_BYTES", "cache_folder", "code_digest", "read_arrays", "write_arrays"]

#: Environment variable naming the cache folder (overrides ``XDG_CACHE_HOME`` and ``~/.cache``).
CACHE_ENV = "PINARMS_CACHE_DIR"
#: Largest cache file read [bytes].
MAX_FILE_BYTES = 64 * 1024 * 1024


def cache_folder(kind: str) -> Path:
    """The folder of the tables of ``kind`` (module docstring); not created here."""
    own = os.environ.get(CACHE_ENV, "")
    if own:
        return Path(own).expanduser() / kind
    xdg = os.environ.get("XDG_CACHE_HOME", "")
    base = Path(xdg) if xdg and os.path.isabs(xdg) else Path.home() / ".cache"
    return base / "pinarms" / kind


@lru_cache(maxsize=None)
def _digest_of(paths: tuple[str, ...]) -> str:
    h = hashlib.sha256()
    for p in paths:
        data = Path(p).read_bytes()
        h.update(len(data).to_bytes(8, "little") + data)
    return h.hexdigest()


def code_digest(modules: Sequence[str | os.PathLike]) -> str:
    """SHA-256 of the source files ``modules`` (read once per process)."""
    return _digest_of(tuple(str(Path(m).resolve()) for m in modules))


def read_arrays(path: Path, names: Sequence[str]) -> dict[str, np.ndarray] | None:
    """The arrays ``names`` of the ``.npz`` file ``path`` (no pickles, at most :data:`MAX_FILE_BYTES`); ``None``
    when absent, unreadable, too large, not a regular file or missing a name."""
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))  # a FIFO planted there never blocks
        with os.fdopen(fd, "rb") as fh:
            info = os.fstat(fh.fileno())
            if not stat.S_ISREG(info.st_mode) or info.st_size > MAX_FILE_BYTES:
                return None
            data = fh.read(MAX_FILE_BYTES + 1)
        if len(data) > MAX_FILE_BYTES:
            return None
        with np.load(io.BytesIO(data), allow_pickle=False) as z:
            return {k: np.array(z[k]) for k in names}
    except (OSError, KeyError, ValueError, EOFError):
        return None
    except Exception:  # zipfile.BadZipFile and the like from a damaged file: only the build is lost
        return None


def write_arrays(path: Path, arrays: dict[str, np.ndarray]) -> None:
    """Write ``arrays`` to ``path`` atomically (the folder made ``0700`` if new); errors are ignored."""
    from pinarms.files import atomic_write

    try:
        path.parent.mkdir(mode=0o700, parents=True, exist_ok=True)
        buf = io.BytesIO()
        np.savez(buf, **arrays)
        atomic_write(path, lambda f: f.write(buf.getvalue()))
    except OSError:
        pass
