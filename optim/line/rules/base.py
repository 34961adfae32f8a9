"""The base of every assignment rule: what an idle arm sees at its decision, and what a rule answers.

At a decision at time ``t`` the simulator (:func:`pinarms.optim.line.simulate.simulate`) hands the rule a
:class:`Decision`: the arm, the feasible picks of the items it may take (:class:`Candidates`, some
startable now, some only later) and the arm's intercept, for rules that plan several picks ahead.
The rule answers with :meth:`AssignmentRule.prefer`: the candidates in its order of preference.
The simulator starts the first it may (a neighbour's ongoing pick may block one: the next is
tried), or, when the first preferred starts later than ``t``, lets the arm sleep until then.

A new rule is a subclass with a ``name`` and its own :meth:`~AssignmentRule.prefer` (and, when it
keeps some items for other arms, :meth:`~AssignmentRule.takes`); it is passed to ``simulate`` or
:class:`~pinarms.optim.line.api.LineSpec` as an object. The built-in rules (one module each) also describe
themselves to the compiled loop (:meth:`~AssignmentRule.kernel_form`), which then runs them without
a call back into Python; a rule without that form runs in the simulator's Python loop.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, ClassVar

import numpy as np

__all__ = ["AssignmentRule", "Candidates", "Decision", "KernelForm", "EPS", "startable"]

#: Time tolerance of "start now" [s].
EPS = 1e-9


@dataclass(frozen=True)
class Candidates:
    """Feasible picks of one arm at its decision time (arrays of shape (k,), ascending ``index``):
    item ``index``, ``start`` [s] (when the arm must leave its box; ``>= t``), ``meet`` [s]
    (rendezvous at the pre-grasp point), ``finish`` [s] (back at rest at the box), ``t0`` [s],
    ``w`` [m], ``distance`` [m] from the tool at rest to the item at decision time."""

    index: np.ndarray
    start: np.ndarray
    meet: np.ndarray
    finish: np.ndarray
    t0: np.ndarray
    w: np.ndarray
    distance: np.ndarray


@dataclass(frozen=True)
class Decision:
    """One decision of an idle arm: ``t`` [s]; ``arm``: its position along the belt (0: the most
    upstream) of ``n_arms``; ``candidates``; ``intercept(ready, item)``: ``(start, finish)`` [s] of
    the pick of ``item`` by the arm ready at ``ready``, or None when it can no longer be picked."""

    t: float
    arm: int
    n_arms: int
    candidates: Candidates
    intercept: Callable[[float, int], tuple[float, float] | None]


@dataclass(frozen=True)
class KernelForm:
    """How the compiled loop runs a built-in rule: ``order`` the key it ranks startable picks by
    before arrival and index (0: arrival, 1: distance to the tool, 2: finish), ``share`` the items an
    arm takes (0: all, 1: its band across the belt, 2: every ``n``-th), ``horizon`` (> 0: the
    look-ahead's branch and bound over that many candidates instead of a ranking)."""

    order: int = 0
    share: int = 0
    horizon: int = 0


def startable(d: Decision) -> np.ndarray:
    """Positions in ``d.candidates`` of the picks that can start at ``d.t``."""
    return np.flatnonzero(d.candidates.start <= d.t + EPS)


class AssignmentRule:
    """An assignment rule: which of its candidates an idle arm starts (module doc).

    Class attributes: ``name``; ``needs_width`` (the simulator refuses to run it without the belt's
    width); ``plans_trays`` (False: refused for arms that place in trays); ``looks_beyond``: how many
    items past its window the arm is shown (from the first item in it).
    """

    name: ClassVar[str] = "rule"
    needs_width: ClassVar[bool] = False
    plans_trays: ClassVar[bool] = True

    @property
    def looks_beyond(self) -> int:
        return 0

    def prefer(self, d: Decision) -> np.ndarray:
        """Positions in ``d.candidates`` in order of preference (empty: wait for the earliest start)."""
        raise NotImplementedError(f"the assignment rule {type(self).__name__} does not say which item it prefers")

    def takes(self, arm: int, n_arms: int, index: np.ndarray, w: np.ndarray, width: float) -> np.ndarray:
        """Which of the items ``index`` (across at ``w`` [m] on a belt ``width`` [m] wide) arm ``arm`` of
        ``n_arms`` (upstream first) may take at all (bool, shape of ``index``): all by default."""
        return np.ones(index.shape, dtype=bool)

    def kernel_form(self) -> KernelForm | None:
        """The rule as the compiled loop runs it (None: a rule the compiled loop does not know)."""
        return None

    def _form_of(self, cls: type, form: KernelForm) -> KernelForm | None:
        """``form`` when this rule still prefers and takes as ``cls`` does (a subclass that changes either
        runs in the Python loop)."""
        same = type(self).prefer is cls.prefer and type(self).takes is cls.takes
        return form if same else None
