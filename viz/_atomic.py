"""Atomic file writes: :mod:`pinarms.files` (the floor every package may import), imported here for viz."""

from __future__ import annotations

from pinarms.files import STALE_AFTER_S, atomic_write, clean_leftovers

__all__ = ["atomic_write", "clean_leftovers", "STALE_AFTER_S"]
