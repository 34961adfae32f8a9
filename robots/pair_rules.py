"""Why a pair of collision geometries is never checked: the reasons a single arm and a cell share.

A pair is skipped only for a reason that is proven from the structure and the shapes, or
declared by the description's author (:class:`PairReason`); a sample never skips a pair on its
own. :func:`by_design` gives the structural reasons (same link, rigid, coaxial, adjacent),
:func:`declared_pairs` reads the declarations (``<disable_collisions link1= link2= reason=/>``,
the SRDF element, at the top level of a URDF; Pinocchio ignores it). :class:`pinarms.robots.SelfCollision`
(one arm) and :mod:`pinarms.robots.cell.pairs` (a cell, which adds ``out of reach`` and ``constant``)
both build on them; the shapes that turn about their own axis come from :mod:`.coaxial`.
"""

from __future__ import annotations

import enum
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from typing import Iterable

import pinocchio as pin

__all__ = ["PairReason", "AllowedPair", "ALWAYS_SHARE", "effective_joint", "by_design", "structural_reason", "declared_pairs", "contact_rows"]

#: Share of seeded random configurations in contact at and above which a pair must be explained
#: (a reason of :func:`by_design` through turning shapes, or a declaration), else it is an error.
ALWAYS_SHARE = 0.95


class PairReason(enum.StrEnum):
    """Why a pair is not checked; equal to its text (``PairReason.RIGID == "rigid"``).

    ``same link``: both belong to one link; ``rigid``: no joint lies between them;
    ``coaxial``: one turns only about its own axis of symmetry relative to the other
    (:mod:`.coaxial`); ``adjacent``: their links are joined by one joint (``<mimic>`` joints
    count as part of the joint they follow); ``declared``: named by the description's author;
    ``out of reach`` and ``constant``: a cell's proven gaps, kept with their bound and checked again at a
    clearance above it (:mod:`pinarms.robots.cell.pairs`, :mod:`.pair_proofs`).
    """

    SAME_LINK = "same link"
    RIGID = "rigid"
    COAXIAL = "coaxial"
    ADJACENT = "adjacent"
    DECLARED = "declared"
    OUT_OF_REACH = "out of reach"
    CONSTANT = "constant"


@dataclass(frozen=True)
class AllowedPair:
    """A pair of geometries that is not checked at clearance 0, and why.

    Attributes:
        geometry_a, geometry_b: geometry names (``"<link>_<k>"``).
        body_a, body_b: link names.
        reason: a :class:`PairReason`.
        distance_bound: for a cell's ``"out of reach"``: a proven lower bound (> 0) of the pair's
            distance in every configuration [m]; for ``"constant"``: its proven constant distance (less
            1e-9 m); ``inf`` for the pairs allowed by design.
        note: for ``"declared"``: the reason the description gives (may be empty); for an ``"out of reach"``
            pair proven by its gap along a joint axis: ``"axial gap"``.
        index_a, index_b: geometry indices in the collision model.
    """

    geometry_a: str
    geometry_b: str
    body_a: str
    body_b: str
    reason: PairReason
    distance_bound: float = float("inf")
    index_a: int = -1
    index_b: int = -1
    note: str = ""


def effective_joint(model: pin.Model, j: int) -> int:
    """``j``, or its first non-mimic ancestor when ``j`` is a ``<mimic>`` joint."""
    while j > 0 and "Mimic" in model.joints[j].shortname():
        j = model.parents[j]
    return j


def by_design(model: pin.Model, a: int, b: int, link: list[str], owner: list[str], eff: list[int],
              still: list[tuple[int, ...]]) -> PairReason | None:
    """The :class:`PairReason` when the structure allows the pair ``(a, b)`` (same link, rigid, coaxial, adjacent),
    else ``None``.

    ``link``, ``owner``, ``eff``: per geometry, its link, its owner (arm or fixture) and its effective joint.
    ``still``: per geometry, the effective joints in whose frames it is fixed (its own joint alone, or with
    those of :func:`.coaxial.still_frames`); two geometries fixed in one frame are ``coaxial``, joined by one
    joint ``adjacent``. A fixture or another arm's base is never adjacent to an arm's link.
    """
    if link[a] == link[b]:
        return PairReason.SAME_LINK
    if eff[a] == eff[b]:
        return PairReason.RIGID
    if set(still[a]) & set(still[b]):
        return PairReason.COAXIAL
    for ea in still[a]:
        for eb in still[b]:
            if (ea == 0 or eb == 0) and owner[a] != owner[b]:
                continue
            if (ea > 0 and effective_joint(model, model.parents[ea]) == eb) or (
                    eb > 0 and effective_joint(model, model.parents[eb]) == ea):
                return PairReason.ADJACENT
    return None



def structural_reason(model: pin.Model, a: int, b: int, link: list[str], owner: list[str], eff: list[int],
                      still: list[tuple[int, ...]], declared: dict) -> tuple[PairReason, str] | None:
    """``(reason, note)`` when the structure (:func:`by_design`) or the user's declaration
    (``declared``: ``{frozenset((link1, link2)): reason given}``) allows the pair ``(a, b)``, else ``None``."""
    reason = by_design(model, a, b, link, owner, eff, still)
    if reason is not None:
        return reason, ""
    note = declared.get(frozenset((link[a], link[b])))
    return None if note is None else (PairReason.DECLARED, note)

def declared_pairs(root: ET.Element, links: Iterable[str], source: str, error: type[Exception],
                   hint: str = "name two of its links") -> tuple[tuple[str, str, str], ...]:
    """The ``<disable_collisions link1 link2 reason>`` elements at the top level of ``root``: ``(link1, link2, reason)``.

    Raises:
        error: an element without two distinct link names, or naming a link not in ``links``.
    """
    known = set(links)
    out = []
    for el in root.findall("disable_collisions"):
        a, b, note = el.get("link1"), el.get("link2"), el.get("reason", "")
        if not a or not b or a == b:
            raise error(f"{source}: a <disable_collisions> needs two different links, link1=\"...\" and "
                        f"link2=\"...\"; got link1={a!r}, link2={b!r}")
        for name in (a, b):
            if name not in known:
                raise error(f"{source}: <disable_collisions> names link {name!r}, which the file does not define; "
                            f"{hint}")
        out.append((a, b, note))
    return tuple(out)


def contact_rows(found: Iterable[tuple[str, str, float, float]], samples: int) -> tuple[tuple, str]:
    """Pairs of links in contact without a reason, for an error: ``found`` holds ``(link_a, link_b, share, depth [m])``
    per geometry pair; returns one ``(link_a, link_b, share, depth)`` row per pair of links (largest share and depth,
    deepest first) and their text (the eight deepest, out of ``samples`` configurations)."""
    worst: dict[tuple[str, str], tuple[float, float]] = {}
    for a, b, share, depth in found:
        s0, d0 = worst.get((a, b), (0.0, 0.0))
        worst[(a, b)] = (max(s0, share), max(d0, depth))
    rows = tuple((a, b, s, d) for (a, b), (s, d) in sorted(worst.items(), key=lambda kv: -kv[1][1]))
    shown = "; ".join(f"{a} – {b} in {s:.0%} of {samples} configurations, up to {d * 1e3:.1f} mm deep"
                      for a, b, s, d in rows[:8])
    more = f"; and {len(rows) - 8} more pair(s)" if len(rows) > 8 else ""
    return rows, shown + more
