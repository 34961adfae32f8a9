"""pinarms.compiled: caches of kernels that call across files are dropped when any of those files changes."""

from __future__ import annotations

from pathlib import Path

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


def _touch(paths: list[Path]) -> None:
    for p in paths:
        p.write_bytes(b"x")


def test_a_change_of_the_called_file_drops_the_callers_cache(tmp_path):
    low, high, caches, other = _kernels(tmp_path)
    mark = high.parent / "__pycache__" / "kernels.sha256"
    _touch(caches + [other])
    assert drop_stale_caches([low, high], mark)          # no digest yet: every cache goes
    assert not any(c.exists() for c in caches) and other.exists() and mark.is_file()
    _touch(caches)
    assert not drop_stale_caches([low, high], mark)      # same sources: kept
    assert all(c.exists() for c in caches)
    low.write_text("def f(x):\n    return 2 * x\n")     # the called file changed, the caller did not
    assert drop_stale_caches([low, high], mark)
    assert not any(c.exists() for c in caches) and other.exists()


def test_an_unreadable_source_leaves_everything_as_it_is(tmp_path):
    low, high, caches, _ = _kernels(tmp_path)
    _touch(caches)
    assert not drop_stale_caches([low, tmp_path / "missing.py"], tmp_path / "mark")
    assert all(c.exists() for c in caches)
