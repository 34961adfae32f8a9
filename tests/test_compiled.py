"""pinarms.compiled: caches of kernels that call across files are dropped when any of those files changes."""

from __future__ import annotations

import os
from pathlib import Path

import numba

from pinarms import compiled
from pinarms.compiled import drop_stale_caches


def _kernels(tmp_path: Path) -> tuple[Path, Path, list[Path], Path]:
    """Two kernel files in two folders (as the cover in robots/cell and the search in optim/motion)."""
    low, high = tmp_path / "robots" / "_low.py", tmp_path / "optim" / "_high.py"
    caches = []
    for src in (low, high):
        src.parent.mkdir(parents=True)
        src.write_text("def f(x):\n    return x\n")
        (src.parent / "__pycache__").mkdir()
        caches += [src.parent / "__pycache__" / f"{src.stem}.f-1.py311.nbi",
                   src.parent / "__pycache__" / f"{src.stem}.f-1.py311.1.nbc"]
    other = high.parent / "__pycache__" / "_high.cpython-311.pyc"
    return low, high, caches, other


def _touch(paths: list[Path], before_start: bool = True) -> None:
    """Write the files; by default dated before this process started (caches of an earlier process)."""
    for p in paths:
        p.write_bytes(b"x")
        if before_start:
            os.utime(p, (compiled.STARTED - 60.0, compiled.STARTED - 60.0))


def test_a_change_of_the_called_file_drops_the_callers_cache(tmp_path):
    low, high, caches, other = _kernels(tmp_path)
    mark = "kernels.sha256"
    _touch(caches + [other])
    assert drop_stale_caches([low, high], mark)          # no digest yet: every cache goes
    assert not any(c.exists() for c in caches) and other.exists()
    assert (high.parent / "__pycache__" / mark).is_file()
    _touch(caches)
    assert not drop_stale_caches([low, high], mark)      # same sources: kept
    assert all(c.exists() for c in caches)
    low.write_text("def f(x):\n    return 2 * x\n")     # the called file changed, the caller did not
    assert drop_stale_caches([low, high], mark)
    assert not any(c.exists() for c in caches) and other.exists()


def test_a_new_guard_keeps_the_caches_this_process_just_wrote(tmp_path):
    """Guards over overlapping files, imported one after the other on a fresh install: the second
    one's first digest must not delete what the kernels imported before it compiled in this process
    (it did: every later process compiled the cover's kernels again)."""
    low, high, caches, _ = _kernels(tmp_path)
    assert drop_stale_caches([low], "low.sha256")        # the cover's guard, then its kernels compile
    _touch(caches[:2], before_start=False)
    assert drop_stale_caches([low, high], "high.sha256")  # the search's guard, imported later: a new digest
    assert all(c.exists() for c in caches[:2])


def test_the_guard_drops_caches_where_numba_keeps_them(tmp_path, monkeypatch):
    """With NUMBA_CACHE_DIR set, numba caches there and not beside the source: the guard looks there."""
    low, high, _, _ = _kernels(tmp_path)
    monkeypatch.setattr(numba.config, "CACHE_DIR", str(tmp_path / "numba-cache"))
    folder = compiled.cache_folder(low)
    assert folder.is_relative_to(tmp_path / "numba-cache")
    stale = [folder / "_low.f-1.py311.nbi", folder / "_low.f-1.py311.1.nbc"]
    _touch(stale)
    assert drop_stale_caches([low, high], "kernels.sha256")
    assert not any(c.exists() for c in stale)
    assert (compiled.cache_folder(high) / "kernels.sha256").is_file()


def test_an_unreadable_source_leaves_everything_as_it_is(tmp_path):
    low, high, caches, _ = _kernels(tmp_path)
    _touch(caches)
    assert not drop_stale_caches([low, tmp_path / "missing.py"], "mark")
    assert all(c.exists() for c in caches)
