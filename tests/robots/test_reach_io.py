"""Reachability map files: exact round trip, and hostile or truncated files give ReachabilityFileError."""

from __future__ import annotations

import shutil

import h5py
import numpy as np
import pytest

from pinarms import robots
from pinarms.robots.errors import InvalidInput
from pinarms.robots.reach_io import ReachabilityFileError, load_reachability, save_reachability
from pinarms.robots.reachability import reachability_map


@pytest.fixture(scope="module")
def small_map():
    return reachability_map(robots.load("aubo_i3"), 0.2, 8)


@pytest.fixture
def saved(small_map, tmp_path):
    return save_reachability(small_map, tmp_path / "aubo.h5")


def test_round_trip_is_exact(small_map, saved, tmp_path):
    back = load_reachability(saved)
    assert back.identical(small_map)
    assert back.solutions is not None and len(back.solutions) == small_map.n_reached
    light = load_reachability(saved, solutions=False)
    assert light.solutions is None and np.array_equal(light.reached, small_map.reached)
    down = reachability_map(robots.load("scara_mushroom"), 0.15, 3, tool_down=0.2, keep_solutions=False)
    assert load_reachability(down.save(tmp_path / "scara.h5")).identical(down)


def test_save_is_atomic_and_checks_its_target(small_map, tmp_path):
    target = tmp_path / "m.h5"
    target.write_bytes(b"old")
    with pytest.raises(InvalidInput, match="does not exist"):
        save_reachability(small_map, tmp_path / "missing" / "m.h5")
    with pytest.raises(InvalidInput, match="folder"):
        save_reachability(small_map, tmp_path)
    save_reachability(small_map, target)
    assert not list(tmp_path.glob(".m.h5.*.part"))
    assert load_reachability(target).identical(small_map)


@pytest.mark.parametrize("fraction", [0.0, 0.01, 0.3, 0.6, 0.99])
def test_truncated_files_are_refused(saved, tmp_path, fraction):
    data = saved.read_bytes()
    cut = tmp_path / "cut.h5"
    cut.write_bytes(data[: int(len(data) * fraction)])
    with pytest.raises(ReachabilityFileError, match="not a valid pinarms reachability map"):
        load_reachability(cut)


def test_a_text_file_and_a_missing_file(tmp_path):
    text = tmp_path / "map.h5"
    text.write_text("<robot/>")
    with pytest.raises(ReachabilityFileError, match="not an HDF5 file"):
        load_reachability(text)
    with pytest.raises(InvalidInput, match="does not exist"):
        load_reachability(tmp_path / "nothing.h5")


def _edit(saved, tmp_path, edit):
    path = tmp_path / "edited.h5"
    shutil.copy(saved, path)
    with h5py.File(path, "r+") as h5:
        edit(h5, tmp_path)
    return path


def _replace(name, data):
    def edit(h5, _):
        del h5[name]
        h5.create_dataset(name, data=data)
    return edit


def _external_link(h5, folder):
    with h5py.File(folder / "other.h5", "w") as other:
        other.create_dataset("flat", data=h5["voxels/flat"][()])
    del h5["voxels/flat"]
    h5["voxels/flat"] = h5py.ExternalLink(str(folder / "other.h5"), "/flat")


def _external_storage(h5, folder):
    flat = h5["voxels/flat"][()]
    raw = folder / "raw.bin"
    raw.write_bytes(flat.astype("<i8").tobytes())
    del h5["voxels/flat"]
    h5.create_dataset("voxels/flat", shape=flat.shape, dtype="<i8", external=[(str(raw), 0, flat.nbytes)])


def _soft_link(h5, _):
    h5["voxels/copy"] = h5["voxels/index"][()]
    del h5["voxels/index"]
    h5["voxels/index"] = h5py.SoftLink("/voxels/copy")


def _set_attr(key, value):
    def edit(h5, _):
        h5.attrs[key] = value
    return edit


def _scale_rotation(h5, _):
    r = h5["orientations/rotations"][()]
    r[0] *= 1.5
    _replace("orientations/rotations", r)(h5, _)


def _flip_bit(h5, _):
    reached = h5["voxels/reached"][()]
    row = int(np.flatnonzero(reached.any(axis=1))[0])
    k = int(np.flatnonzero(reached[row])[0])
    reached[row, k] = 0
    _replace("voxels/reached", reached)(h5, _)


def _q_outside(h5, _):
    q = h5["poses/q"][()]
    q[0, 0] = 10.0
    _replace("poses/q", q)(h5, _)


def _nan_origin(h5, _):
    _replace("grid/origin", np.array([np.nan, 0.0, 0.0]))(h5, _)


def _wrong_width(h5, _):
    _replace("voxels/reached", h5["voxels/reached"][:, :-1])(h5, _)


def _float_flat(h5, _):
    _replace("voxels/flat", h5["voxels/flat"][()].astype(float))(h5, _)


def _unsorted(h5, _):
    _replace("voxels/flat", h5["voxels/flat"][()][::-1].copy())(h5, _)


def _missing(h5, _):
    del h5["voxels/index"]


def _pose_of_unreached(h5, _):
    o = h5["poses/orientation"][()]
    o[0] = (o[0] + 1) % h5["orientations/rotations"].shape[0]
    _replace("poses/orientation", o)(h5, _)


@pytest.mark.parametrize(
    "edit, match",
    [
        (_set_attr("format", "pinarms-session"), "format is 'pinarms-session'"),
        (_set_attr("version", 99), "upgrade pinarms"),
        (_set_attr("resolution", -1.0), "resolution"),
        (_set_attr("solver", "oracle"), "solver"),
        (_set_attr("parameters", "{not json"), "not valid JSON"),
        (_set_attr("shape", np.array([100000, 100000, 100000])), "more than"),
        (_external_link, "ExternalLink"),
        (_external_storage, "external files"),
        (_soft_link, "SoftLink"),
        (_missing, "/voxels/index is missing"),
        (_float_flat, "dtype float64, expected int64"),
        (_wrong_width, "shape"),
        (_unsorted, "strictly increasing"),
        (_nan_origin, "NaN"),
        (_scale_rotation, "not a proper rotation"),
        (_flip_bit, "does not follow from /voxels/reached|solutions for the 837 reached poses"),
        (_q_outside, "outside the joint limits"),
        (_pose_of_unreached, "marked unreached|exactly one solution"),
    ],
)
def test_hostile_edits_are_named(saved, tmp_path, edit, match):
    path = _edit(saved, tmp_path, edit)
    with pytest.raises(ReachabilityFileError, match=match):
        load_reachability(path)


def test_arrays_larger_than_the_memory_budget_are_refused_before_reading(saved, tmp_path):
    with pytest.raises(ReachabilityFileError, match="max_bytes"):
        load_reachability(saved, max_bytes=2000)

    def bomb(h5, _):  # 16 GB declared, a few kB on disk (chunks never written)
        del h5["voxels/flat"]
        h5.create_dataset("voxels/flat", shape=(2 * 10**9,), dtype="<i8", chunks=(10**6,), compression="gzip")

    with pytest.raises(ReachabilityFileError, match="MB in memory"):
        load_reachability(_edit(saved, tmp_path, bomb))


def test_an_unknown_filter_is_refused(saved, tmp_path):
    def scaleoffset(h5, _):
        data = h5["voxels/index"][()]
        del h5["voxels/index"]
        h5.create_dataset("voxels/index", data=data, scaleoffset=4, chunks=True)

    with pytest.raises(ReachabilityFileError, match="filter"):
        load_reachability(_edit(saved, tmp_path, scaleoffset))


def test_a_streamed_map_file_equals_the_map_built_in_memory(small_map, tmp_path):
    streamed = reachability_map(robots.load("aubo_i3"), 0.2, 8, out=tmp_path / "streamed.h5")
    assert streamed.solutions is None
    assert load_reachability(tmp_path / "streamed.h5").identical(small_map)


class _Raises:
    def in_collision(self, q):
        raise RuntimeError("collision checker broke")


def test_a_failing_chunk_leaves_no_file(tmp_path):
    from pinarms.robots.errors import ExecutionError

    with pytest.raises(ExecutionError, match="chunk 0.*collision checker broke"):
        reachability_map(robots.load("aubo_i3"), 0.2, 8, collision=_Raises(), out=tmp_path / "broken.h5")
    assert list(tmp_path.iterdir()) == []
