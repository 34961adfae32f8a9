"""Assignment rules as objects: a new rule runs without touching the simulator; the Python loop and
the compiled loop give the same runs for every built-in rule."""

import numpy as np
import pytest

from pinarms.optim.line._sim_kernel import spacing
from pinarms.optim.line.belt import Belt
from pinarms.optim.line.items import poisson_items
from pinarms.optim.line.rules import RULES, AssignmentRule, Bands, FirstInWindow, LookAhead, Rule, assignment_rule
from pinarms.optim.line.rules.base import startable
from pinarms.optim.line.simulate import SimArm, simulate
from pinarms.optim.line.task_maps import TaskMap
from pinarms.errors import InvalidInput

BELT = Belt((0.0, 0.0, 0.8), speed=0.2, width=0.3, length=4.0)


def leave_map(leave=(0.3, 1.4)):
    du = np.linspace(-0.3, 0.3, 13)
    return TaskMap("m", du, np.array([-0.15, 0.15]), np.full((13, 2), 0.4), np.tile(leave, (13, 1)), 0.5, 0.1,
                   BELT.speed, 0.1)


class LastInWindow(AssignmentRule):
    """A rule the simulator does not know: the startable item that arrived last."""

    name = "last"

    def prefer(self, d):
        s = startable(d)
        return s[np.argsort(-d.candidates.t0[s], kind="stable")]


def test_a_new_rule_runs_without_touching_the_simulator():
    items = poisson_items(BELT, 0.6, 300.0, seed=4)
    arm = [SimArm("a", 1.0, (leave_map(),))]
    last = simulate(arm, items, BELT.speed, LastInWindow(), duration=300.0)
    first = simulate(arm, items, BELT.speed, "first", duration=300.0)
    assert LastInWindow().kernel_form() is None
    assert last.picks > 0 and not np.array_equal(last.picked_by, first.picked_by)

    def out_of_order(r):  # picks of a later arrival started before the pick of an earlier one
        done = np.flatnonzero(r.picked_by == 0)
        return int(np.count_nonzero(np.diff(r.start[done]) < 0))

    assert out_of_order(first) == 0 and out_of_order(last) > 0


class Python(AssignmentRule):
    """A built-in rule seen through a rule the compiled loop does not know: the same preferences, the Python loop."""

    def __init__(self, inner):
        self.inner, self.name, self.needs_width = inner, inner.name, inner.needs_width

    @property
    def looks_beyond(self):
        return self.inner.looks_beyond

    def prefer(self, d):
        return self.inner.prefer(d)

    def takes(self, arm, n_arms, index, w, width):
        return self.inner.takes(arm, n_arms, index, w, width)


@pytest.mark.parametrize("rule", RULES)
def test_python_and_compiled_loops_give_the_same_runs(rule):
    inner = Rule(rule, 5).build()
    assert inner.kernel_form() is not None and Python(inner).kernel_form() is None
    arms = [SimArm(f"a{k}", 1.0 + 0.45 * k, (leave_map(),), rest=(0.8 + 0.45 * k, 0.3)) for k in (2, 0, 1)]
    items = poisson_items(BELT, 1.2, 150.0, seed=11)
    fast = simulate(arms, items, BELT.speed, inner, duration=150.0, width=BELT.width)
    slow = simulate(arms, items, BELT.speed, Python(inner), duration=150.0, width=BELT.width)
    assert fast.picks > 0 and fast.decisions == slow.decisions
    for column in ("picked_by", "meet", "u_meet", "start", "finish"):
        assert np.array_equal(getattr(fast, column), getattr(slow, column), equal_nan=True), column


def test_a_subclass_that_changes_the_choice_leaves_the_compiled_loop():
    class Later(FirstInWindow):
        def prefer(self, d):
            return super().prefer(d)[::-1]

    class NarrowBands(Bands):
        def takes(self, arm, n_arms, index, w, width):
            return super().takes(arm, n_arms, index, w, width) & (np.abs(w) < 0.1)

    assert FirstInWindow().kernel_form() is not None and Bands().kernel_form() is not None
    assert Later().kernel_form() is None and NarrowBands().kernel_form() is None


def test_rules_by_name_and_bad_rules():
    assert [type(assignment_rule(n)).name for n in RULES] == list(RULES)
    assert assignment_rule(Rule("lookahead", 7)) == LookAhead(7)
    with pytest.raises(InvalidInput, match="unknown assignment rule 'fastest'; known: first, nearest"):
        assignment_rule("fastest")
    with pytest.raises(InvalidInput, match="a name .* a Rule or an AssignmentRule, got int"):
        assignment_rule(3)
    with pytest.raises(InvalidInput, match=r"horizon must be an integer in 1..8, got 9"):
        LookAhead(9)
    with pytest.raises(NotImplementedError, match="does not say which item it prefers"):
        simulate([SimArm("a", 1.0, (leave_map(),))], poisson_items(BELT, 0.5, 20.0, seed=0), BELT.speed,
                 AssignmentRule(), duration=20.0)


def test_spacing_is_numpys():
    x = np.concatenate([[0.0, 5e-324, 1e-310, 0.5, 1.0, 2.0, 3600.0, 2.0 ** 40],
                        np.random.default_rng(0).uniform(0.0, 1e6, 200)])
    assert [spacing.py_func(float(v)) for v in x] == [float(np.spacing(v)) for v in x]


def test_a_line_spec_takes_a_rule_object(scara_line):
    from pinarms.optim.line.api import LineSpec, Stream, run_line

    belt, station = scara_line
    spec = LineSpec(BELT, (station,), Stream("poisson", 0.6, 120.0), rule=LastInWindow(), seeds=(0, 1))
    result = run_line(spec, maps={station.name: (leave_map(),)})
    assert spec.rule.name == "last" and all(r.picks > 0 for r in result.runs)
    with pytest.raises(InvalidInput, match="rule must be a rule name, a Rule or an AssignmentRule, got int"):
        LineSpec(belt, (station,), rule=3)
