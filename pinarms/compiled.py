"""Compiled kernels (numba): the one ``jit`` decorator of the project and the guard against stale caches.

Every kernel is compiled with ``nogil`` (threads run it in parallel) and cached on disk beside
its source (or in numba's user cache folder when that is read-only; without any writable
cache location it is compiled in each process).

numba keys a cached function on its *own* file only: a kernel calling (or inlining) functions
of another file keeps their old compiled code after that file changes — an edit, a branch
switch, an upgrade — and would run it. :func:`drop_stale_caches` is called by each module
whose kernels call across files, with the list of those files: a digest of their sources,
kept beside the caches, tells when the caches of all of them must be compiled again.
"""

from __future__ import annotations

import hashlib
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from numba import njit

from pinarms.files import write_text

__all__ = ["jit", "jit_inline", "drop_stale_caches"]


def jit(function: Callable[..., Any]) -> Callable[..., Any]:
    """``numba.njit`` with ``nogil``, cached on disk (see the module docstring)."""
    try:
        return njit(cache=True, nogil=True)(function)
    except RuntimeError:  # numba: "cannot cache function ...: no locator available"
        return njit(nogil=True)(function)


def jit_inline(function: Callable[..., Any]) -> Callable[..., Any]:
    """:func:`jit` inlined into its callers by numba (no call, no reference counting of its array arguments)."""
    try:
        return njit(cache=True, nogil=True, inline="always")(function)
    except RuntimeError:
        return njit(nogil=True, inline="always")(function)


def drop_stale_caches(sources: Sequence[str | Path], mark: str | Path) -> bool:
    """Delete numba's on-disk caches of every file of ``sources`` when any of them changed since
    the digest kept in ``mark`` (a file); return whether caches were dropped.

    The caches are the ``<stem>.*.nbi`` / ``.nbc`` files in each source's ``__pycache__``.
    Nothing happens where the cache folder cannot be read or written (an installed, read-only
    package is compiled in numba's own cache folder, keyed on the installed files).
    """
    paths = [Path(s) for s in sources]
    mark = Path(mark)
    try:
        digest = hashlib.sha256(b"".join(p.read_bytes() for p in paths)).hexdigest()
        if mark.is_file() and mark.read_text(encoding="utf-8") == digest:
            return False
        for p in paths:
            for stale in (p.parent / "__pycache__").glob(p.stem + ".*.nb[ic]"):
                stale.unlink()
        mark.parent.mkdir(exist_ok=True)
        write_text(mark, digest)
    except OSError:
        return False
    return True
