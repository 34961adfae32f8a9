"""Fuzzed line files: seeded byte flips and cuts of a task map file, seeded edits of an arrivals list.

Every outcome is a map (or items) that passes the checks, or the file type's named error
(TaskMapError, ArrivalsFileError) naming the file, within a second.
"""

from __future__ import annotations

import numpy as np
import pytest

from fuzz_support import EXPLORE, damaged_file, time_bound
from pinarms.optim.line.belt import Belt
from pinarms.optim.line.errors import ArrivalsFileError, TaskMapError
from pinarms.optim.line.items import ItemType, read_arrivals
from pinarms.optim.line.task_maps import TaskMap
from pinarms.errors import InvalidInput

BELT = Belt((0.0, 0.0, 0.8), speed=0.2, width=0.3, length=4.0)
TYPES = (ItemType("enoki", 0.15, (0.10, 0.06, 0.04)), ItemType("bunch", 0.2, (0.10, 0.08, 0.05)))
N_FLIPS, N_CUTS, N_EDITS = 30 * EXPLORE, 8 * EXPLORE, 40 * EXPLORE


@pytest.fixture(scope="module")
def map_bytes(tmp_path_factory):
    du, w = np.linspace(0.0, 0.3, 6), np.linspace(-0.12, 0.12, 3)
    a = 0.3 + 0.1 * np.add.outer(du, w)
    a[0, 0] = np.nan
    m = TaskMap("fuzz", du, w, a, a + 0.2, 0.5, 0.1, 0.2, 0.1, branches=(0, 1),
                branch_approach=np.stack([a, a + 0.3]), branch_leave=np.stack([a + 0.2, a + 0.1]))
    return m, m.save(tmp_path_factory.mktemp("line_fuzz") / "m.npz").read_bytes()


def _map_cases():
    rng = np.random.default_rng(2035)
    size = 4000  # about the base file's size; offsets taken modulo the real size
    return ([("flip", int(o), int(x)) for o, x in zip(rng.integers(0, size, N_FLIPS), rng.integers(1, 256, N_FLIPS))]
            + [("cut", int(o), 0) for o in rng.integers(0, size, N_CUTS)])


@pytest.mark.parametrize("kind, offset, xor", _map_cases())
def test_a_damaged_task_map_loads_checked_or_is_refused_by_name(map_bytes, tmp_path, kind, offset, xor):
    m, data = map_bytes
    path = damaged_file(tmp_path, "damaged.npz", data, kind, offset, xor)
    with time_bound(1.0):
        try:
            back = TaskMap.load(path)
        except TaskMapError as exc:
            assert str(path) in str(exc)
            return
    # the flip hit bytes no value depends on (a name's padding, a header's spaces): the same values
    assert back.checksum == m.checksum
    assert np.array_equal(back.approach, m.approach, equal_nan=True)


GOOD = "time,across,type,yaw\n0.5,0.01,enoki,0.1\n1.0,-0.02,bunch,0\n1.5,0.0,enoki,-0.3\n"
PIECES = ["", ",", "\n", "\r", '"', "\ufeff", "\x00", "nan", "inf", "-1", "1e308", "time", "yaw", "tulip", " ",
          "9" * 400, "x" * 140_000]


def _edits():
    rng = np.random.default_rng(35)
    return [(int(rng.integers(0, len(GOOD))), int(rng.integers(0, 4)), int(rng.integers(0, len(PIECES))))
            for _ in range(N_EDITS)]


@pytest.mark.parametrize("at, drop, piece", _edits())
def test_an_edited_arrivals_list_reads_checked_or_is_refused_by_name(tmp_path, at, drop, piece):
    text = GOOD[:at] + PIECES[piece] + GOOD[at + drop:]
    path = tmp_path / "arrivals.csv"
    path.write_text(text, encoding="utf-8")
    with time_bound(1.0):
        try:
            items = read_arrivals(path, BELT, TYPES)
        except ArrivalsFileError as exc:
            assert str(path) in str(exc)
            return
        except InvalidInput as exc:  # an item off the belt: the stream's own check
            assert "off the belt" in str(exc)
            return
    assert np.all(np.isfinite(items.t0)) and np.all(np.diff(items.t0) >= 0) and np.all(items.t0 >= 0)
    assert np.all(np.abs(items.w) <= BELT.width / 2)
