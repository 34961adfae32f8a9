"""The paper-vs-pinarms table in a terminal: wrapped to its width, every word kept."""

from __future__ import annotations

import re

import pytest

from pinarms.report import Row, format_table
from pinarms.errors import InvalidInput

ROWS = [
    Row("000", "3-5-3 at the paper's optimised times: peak |v|", 54.2, 44.459, "deg/s", 0.1,
        "exact peak of the paper's own 3-5-3 at its times; its 54.2 does not follow (limit 55)"),
    Row("001", "Table 3 J1-J3 at t = 2.2 s", (-0.295, 1.2716, 1.7386), (-0.29501, 1.2716, 1.7385), "rad", 0.001,
        "measured on the robot: tracking error (paper: up to 8e-4 rad)"),
    Row("002", "pick-and-place cycle of the gantry (the lift-feed-lower move and back, dwell 0.2 s, axis limits "
        "0.5 m/s of the model, 2.3873 m/s², 31.831 m/s³): picks per minute", 60, 17.826, "1/min", None,
        "different path (the paper's is not printed), limits of the model, not the machine's"),
]


def _text(table: str) -> list[str]:
    """All characters of the cells (sorted: wrapping interleaves the columns), without rules and spacing."""
    return sorted("".join(line for line in table.splitlines() if not re.fullmatch(r"[- =]+", line)).replace(" ", ""))


@pytest.mark.parametrize("width", [80, 100, 160])
def test_wrapped_to_the_width_with_every_word(width):
    full = format_table(ROWS)
    assert max(len(line) for line in full.splitlines()) > 200  # the long quantity on one line
    table = format_table(ROWS, width=width)
    assert max(len(line) for line in table.splitlines()) <= width
    assert _text(table) == _text(full)
    assert table.splitlines()[-1] == "3 rows: 1 agree, 1 differ (reason given), 1 not comparable"


def test_a_table_that_fits_is_unchanged():
    short = [Row("004", "FK z", -929.2, -929.17, "mm", 0.05, "")]
    assert format_table(short, width=120) == format_table(short)


def test_bad_width():
    for bad in (10, 80.0, True):
        with pytest.raises(InvalidInput, match="width"):
            format_table(ROWS, width=bad)


def test_signed_percent_prints_one_text_for_a_zero_of_either_sign():
    """A ratio of float noise (1e-12 either way) printed "-0.0 %" on one processor and "+0.0 %" on another."""
    from pinarms.report import signed_percent

    assert signed_percent(-1e-12) == signed_percent(1e-12) == signed_percent(-0.0004) == "+0.0 %"
    assert signed_percent(0.0123) == "+1.2 %" and signed_percent(-0.0123) == "-1.2 %"
