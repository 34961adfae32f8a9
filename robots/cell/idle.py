"""The arms that do not move: what they touch at their hold pose.

A planner or a cycle checks the pairs of the arm it moves; the pairs among the idle arms
and the fixtures never change while it does. A contact there would fail every attempt (or
the final re-check) with a message about the motion; :func:`idle_contacts` finds it first,
so that the caller names the idle arm and the hold pose instead.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Iterable

import numpy as np
from numpy.typing import ArrayLike

from pinarms.robots.cell.pairs import CollisionPair

from pinarms.robots.cell.cell_model import CellModel

__all__ = ["IdleContacts", "idle_contacts"]


@dataclass(frozen=True)
class IdleContacts:
    """The contacts of the idle arms at a cell configuration.

    Attributes:
        arms: the idle arms in contact (sorted).
        pairs: the touching pairs (neither body on a moving arm).
        distances: their signed distances [m] by coal (negative: penetration depth).
    """

    arms: tuple[str, ...]
    pairs: tuple[CollisionPair, ...]
    distances: tuple[float, ...]

    def __bool__(self) -> bool:
        return bool(self.pairs)

    def text(self) -> str:
        """``"b_link2 – table (overlap 18.0 mm), ..."``."""
        return ", ".join(f"{p.body_a} – {p.body_b} ({'overlap ' if d < 0 else ''}{abs(d) * 1e3:.1f} mm)"
                         for p, d in zip(self.pairs, self.distances))

    def message(self, how: str) -> str:
        """One line naming the first idle arm, the pairs and ``how`` to give it another hold pose."""
        return (f"idle arm {self.arms[0]!r} is in collision at its hold pose: {self.text()}; it does not move: give "
                f"it a clear hold pose ({how})")


def _pair_distances(cell: "CellModel", q: np.ndarray, pairs: Iterable[CollisionPair]) -> tuple[float, ...]:
    import coal
    import pinocchio as pin

    from pinarms.robots.collision_requests import cold_start

    model, gm = cell.model, cell.collision_model
    gd = cold_start(pin.GeometryData(gm))
    pin.updateGeometryPlacements(model, model.createData(), gm, gd, cell.robot.q_to_pinocchio(q))

    def placed(i: int) -> Any:
        return coal.Transform3s(gd.oMg[i].rotation, gd.oMg[i].translation)

    out = []
    for p in pairs:
        request, result = coal.DistanceRequest(), coal.DistanceResult()
        request.enable_signed_distance = True
        out.append(float(coal.distance(gm.geometryObjects[p.index_a].geometry, placed(p.index_a),
                                       gm.geometryObjects[p.index_b].geometry, placed(p.index_b), request, result)))
    return tuple(out)


def idle_contacts(cell: "CellModel", q: ArrayLike, moving: Iterable[str]) -> IdleContacts:
    """The touching pairs (distance ≤ 0) at the cell configuration ``q (nq,)`` with no body on an arm of ``moving``.

    Only pairs with at least one idle arm count (two fixtures never touch: rigid pairs are
    not checked).
    """
    skip = set(moving)
    idle = {a.name for a in cell.arms} - skip
    q = cell.robot.check_q(q)[0][0]
    pairs = tuple(p for p in cell.collisions(q).pairs_at(0)
                  if p.owner_a not in skip and p.owner_b not in skip and (p.owner_a in idle or p.owner_b in idle))
    if not pairs:
        return IdleContacts((), (), ())
    arms = tuple(sorted({o for p in pairs for o in (p.owner_a, p.owner_b) if o in idle}))
    return IdleContacts(arms, pairs, _pair_distances(cell, q, pairs))
