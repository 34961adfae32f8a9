"""The hand-off study takes the cell study's plans instead of planning them again."""

import numpy as np
import pytest

from pinarms.errors import InvalidInput
from pinarms.studies import handoff_plans
from pinarms.studies.handoff import handoff_motions


def test_remember_names_what_it_keeps():
    with pytest.raises(InvalidInput, match="line_cycles"):
        handoff_plans.remember(cycles={})  # not a known plan: the message lists the known ones


@pytest.mark.slow
def test_cell_study_plans_are_reused_and_equal_the_shipped_ones():
    from pinarms.export.shipped import shipped_motions
    from pinarms.studies.cell import study_cell

    handoff_plans.forget()
    try:
        study_cell(quick=True)
        kept = handoff_plans.kept()
        assert set(kept) == set(handoff_plans.KEPT_NAMES)
        reused = handoff_motions()
    finally:
        handoff_plans.forget()
    fresh = shipped_motions(line=True)
    assert [m.name for m in reused] == [m.name for m in fresh]
    by_name = {m.name: m for m in reused}
    assert by_name["station_cycle"].source is kept["station_cycle"]  # taken, not planned again
    assert by_name["line_schedule"].source is kept["schedule"]
    assert by_name["line_left_cycle"].source is kept["line_cycles"]["left"]
    from pinarms.optim.motion.crate_guard import crate_guard_move

    assert by_name["crate_guard_move"].source is crate_guard_move().plan  # planned once per process
    # the same motions as planning them afresh: cycle times, schedule, trajectories
    for a, b in zip(reused, fresh):
        assert (a.arm, a.cell.name, sorted(a.cycles)) == (b.arm, b.cell.name, sorted(b.cycles))
    for name in ("station_cycle", "line_left_cycle", "line_right_cycle"):
        a, b = by_name[name].source, next(m.source for m in fresh if m.name == name)
        assert a.cycle_time == pytest.approx(b.cycle_time, abs=1e-12)
        assert np.array_equal(a.trajectory.knot_times, b.trajectory.knot_times)
        assert np.array_equal(a.trajectory.coefficients, b.trajectory.coefficients)
    s_a, s_b = by_name["line_schedule"].source, fresh[-1].source
    assert s_a.period == pytest.approx(s_b.period, abs=1e-12)
    assert s_a.offsets == pytest.approx(s_b.offsets, abs=1e-12)
