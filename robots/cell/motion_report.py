"""What a continuous motion check of a cell found: :class:`MotionCheck` and its first :class:`Contact`.

:func:`~pinarms.robots.cell.motion.check_motion` builds them; the verdicts
(``collision_free``, ``clear``) are proofs, see :mod:`.motion` for the rule.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field

import numpy as np

from pinarms.robots.cell.pairs import CollisionPair

__all__ = ["Contact", "MotionCheck"]


@dataclass(frozen=True, eq=False)
class Contact:
    """Where a motion first touches.

    Attributes:
        time: cell time [s] (the first instant found in contact, within ``dt / 1024``).
        pair: the pair in contact.
        depth: penetration depth there [m] (≥ 0).
        q: the cell configuration at that time ``(nq,)``.
    """

    time: float
    pair: CollisionPair
    depth: float
    q: np.ndarray


@dataclass(frozen=True, eq=False)
class MotionCheck:
    """What :func:`check_motion` found.

    Attributes:
        collision_free: proven: no contact anywhere in the window.
        clear: proven: every distance stays ≥ ``required`` [m] in the window.
        first_contact: the first contact (:class:`Contact`) or ``None``.
        max_depth: the largest penetration depth seen at a sample [m] (0 when none).
        min_clearance: the true smallest distance found [m]: coal's exact distance, over every
            pair of the cell, at the sample where it is smallest (negative: overlap, the
            deepest sample); ``min_clearance_time`` [s] and ``min_clearance_pair`` (the two
            shapes; ``None`` only in a cell without pairs) say where. Always a distance, never
            a bound: the motion's true minimum lies between :attr:`lower_bound` and it.
        lower_bound: a proven lower bound of every distance over the whole window [m] (no
            two shapes come closer, between the samples too), at the check's resolution
            ``margin``: once ``required`` is proven the proof stops there, so it is a
            guarantee, not a distance; with a contact, the deepest sample.
        times: ``(M,)`` sample times [s] (refinement samples included, sorted);
            ``clearance``: ``(M,)`` smallest distance at each [m], exact where ``exact``
            ``(M,)`` is true, else the :attr:`screening_bound` ``required + margin`` (the
            sample is at least that far from every contact, not computed further);
            ``pair_index``: ``(M,)`` index into ``pairs`` of the closest pair (−1 where not
            exact).
        dt: the finest time step [s] (at the global speed bound); ``speed_bound``: that
            bound ``V`` [m/s];
            ``margin`` and ``required`` [m]; ``window``: ``(t_start, t_end)`` [s].
        pairs: the pairs looked at (:meth:`Cell.pairs_for` at ``required + margin``); the
            pairs left out are proven farther than that in every configuration.
        curves: with ``curve=True``, ``{group: (M,) exact distance [m] at times}``: each moving
            arm against the fixtures, against each other arm, and between its own links
            (:func:`.motion_curves.moving_arm_curves`; shapes that do not move left out); else
            empty. ``curve_pairs``: ``{group: CollisionPair}`` the closest pair of each group.

    ``repr`` is :meth:`summary`.
    """

    collision_free: bool
    clear: bool
    first_contact: Contact | None
    max_depth: float
    min_clearance: float
    min_clearance_time: float
    min_clearance_pair: CollisionPair | None
    lower_bound: float
    times: np.ndarray
    clearance: np.ndarray
    pair_index: np.ndarray
    exact: np.ndarray
    dt: float
    speed_bound: float
    margin: float
    required: float
    window: tuple[float, float]
    pairs: tuple[CollisionPair, ...]
    curves: dict[str, np.ndarray] = field(default_factory=dict)
    curve_pairs: dict[str, CollisionPair] = field(default_factory=dict)

    @property
    def n_samples(self) -> int:
        """Number of configurations whose distance was computed."""
        return int(self.times.size)

    @property
    def min_clearance_is_exact(self) -> bool:
        """Deprecated: :attr:`min_clearance` is always an exact distance now (``True`` but in a cell without pairs)."""
        warnings.warn("MotionCheck.min_clearance_is_exact is deprecated: min_clearance is always an exact distance",
                      DeprecationWarning, stacklevel=2)
        return self.min_clearance_pair is not None

    @property
    def min_sample_distance(self) -> float:
        """Deprecated: the same as :attr:`min_clearance` (the smallest exact distance at a sample) [m]."""
        warnings.warn("MotionCheck.min_sample_distance is deprecated: read min_clearance (always an exact distance)",
                      DeprecationWarning, stacklevel=2)
        return self.min_clearance

    @property
    def screening_bound(self) -> float:
        """The screen's distance ``required + margin`` [m]: a sample not computed exactly is at least this far."""
        return self.required + self.margin

    def __repr__(self) -> str:
        return f"MotionCheck({self.summary()})"

    @property
    def in_contact(self) -> np.ndarray:
        """``(M,)`` bool: the samples in contact (distance ≤ 0)."""
        return self.clearance <= 0.0

    def summary(self) -> str:
        """One line in plain words: the smallest clearance and where, whether the clearance held (and what is proven).

        E.g. ``smallest clearance 32.2 mm (forearm ↔ table at t = 0.410 s); the 10 mm clearance holds
        along the whole motion (proven: no two shapes closer than 10.0 mm); 507 samples, ...``.
        """
        return f"{self.verdict()}; {self.n_samples} samples, dt = {self.dt * 1e3:.3f} ms, speed bound {self.speed_bound:.2f} m/s"

    def verdict(self) -> str:
        """The summary without the sampling figures: the smallest clearance, then what held and what is proven."""
        if self.first_contact is not None:
            c = self.first_contact
            return (f"CONTACT at t = {c.time:.4f} s: {_pair_text(c.pair)} (depth {c.depth * 1e3:.1f} mm, deepest "
                    f"{self.max_depth * 1e3:.1f} mm)")
        where = ("" if self.min_clearance_pair is None else
                 f" ({_pair_text(self.min_clearance_pair)} at t = {self.min_clearance_time:.3f} s)")
        head = f"smallest clearance {_mm(self.min_clearance)}{where}"
        proven = f"proven: no two shapes closer than {_mm(self.lower_bound)}"
        if self.required > 0.0:
            asked = f"the {self.required * 1e3:g} mm clearance"
            if self.clear:
                return f"{head}; {asked} holds along the whole motion ({proven})"
            return f"{head}; {asked} is NOT proven along the whole motion ({proven})"
        if self.collision_free:
            return f"{head}; no contact along the whole motion ({proven})"
        return f"{head}; contact-free NOT proven between the samples ({proven})"


def _mm(x: float) -> str:
    return "inf" if not np.isfinite(x) else f"{x * 1e3:.1f} mm"


def _pair_text(pair: CollisionPair) -> str:
    return f"{pair.body_a} ↔ {pair.body_b}"
