"""Fuzzed reachability map files: seeded byte flips and truncations of a small valid map.

Every outcome is a map that passes the loader's checks or a ReachabilityFileError naming the
file, within the loader's time bound (a flip that makes libhdf5 spin is stopped by the
reader's timeout).
"""

from __future__ import annotations

import time

import numpy as np
import pytest

from fuzz_support import EXPLORE, assert_finite
from pinarms import robots
from pinarms.robots.reach.reach_io import DEFAULT_TIMEOUT, ReachabilityFileError, load_reachability, save_reachability
from pinarms.robots.reach.reachability import ReachabilityMap, reachability_map

N_FLIPS = 24 * EXPLORE  # anywhere in the file
N_HEAD_FLIPS = 10 * EXPLORE  # in the first 4 kB: superblock, object headers, B-trees, the global heap
N_CUTS = 6 * EXPLORE
#: the reader's start (imports) plus its inspection bound plus reading a 90 kB file, with room for a busy machine
BOUND_S = DEFAULT_TIMEOUT + 4.0


@pytest.fixture(scope="module")
def base(tmp_path_factory):
    m = reachability_map(robots.load("aubo_i3"), 0.2, 8)
    path = save_reachability(m, tmp_path_factory.mktemp("fuzz_maps") / "base.h5")
    return m, path.read_bytes()


def _cases() -> list[tuple[str, int, int]]:
    rng = np.random.default_rng(2029)
    size = 89_000  # about the base map's size; offsets are taken modulo the real size
    flips = [("flip", int(o), int(x)) for o, x in zip(rng.integers(0, size, N_FLIPS), rng.integers(1, 256, N_FLIPS))]
    head = [("flip", int(o), int(x)) for o, x in zip(rng.integers(0, 4096, N_HEAD_FLIPS),
                                                      rng.integers(1, 256, N_HEAD_FLIPS))]
    cuts = [("cut", int(o), 0) for o in rng.integers(1, size, N_CUTS)]
    return flips + head + cuts


@pytest.mark.parametrize("kind, offset, xor", _cases())
def test_a_damaged_map_loads_checked_or_is_refused_by_name_in_time(base, tmp_path, kind, offset, xor):
    m, data = base
    data = bytearray(data)
    offset %= len(data)
    if kind == "flip":
        data[offset] ^= xor
    else:
        del data[offset:]
    path = tmp_path / "damaged.h5"
    path.write_bytes(bytes(data))
    t0 = time.perf_counter()
    try:
        back = load_reachability(path)
    except ReachabilityFileError as exc:
        assert str(path) in str(exc)
        assert "is not a valid pinarms reachability map" in str(exc) or "upgrade pinarms" in str(exc)
        back = None
    seconds = time.perf_counter() - t0
    assert seconds < BOUND_S, f"{kind} at {offset}: {seconds:.1f} s"
    if back is not None:  # the flip hit bytes the checks cannot tell (free space, a text, padding): a valid map
        assert isinstance(back, ReachabilityMap) and back.shape == m.shape
        assert np.all((back.index >= 0) & (back.index <= 1))
        assert_finite(back.index, "index")
        assert back.n_reached == back.solutions.voxel.size
