"""How a seeded sweep is cut into chunks: the seed of each chunk and the size of each chunk.

A sweep of the execution layer (:mod:`pinarms.execution`) is a list of tasks; a task carries
its chunk's seed (:func:`chunk_seeds`) and its share of the items (:func:`split_count`), so
its result depends only on its own arguments, whatever runs it and however many chunks
there are. Part of the floor: imports numpy at module level and the error classes
(``pinarms.errors``, which imports nothing of ours).
"""

from __future__ import annotations

import numpy as np

from pinarms.errors import InvalidInput

__all__ = ["chunk_seeds", "split_count"]

#: Bits of each chunk seed drawn from the chunk's SeedSequence (two 64-bit words).
SEED_BITS = 128


def chunk_seeds(seed: int, n_chunks: int) -> list[int]:
    """Independent seeds of ``n_chunks`` chunks of one seeded sweep.

    Rule: chunk ``k``'s seed is the 128-bit integer made of the first two 64-bit words of
    ``numpy.random.SeedSequence(seed).spawn(n_chunks)[k].generate_state(2, numpy.uint64)``
    (word 0 the low word). A spawned child depends only on ``seed`` and ``k``, so chunk ``k``
    has the same seed whatever the number of chunks; a task makes its generator with
    ``numpy.random.default_rng(chunk_seed)``.
    """
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise InvalidInput(f"seed must be a non-negative integer, got {seed!r}")
    if isinstance(n_chunks, bool) or not isinstance(n_chunks, (int, np.integer)) or n_chunks < 0:
        raise InvalidInput(f"n_chunks must be a non-negative integer, got {n_chunks!r}")
    children = np.random.SeedSequence(int(seed)).spawn(int(n_chunks))
    out = []
    for child in children:
        low, high = child.generate_state(2, dtype=np.uint64)
        out.append(int(low) | (int(high) << 64))
    return out


def split_count(n: int, chunk_size: int) -> list[int]:
    """Sizes of the chunks of ``n`` items, ``chunk_size`` each and the remainder last.

    ``split_count(10, 4) == [4, 4, 2]``; ``split_count(0, 4) == []``.
    """
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 0:
        raise InvalidInput(f"n must be a non-negative integer, got {n!r}")
    if isinstance(chunk_size, bool) or not isinstance(chunk_size, (int, np.integer)) or chunk_size < 1:
        raise InvalidInput(f"chunk_size must be a positive integer, got {chunk_size!r}")
    n, chunk_size = int(n), int(chunk_size)
    full, rest = divmod(n, chunk_size)
    return [chunk_size] * full + ([rest] if rest else [])
