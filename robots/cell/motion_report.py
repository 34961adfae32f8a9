"""What a continuous motion check of a cell found: :class:`MotionCheck` and its first :class:`Contact`.

:func:`~pinarms.robots.cell.motion.check_motion` builds them; the verdicts
(``collision_free``, ``clear``) are proofs, see :mod:`.motion` for the rule.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .pairs import CollisionPair

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
        min_clearance: the smallest distance at the samples [m] (negative: overlap), its
            time [s] and pair (``min_clearance_time``, ``min_clearance_pair``).
        lower_bound: when no contact is found, a proven lower bound of the distance over
            the whole window [m]; with a contact, the deepest sample.
        times: ``(M,)`` sample times [s] (refinement samples included, sorted);
            ``clearance``: ``(M,)`` smallest distance at each [m], exact where ``exact``
            ``(M,)`` is true, else the screen's bound ``required + margin`` (the sample is at
            least that far from every contact); ``pair_index``: ``(M,)`` index into
            ``pairs`` of the closest pair (−1 where not exact).
        min_clearance: the smallest value of ``clearance``: an exact distance when
            :attr:`min_clearance_is_exact` (then ``min_clearance_pair`` is its pair), else
            — no sample came within ``required + margin`` of a contact and ``curve`` was
            off — the screening *bound* ``required + margin`` and ``min_clearance_pair`` is
            ``None``. Quote :attr:`min_sample_distance` for a distance and
            :attr:`lower_bound` for a proven bound.
        dt: the finest time step [s] (at the global speed bound); ``speed_bound``: that
            bound ``V`` [m/s];
            ``margin`` and ``required`` [m]; ``window``: ``(t_start, t_end)`` [s].
        pairs: the pairs looked at (:meth:`Cell.pairs_for` at ``required + margin``); the
            pairs left out are proven farther than that in every configuration.

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

    @property
    def n_samples(self) -> int:
        """Number of configurations whose distance was computed."""
        return int(self.times.size)

    @property
    def min_clearance_is_exact(self) -> bool:
        """Whether :attr:`min_clearance` is an exact distance (else the screening bound)."""
        return self.min_clearance_pair is not None

    @property
    def min_sample_distance(self) -> float:
        """The smallest exact distance at a sample [m] (coal); ``nan`` when every sample was screened clear."""
        d = self.clearance[self.exact]
        return float(d.min()) if d.size else float("nan")

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
        """One line: verdict, first contact or minimum clearance, samples and step."""
        if self.first_contact is not None:
            c = self.first_contact
            head = f"contact at t = {c.time:.4f} s: {c.pair} (depth {c.depth * 1e3:.1f} mm)"
        elif self.min_clearance_pair is None:
            head = (f"{'clear' if self.clear else 'NOT proven clear'}: every sample at least {self.min_clearance * 1e3:.1f} mm"
                    f" (screening bound), proven lower bound {self.lower_bound * 1e3:.1f} mm")
        else:
            head = (
                f"{'clear' if self.clear else 'NOT proven clear'}: smallest sampled distance {self.min_clearance * 1e3:.1f} mm"
                f" at t = {self.min_clearance_time:.4f} s ({self.min_clearance_pair}), proven lower bound "
                f"{self.lower_bound * 1e3:.1f} mm"
            )
        return f"{head}; {self.n_samples} samples, dt = {self.dt * 1e3:.3f} ms, speed bound {self.speed_bound:.2f} m/s"
