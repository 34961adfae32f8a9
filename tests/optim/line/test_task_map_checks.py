"""Task maps checked when made and when read: grids, times, sizes before inflating, a checksum.

Issue 35 (item 11): negative, NaN-gridded, one-node and decreasing maps were accepted (a
decreasing grid picked 0 of 80 items without a word, a one-node grid failed later in
``simulate`` with an IndexError), a 2 MB deflate bomb cost 2.26 GB and 26 s, a truncated file
raised a raw BadZipFile, and a narrow pick window lost items to rounding.
"""

import io
import time
import tracemalloc
import zipfile

import numpy as np
import pytest

from pinarms.optim.line.belt import Belt
from pinarms.optim.line.errors import TaskMapError
from pinarms.optim.line.items import regular_items
from pinarms.optim.line.simulate import SimArm, simulate
from pinarms.optim.line.task_maps import MAX_MAP_VALUES, TaskMap

BELT = Belt((0.0, 0.0, 0.8), speed=0.2, width=0.3, length=4.0)
DU = np.array([0.0, 0.1, 0.2])
W = np.array([-0.15, 0.15])


def _map(du=DU, w=W, approach=None, leave=None, track=0.5, release=0.1, speed=0.2, mass=0.1, **kw):
    a = np.full((np.size(du), np.size(w)), 0.3) if approach is None else approach
    c = np.full((np.size(du), np.size(w)), 0.3) if leave is None else leave
    return TaskMap("a", np.asarray(du, float), np.asarray(w, float), a, c, track, release, speed, mass, **kw)


@pytest.mark.parametrize("du, what", [
    ([0.0], "at least 2"),
    ([0.1, 0.1], "strictly increasing"),
    ([0.2, 0.1, 0.0], "strictly increasing"),
    ([0.0, np.nan, 0.2], "finite"),
    ([0.0, 0.1, np.inf], "finite"),
    ([0.0, 0.2, 0.1], "strictly increasing"),
])
def test_a_bad_du_grid_is_refused(du, what):
    with pytest.raises(TaskMapError, match=f"'a'.*du.*{what}"):
        _map(du=du)


def test_a_bad_w_grid_is_refused():
    with pytest.raises(TaskMapError, match="w .*strictly increasing"):
        _map(w=[0.1, 0.1])
    with pytest.raises(TaskMapError, match="w .*at least 2"):
        _map(w=np.zeros(1))


@pytest.mark.parametrize("value, what", [(-0.1, "approach"), (1e300, "approach"), (np.inf, "approach")])
def test_bad_times_are_refused(value, what):
    a = np.full((3, 2), 0.3)
    a[1, 0] = value
    with pytest.raises(TaskMapError, match=f"{what}.*node \\(1, 0\\)"):
        _map(approach=a)
    with pytest.raises(TaskMapError, match="leave"):
        _map(leave=a)


def test_nan_marks_an_infeasible_node_and_stays_allowed():
    a = np.full((3, 2), 0.3)
    a[0, 0] = np.nan
    m = _map(approach=a)
    assert np.isnan(m.times(0.01, -0.14)[0]) and m.times(0.15, 0.0)[0] == pytest.approx(0.3)


@pytest.mark.parametrize("field, value", [("track", np.inf), ("track", -1.0), ("release", np.nan), ("speed", -0.2),
                                          ("speed", 0.0), ("mass", -0.1), ("mass", np.inf)])
def test_bad_scalars_are_refused(field, value):
    with pytest.raises(TaskMapError, match=field):
        _map(**{field: value})


def test_a_one_node_grid_no_longer_fails_later_in_simulate():
    with pytest.raises(TaskMapError, match="at least 2"):
        SimArm("a", 1.0, (_map(du=[0.1], approach=np.full((1, 2), 0.3), leave=np.full((1, 2), 0.3)),))


def test_a_grid_past_the_cap_is_refused_before_any_table_is_made():
    n = int(np.sqrt(MAX_MAP_VALUES)) + 2
    with pytest.raises(TaskMapError, match="at most"):
        _map(du=np.arange(n, dtype=float), w=np.arange(n, dtype=float), approach=np.zeros((1, 1)))


def test_a_narrow_pick_window_is_simulated_exactly():
    """A window a nanometre wide: each item is reachable at one instant; every one is picked."""
    items = regular_items(BELT, 5.0, 400.0, w=0.0)
    for width in (1e-12, 1e-9, 0.05):
        m = _map(du=[0.5, 0.5 + width], approach=np.full((2, 2), 0.3), leave=np.full((2, 2), 0.3))
        r = simulate([SimArm("a", 1.0, (m,))], items, 0.2)
        assert r.picks == len(items) == 80, width
        assert np.allclose(r.u_meet, 1.5, atol=1e-6)


def test_save_and_load_keep_every_value_and_the_checksum(tmp_path):
    m = _map(approach=np.array([[0.3, np.nan], [0.4, 0.5], [0.6, 0.7]]))
    back = TaskMap.load(m.save(tmp_path / "m.npz"))
    assert np.array_equal(back.approach, m.approach, equal_nan=True) and back.track == 0.5
    assert back.checksum == m.checksum and len(m.checksum) == 64


def _saved(tmp_path):
    return _map().save(tmp_path / "m.npz")


def test_a_flipped_byte_is_refused(tmp_path):
    """A byte flipped in a stored value: the zip's CRC or the map's checksum finds it."""
    p = _saved(tmp_path)
    data = bytearray(p.read_bytes())
    k = data.index(np.float64(0.3).tobytes())  # the first approach time, stored uncompressed
    data[k] ^= 0x01
    p.write_bytes(bytes(data))
    with pytest.raises(TaskMapError, match="not a task map file|checksum"):
        TaskMap.load(p)


def test_a_value_changed_in_a_rewritten_archive_is_found_by_the_checksum(tmp_path):
    """Rewritten with valid zip CRCs (as numpy or any zip tool writes it), a changed time still
    fails the map's own checksum."""
    p = _saved(tmp_path)
    with zipfile.ZipFile(p) as z:
        members = {n: z.read(n) for n in z.namelist()}
    raw = members["approach.npy"]
    k = raw.index(np.float64(0.3).tobytes())
    members["approach.npy"] = raw[:k] + np.float64(0.2999).tobytes() + raw[k + 8:]
    with zipfile.ZipFile(p, "w") as z:
        for n, b in members.items():
            z.writestr(n, b)
    with pytest.raises(TaskMapError, match="do not match its checksum"):
        TaskMap.load(p)
    with zipfile.ZipFile(p, "w") as z:  # no checksum at all
        for n, b in members.items():
            if n != "checksum.npy":
                z.writestr(n, b)
    with pytest.raises(TaskMapError, match="has no checksum"):
        TaskMap.load(p)


def test_a_truncated_or_foreign_file_is_a_named_error(tmp_path):
    p = _saved(tmp_path)
    data = p.read_bytes()
    for bad in (data[: len(data) // 2], b"not a zip", b""):
        p.write_bytes(bad)
        with pytest.raises(TaskMapError, match="not a task map file"):
            TaskMap.load(p)


@pytest.fixture(scope="module")
def bomb(tmp_path_factory):
    """A task map file whose approach member inflates to 256 MiB of zeros from about 250 kB."""
    p = _map().save(tmp_path_factory.mktemp("bomb") / "m.npz")
    with zipfile.ZipFile(p) as z:
        members = {n: z.read(n) for n in z.namelist() if n != "approach.npy"}
    big = np.zeros((2**14, 2**11))
    header = io.BytesIO()
    np.lib.format.write_array_header_1_0(header, np.lib.format.header_data_from_array_1_0(big))
    with zipfile.ZipFile(p, "w", zipfile.ZIP_DEFLATED) as z:
        for n, b in members.items():
            z.writestr(n, b)
        with z.open("approach.npy", "w", force_zip64=True) as f:
            f.write(header.getvalue())
            for _ in range(big.nbytes // 2**24):
                f.write(bytes(2**24))
    return p


def test_a_deflate_bomb_is_refused_before_inflating(bomb):
    assert bomb.stat().st_size < 2e6
    tracemalloc.start()
    t0 = time.perf_counter()
    try:
        with pytest.raises(TaskMapError, match=r"approach.npy.* declares 268435584 bytes"):
            TaskMap.load(bomb)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert time.perf_counter() - t0 < 1.0 and peak < 50e6, peak


def test_a_member_that_inflates_past_its_declared_size_is_refused(tmp_path):
    """A member whose declared size is small but whose deflate stream holds more: read up to the
    declared size only, then refused (its CRC cannot match)."""
    p = _saved(tmp_path)
    with zipfile.ZipFile(p) as z:
        members = {n: z.read(n) for n in z.namelist()}
    honest = members["leave.npy"]
    with zipfile.ZipFile(p, "w", zipfile.ZIP_DEFLATED) as z:
        for n, b in members.items():
            if n != "leave.npy":
                z.writestr(n, b)
        z.writestr("leave.npy", honest + bytes(2**22))
    data = bytearray(p.read_bytes())
    declared = (len(honest) + 2**22).to_bytes(4, "little")
    for k in range(len(data) - 4):  # the local header and the directory both say the real size: lie in both
        if data[k: k + 4] == declared:
            data[k: k + 4] = len(honest).to_bytes(4, "little")
    p.write_bytes(bytes(data))
    with pytest.raises(TaskMapError, match="not a task map file"):
        TaskMap.load(p)
