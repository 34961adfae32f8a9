"""Streams and arrivals files past their bounds: a named error before any large allocation.

Each case once cost gigabytes or many seconds (issue 35, items 9 and 12); each must now be
refused within a fraction of a second and a few megabytes.
"""

import time
import tracemalloc

import numpy as np
import pytest

from pinarms.optim.line.api import Stream
from pinarms.optim.line.belt import Belt
from pinarms.optim.line.errors import ArrivalsFileError
from pinarms.optim.line.items import MAX_ITEMS, ItemType, poisson_items, read_arrivals, regular_items
from pinarms.errors import InvalidInput

BELT = Belt((0.0, 0.0, 0.8), speed=0.2, width=0.3, length=4.0)
TYPES = (ItemType("enoki", 0.15, (0.10, 0.06, 0.04)),)


def _refused_cheaply(call, error, match):
    """``call()`` raises ``error`` matching ``match`` in under 1 s, with under 50 MB allocated."""
    tracemalloc.start()
    t0 = time.perf_counter()
    try:
        with pytest.raises(error, match=match):
            call()
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert time.perf_counter() - t0 < 1.0
    assert peak < 50e6, f"{peak / 1e6:.0f} MB allocated before the refusal"


@pytest.mark.parametrize("call", [
    lambda: regular_items(BELT, 1e-9, 1.0),
    lambda: regular_items(BELT, 1.0, 1e300),
    lambda: poisson_items(BELT, 1e12, 1e12),
    lambda: poisson_items(BELT, 1e8 / 60.0, 600.0),  # `belt run --rate 1e8`: 7.45 GiB asked for
    lambda: poisson_items(BELT, 1e300, 1e300),
])
def test_a_stream_past_the_cap_is_refused_before_allocation(call):
    _refused_cheaply(call, InvalidInput, f"at most {MAX_ITEMS}")


def test_a_stream_just_under_the_cap_is_made():
    items = regular_items(BELT, 1.0, 1000.0, w=0.0)
    assert len(items) == 1000 and items.t0[-1] == 999.0


def test_a_stream_description_past_the_cap_is_refused_when_made():
    with pytest.raises(InvalidInput, match=r"1e\+09 items.*at most 2000000"):
        Stream("poisson", 1e8 / 60.0, 600.0)
    with pytest.raises(InvalidInput, match="at most 2000000"):
        Stream("regular", 1e8 / 60.0, 600.0)
    Stream("file", 1e8 / 60.0, 600.0, path="arrivals.csv")  # a file's rows are counted when it is read


def _write(tmp_path, text: str | bytes):
    p = tmp_path / "arrivals.csv"
    p.write_bytes(text if isinstance(text, bytes) else text.encode("utf-8"))
    return p


def test_arrivals_with_a_byte_order_mark_are_read(tmp_path):
    p = _write(tmp_path, "\ufefftime,across,type\n0.5,0.01,enoki\n")
    items = read_arrivals(p, BELT, TYPES)
    assert items.t0.tolist() == [0.5] and items.w.tolist() == [0.01]


def test_arrivals_with_a_column_twice_are_refused_naming_it(tmp_path):
    p = _write(tmp_path, "time,across,type,across\n0.5,0.01,enoki,0.1\n")
    with pytest.raises(ArrivalsFileError, match="column 'across' twice"):
        read_arrivals(p, BELT, TYPES)


def test_arrivals_with_a_huge_field_are_refused_by_name(tmp_path):
    p = _write(tmp_path, "time,across,type\n0.5,0.01," + "e" * 200_000 + "\n")
    with pytest.raises(ArrivalsFileError, match=r"row 1: a field longer than"):
        read_arrivals(p, BELT, TYPES)


def test_arrivals_past_the_row_cap_stop_at_the_cap(tmp_path):
    """2 000 001 rows once cost 15 s and 800 MB before the refusal; the reader now stops at the
    first row past the cap (measured: about 2 s and no row kept beyond a compact array)."""
    row = b"0.5,0.01,enoki\n"
    p = _write(tmp_path, b"time,across,type\n" + row * (MAX_ITEMS + 1))
    tracemalloc.start()
    t0 = time.perf_counter()
    try:
        with pytest.raises(ArrivalsFileError, match=f"more than {MAX_ITEMS} rows"):
            read_arrivals(p, BELT, TYPES)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert time.perf_counter() - t0 < 5.0
    assert peak < 200e6, f"{peak / 1e6:.0f} MB"


def test_arrivals_rows_are_stored_compactly(tmp_path):
    p = _write(tmp_path, "time,across,type,yaw\n" + "".join(f"{k * 0.5},0.0{k % 3},enoki,0.{k % 7}\n" for k in range(50)))
    items = read_arrivals(p, BELT, TYPES)
    assert len(items) == 50 and items.t0[-1] == 24.5 and items.w[4] == 0.01 and items.yaw[6] == 0.6
    assert np.all(items.kind == 0)


def test_a_stream_rate_is_per_second_as_poisson_items_takes_it():
    """``Stream.rate_per_s`` [items/s], the unit of ``poisson_items(rate=)``; one every 1/rate s when regular."""
    s = Stream("poisson", rate_per_s=2.0, duration=60.0)
    assert s.rate_per_s == 2.0
    items = s.items(BELT, seed=3)
    assert np.array_equal(items.t0, poisson_items(BELT, 2.0, 60.0, seed=3).t0)
    assert 90 < len(items) < 150  # about 2/s × 60 s
    regular = Stream("regular", rate_per_s=4.0, duration=10.0).items(BELT, seed=0)
    assert np.allclose(np.diff(regular.t0), 0.25)
    with pytest.raises(InvalidInput, match=r"rate_per_s \[items/s\]"):
        Stream("poisson", rate_per_s=-1.0)
