"""Assignment rules: which item an idle arm takes next, one class per rule.

Each rule is an :class:`AssignmentRule` (:mod:`~.base`): the simulator hands it a
:class:`Decision` (the arm's feasible picks at its decision time as :class:`Candidates`) and it
answers with its order of preference; a new rule is a subclass passed to the simulator as an
object, the simulator is not changed. The rules (names as in the literature and in the
commercial tools, ``LINE_NOTES.md``):

- ``"first"`` (:class:`~.first.FirstInWindow`): the item furthest downstream (leaves the window soonest; FIFO).
- ``"nearest"`` (:class:`~.nearest.Nearest`): the item nearest the tool at ``t`` (ABB/Schneider "nearest").
- ``"shortest"`` (:class:`~.shortest.Shortest`): the item whose task ends first (shortest processing time).
- ``"bands"`` (:class:`~.bands.Bands`): arm ``k`` of ``n`` takes only items in band ``k`` of ``n`` equal
  bands across the belt (Schneider's balancing by band), first in window within its band.
- ``"split"`` (:class:`~.split.Split`): a fixed load split: arm ``k`` takes only every ``n``-th item
  (``index mod n == k``; FANUC's percentage split with equal shares).
- ``"lookahead"`` (:class:`~.lookahead.LookAhead`): the best sequence of the next ``horizon``
  candidates, by exhaustive branch and bound (most picks, then earliest end), its first item (Han,
  Feng, Yu 2020 solve the same finite-horizon problem by dynamic programming).

:class:`Rule` names a built-in rule (what a :class:`~pinarms.optim.line.api.LineSpec` and the CLI carry);
:func:`assignment_rule` turns a name, a :class:`Rule` or a rule object into the object the simulator calls.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pinarms.optim.line.rules.bands import Bands
from pinarms.optim.line.rules.base import AssignmentRule, Candidates, Decision, KernelForm
from pinarms.optim.line.rules.first import FirstInWindow
from pinarms.optim.line.rules.lookahead import MAX_HORIZON, LookAhead, best_sequence
from pinarms.optim.line.rules.nearest import Nearest
from pinarms.optim.line.rules.shortest import Shortest
from pinarms.optim.line.rules.split import Split
from pinarms.errors import InvalidInput

__all__ = ["RULES", "Rule", "AssignmentRule", "Candidates", "Decision", "KernelForm", "FirstInWindow", "Nearest",
           "Shortest", "Bands", "Split", "LookAhead", "best_sequence", "assignment_rule"]

#: The built-in rules by name.
BUILT_IN: dict[str, type[AssignmentRule]] = {c.name: c for c in (FirstInWindow, Nearest, Shortest, Bands, Split,
                                                                 LookAhead)}
RULES = tuple(BUILT_IN)


@dataclass(frozen=True)
class Rule:
    """A built-in assignment rule by name: ``name`` in :data:`RULES`; ``horizon``: items the look-ahead
    orders (1..8)."""

    name: str = "first"
    horizon: int = 4

    def __post_init__(self) -> None:
        if self.name not in RULES:
            raise InvalidInput(f"unknown assignment rule {self.name!r}; known: {', '.join(RULES)}")
        if isinstance(self.horizon, bool) or not isinstance(self.horizon, (int, np.integer)) or \
                not 1 <= self.horizon <= MAX_HORIZON:
            raise InvalidInput(f"look-ahead horizon must be an integer in 1..{MAX_HORIZON}, got {self.horizon!r}")

    def build(self) -> AssignmentRule:
        """The rule object the simulator calls."""
        cls = BUILT_IN[self.name]
        return cls(int(self.horizon)) if cls is LookAhead else cls()


def assignment_rule(rule: "Rule | str | AssignmentRule") -> AssignmentRule:
    """The rule object of a name, a :class:`Rule` or a rule object (returned as it is).

    Raises:
        InvalidInput: an unknown name, a horizon out of range, or something that is none of these.
    """
    if isinstance(rule, AssignmentRule):
        return rule
    if isinstance(rule, Rule):
        return rule.build()
    if isinstance(rule, str):
        return Rule(rule).build()
    raise InvalidInput(f"an assignment rule is a name ({', '.join(RULES)}), a Rule or an AssignmentRule, "
                       f"got {type(rule).__name__}")

