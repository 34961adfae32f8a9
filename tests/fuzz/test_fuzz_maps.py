"""Fuzzed reachability map files: seeded byte flips and truncations of a small valid map.

Every outcome is a map that passes the loader's checks or a ReachabilityFileError naming the
file, within the loader's time bound (a flip that makes libhdf5 spin is stopped by the
reader's timeout).
"""

from __future__ import annotations

import time

import numpy as np
import pytest

from fuzz_support import EXPLORE, assert_finite, damaged_file
from pinarms import robots
from pinarms.robots.reach.reach_io import DEFAULT_TIMEOUT, ReachabilityFileError, load_reachability, save_reachability
from pinarms.robots.reach.reachability import ReachabilityMap, ReachabilityRequest, reachability_map

N_FLIPS = 24 * EXPLORE  # anywhere in the file
N_HEAD_FLIPS = 10 * EXPLORE  # in the first 4 kB: superblock, object headers, B-trees, the global heap
N_CUTS = 6 * EXPLORE
#: the reader's start (imports) plus its inspection bound plus reading a 90 kB file, with room for a busy machine
BOUND_S = DEFAULT_TIMEOUT + 4.0


@pytest.fixture(scope="module")
def base(tmp_path_factory):
    m = reachability_map(ReachabilityRequest(robots.load("aubo_i3"), 0.2, 8))
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
    path = damaged_file(tmp_path, "damaged.h5", data, kind, offset, xor)
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


def test_a_flipped_value_byte_is_refused_by_the_checksum(base, tmp_path):
    """Small datasets are stored uncompressed and unchecked by HDF5: one flipped bit of
    ``best_manipulability`` once changed the map silently (issue 35)."""
    m, data = base
    value = m.best_manipulability[np.isfinite(m.best_manipulability)][0]
    k = data.find(np.float64(value).tobytes())
    assert k >= 0
    damaged = bytearray(data)
    damaged[k] ^= 0x01  # the lowest bit of the mantissa: still a valid, plausible value
    path = tmp_path / "flipped.h5"
    path.write_bytes(bytes(damaged))
    with pytest.raises(ReachabilityFileError, match="do not match the checksum"):
        load_reachability(path)


def test_a_value_rewritten_through_hdf5_is_refused_and_the_poses_too(base, tmp_path):
    import h5py

    m, data = base
    for member in ("voxels/best_manipulability", "poses/manipulability"):
        path = tmp_path / "edited.h5"
        path.write_bytes(data)
        with h5py.File(path, "r+") as h5:
            values = h5[member][...]
            values[np.isfinite(values)] *= 1.5
            h5[member][...] = values
        with pytest.raises(ReachabilityFileError, match="checksum"):
            load_reachability(path)
    back = load_reachability(path, solutions=False)  # the map's own values are intact
    assert np.array_equal(back.index, m.index)


@pytest.mark.parametrize("key, value, match", [
    ("resolution", 1e300, "resolution must be a length from"),
    ("resolution", 1e-9, "resolution must be a length from"),
    ("checksum", None, "holds no checksum"),
])
def test_attributes_out_of_bounds_are_refused(base, tmp_path, key, value, match):
    import h5py

    _, data = base
    path = tmp_path / "attr.h5"
    path.write_bytes(data)
    with h5py.File(path, "r+") as h5:
        if value is None:
            del h5.attrs[key]
        else:
            h5.attrs[key] = value
    with pytest.raises(ReachabilityFileError, match=match):
        load_reachability(path)


def test_seed_samples_are_capped_before_any_is_drawn():
    from pinarms.errors import InvalidInput

    t0 = time.perf_counter()
    with pytest.raises(InvalidInput, match="samples = 1,000,000,000,000 is more than"):
        reachability_map(ReachabilityRequest(robots.load("aubo_i3"), 0.2, 8, samples=10**12))
    assert time.perf_counter() - t0 < 5.0
