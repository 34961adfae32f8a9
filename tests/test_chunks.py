"""Cutting a seeded sweep into chunks: each chunk's seed and each chunk's size."""

from __future__ import annotations

import numpy as np
import pytest

from pinarms import execution
from pinarms.chunks import chunk_seeds, split_count
from pinarms.errors import InvalidInput


def test_chunk_seeds_follow_the_seed_sequence_rule():
    seeds = chunk_seeds(2024, 3)
    child = np.random.SeedSequence(2024).spawn(3)[1]
    low, high = child.generate_state(2, dtype=np.uint64)
    assert seeds[1] == int(low) | (int(high) << 64)
    assert len(set(seeds)) == 3
    # chunk k's seed does not depend on how many chunks there are
    assert chunk_seeds(2024, 5)[:3] == seeds
    assert chunk_seeds(2025, 3) != seeds
    with pytest.raises(InvalidInput, match="seed"):
        chunk_seeds(-1, 3)
    with pytest.raises(InvalidInput, match="n_chunks"):
        chunk_seeds(1, 2.5)


def test_split_count():
    assert split_count(10, 4) == [4, 4, 2]
    assert split_count(8, 4) == [4, 4]
    assert split_count(0, 4) == []
    with pytest.raises(InvalidInput, match="chunk_size"):
        split_count(10, 0)


def test_the_execution_layer_names_the_same_functions():
    assert execution.chunk_seeds is chunk_seeds
    assert execution.split_count is split_count
