"""Compiled kernels (numba): the one ``jit`` decorator of the project and the guard against stale caches.

Every kernel is compiled with ``nogil`` (threads run it in parallel) and cached on disk beside
its source (or in numba's user cache folder when that is read-only; without any writable
cache location it is compiled in each process).

numba keys a cached function on its *own* file only: a kernel calling (or inlining) functions
of another file keeps their old compiled code after that file changes — an edit, a branch
switch, an upgrade — and would run it. :func:`drop_stale_caches` is called by each module
whose kernels call across files, with the list of those files: a digest of their sources,
kept beside the caches, tells when the caches of all of them must be compiled again.

The guard looks where numba itself keeps a file's caches (the first of numba's cache locators that
applies: ``NUMBA_CACHE_DIR`` when set, the ``__pycache__`` beside the source when writable, the
user-wide cache folder otherwise). It never drops a cache written since this process started: that
one was compiled from the sources this process runs. (Several modules guard overlapping sets of
files and are imported one after the other: the first import of a guard with no digest yet would
otherwise delete the caches that the kernels imported before it had just built, and the next
process would compile them all again.)
"""

from __future__ import annotations

import hashlib
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from numba import njit
from numba.core import caching

import pinarms.compile_notice as compile_notice
from pinarms.files import write_text

__all__ = ["jit", "jit_inline", "drop_stale_caches", "cache_folder", "STARTED"]


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


#: [s since the epoch] when this process imported the guard: caches written since were compiled here
STARTED = time.time()


def _locate() -> None:
    """A stand-in kernel: numba's locators take a function of the source file (they read only its first line)."""


def _locator_classes() -> list[Any]:
    """numba's cache locators, in the order numba tries them (``CacheImpl``; ``_CacheImpl`` before 0.61)."""
    impl = getattr(caching, "CacheImpl", None) or getattr(caching, "_CacheImpl", None)
    return list(getattr(impl, "_locator_classes", ()))


def cache_folder(source: str | Path) -> Path:
    """The folder where numba keeps the caches of the kernels of ``source`` (numba's first locator
    that applies; the ``__pycache__`` beside it when numba's locators cannot be asked)."""
    source = Path(source)
    for locator_class in _locator_classes():
        try:
            locator = locator_class.from_function(_locate, str(source))
        except Exception:  # a locator of numba's own kind (IPython, zip) that does not apply here
            continue
        if locator is not None:
            return Path(locator.get_cache_path())
    return source.parent / "__pycache__"


def drop_stale_caches(sources: Sequence[str | Path], mark: str | Path) -> bool:
    """Delete numba's on-disk caches of every file of ``sources`` when any of them changed since
    the digest kept in the file named ``mark`` (its name, in the cache folder of the last source);
    return whether the digest was new.

    The caches are the ``<stem>.*.nbi`` / ``.nbc`` files in each source's :func:`cache_folder`;
    those written since this process started (:data:`STARTED`) are kept (see the module docstring).
    Nothing happens where the cache folder cannot be read or written.
    """
    paths = [Path(s) for s in sources]
    try:
        mark = cache_folder(paths[-1]) / Path(mark).name
        digest = hashlib.sha256(b"".join(p.read_bytes() for p in paths)).hexdigest()
        if mark.is_file() and mark.read_text(encoding="utf-8") == digest:
            return False
        for p in paths:
            for stale in cache_folder(p).glob(p.stem + ".*.nb[ic]"):
                if stale.stat().st_mtime < STARTED:
                    stale.unlink()
        mark.parent.mkdir(parents=True, exist_ok=True)
        write_text(mark, digest)
    except OSError:
        return False
    return True


compile_notice.attach()  # a progress line started by the command line before numba was imported
