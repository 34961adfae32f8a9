"""What a line engineer quotes: picks per minute, miss rate with a confidence interval over
seeds, each arm's utilisation and idle time, how long items wait and arms idle.

The miss rate's interval is Student's t over the seeds' miss rates (95 %, ``n − 1`` degrees
of freedom; one seed: no interval). Idle gaps are the times an arm spends at rest at its box
between two picks.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np

from pinarms.optim.line.simulate import SimResult
from pinarms.errors import InvalidInput

__all__ = ["LineFigures", "summarise", "confidence_interval"]


def confidence_interval(values: Sequence[float], level: float = 0.95) -> tuple[float, float, float]:
    """(mean, low, high) of ``values`` by Student's t (low = high = mean for one value)."""
    from scipy import stats

    x = np.asarray(values, dtype=float)
    if x.size == 0:
        raise InvalidInput("a confidence interval needs at least one value")
    m = float(x.mean())
    if x.size == 1:
        return m, m, m
    half = float(stats.t.ppf(0.5 + level / 2.0, x.size - 1) * x.std(ddof=1) / np.sqrt(x.size))
    return m, m - half, m + half


@dataclass(frozen=True)
class LineFigures:
    """Figures over the seeds' runs (means unless named).

    Attributes:
        picks_per_minute, arrivals_per_minute: picked and arrived items per minute.
        miss_rate: mean fraction missed; ``miss_rate_ci``: its 95 % interval (low, high).
        utilisation: per arm, fraction of the time moving; ``idle_s``: per arm, idle time [s] per run.
        picks_share: per arm, fraction of the picks it made.
        wait_mean_s, wait_p95_s: time items spend on the belt before their rendezvous [s].
        idle_gap_mean_s: mean length of an arm's rest between two picks [s].
        seeds: runs summarised.
        tray_fill_rate: placed items over the slots of the trays seen (None: boxes only);
        trays_unfilled: trays that left the last place window with a free slot, per run;
        unplaced_rate: fraction of items missed for want of a free reachable tray slot.
    """

    arms: tuple[str, ...]
    picks_per_minute: float
    arrivals_per_minute: float
    miss_rate: float
    miss_rate_ci: tuple[float, float]
    utilisation: tuple[float, ...]
    idle_s: tuple[float, ...]
    picks_share: tuple[float, ...]
    wait_mean_s: float
    wait_p95_s: float
    idle_gap_mean_s: float
    seeds: int
    tray_fill_rate: float | None = None
    trays_unfilled: float | None = None
    unplaced_rate: float | None = None

    def as_dict(self) -> dict[str, Any]:
        tray = ("tray_fill_rate", "trays_unfilled", "unplaced_rate")
        return {k: (list(v) if isinstance(v, tuple) else v) for k, v in self.__dict__.items()
                if not (k in tray and v is None)}


def _idle_gaps(r: SimResult) -> np.ndarray:
    gaps = []
    for k in range(len(r.arms)):
        sel = np.flatnonzero(r.picked_by == k)
        if sel.size > 1:
            o = np.argsort(r.start[sel])
            gaps.append(r.start[sel][o][1:] - r.finish[sel][o][:-1])
    return np.concatenate(gaps) if gaps else np.zeros(0)


def summarise(results: Sequence[SimResult]) -> LineFigures:
    """:class:`LineFigures` of runs of the same line on different seeds."""
    if not results:
        raise InvalidInput("summarise needs at least one simulation result")
    arms = results[0].arms
    miss = [r.miss_rate for r in results]
    mean, lo, hi = confidence_interval(miss)
    util = np.mean([r.utilisation for r in results], axis=0)
    idle = np.mean([r.duration - r.busy for r in results], axis=0)
    share = np.mean([np.bincount(r.picked_by[r.picked_by >= 0], minlength=len(arms)) / max(r.picks, 1)
                     for r in results], axis=0)
    waits = np.concatenate([r.meet[r.picked_by >= 0] - _t0(r) for r in results])
    gaps = np.concatenate([_idle_gaps(r) for r in results])
    return LineFigures(
        arms=tuple(arms),
        picks_per_minute=float(np.mean([r.picks_per_minute for r in results])),
        arrivals_per_minute=float(np.mean([60.0 * r.n_items / r.duration for r in results])),
        miss_rate=mean,
        miss_rate_ci=(max(0.0, lo), min(1.0, hi)),
        utilisation=tuple(float(x) for x in util),
        idle_s=tuple(float(x) for x in idle),
        picks_share=tuple(float(x) for x in share),
        wait_mean_s=float(waits.mean()) if waits.size else float("nan"),
        wait_p95_s=float(np.percentile(waits, 95)) if waits.size else float("nan"),
        idle_gap_mean_s=float(gaps.mean()) if gaps.size else 0.0,
        seeds=len(results),
        **_tray_figures(results),
    )


def _tray_figures(results: Sequence[SimResult]) -> dict[str, Any]:
    if all(r.tray is None for r in results):
        return {}
    return {"tray_fill_rate": float(np.nanmean([r.tray_fill for r in results])),
            "trays_unfilled": float(np.mean([r.trays_unfilled for r in results])),
            "unplaced_rate": float(np.mean([r.unplaced / max(r.n_items, 1) for r in results]))}


def _t0(r: SimResult) -> np.ndarray:
    return r.t0[r.picked_by >= 0]
