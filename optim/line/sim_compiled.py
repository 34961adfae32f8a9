"""The compiled event loop's driver: the run's arrays for :func:`~._sim_kernel.run_events`.

Arms sharing their maps share their rows (:class:`~.sim_arm.ItemRows`): the kernel gets one table
per distinct set of maps (padded with infeasible nodes to the longest grid) and each arm's index
into it. numba is imported here, on the first compiled run, not with :mod:`pinarms.optim.line`.
"""

from __future__ import annotations

from typing import Sequence

import numpy as np

from pinarms.optim.line.items import Items
from pinarms.optim.line.rules.base import KernelForm
from pinarms.optim.line.sim_arm import ArmState
from pinarms.optim.line.sim_loop import Columns

__all__ = ["run_compiled"]


def _tables(states: Sequence[ArmState]) -> tuple[np.ndarray, ...]:
    """(group (A,), RA, RC (G, n, K), EX (G, n), U (A, K)) of the arms' states."""
    rows, group = [], []
    for st in states:
        found = next((g for g, r in enumerate(rows) if r is st.rows), None)
        if found is None:
            rows.append(st.rows)
            found = len(rows) - 1
        group.append(found)
    K = max(st.u.size for st in states)
    if len(rows) == 1 and rows[0].tA.shape[1] == K:
        r = rows[0]
        RA, RC, EX = (np.ascontiguousarray(x)[None] for x in (r.tA, r.tC, r.extra))
    else:
        n = rows[0].tA.shape[0]
        RA, RC = np.full((len(rows), n, K), np.nan), np.full((len(rows), n, K), np.nan)
        EX = np.stack([r.extra for r in rows])
        for g, r in enumerate(rows):
            RA[g, :, :r.tA.shape[1]], RC[g, :, :r.tC.shape[1]] = r.tA, r.tC
    U = np.stack([np.concatenate([st.u, np.full(K - st.u.size, st.u[-1])]) for st in states])
    return np.array(group, dtype=np.int64), RA, RC, EX, U


def run_compiled(states: Sequence[ArmState], items: Items, speed: float, form: KernelForm,
                 width: float) -> tuple[Columns, int]:
    """The item columns and the number of decisions of the run (arms upstream first)."""
    from pinarms.optim.line._sim_kernel import run_events

    cols = Columns.empty(len(items))
    group, RA, RC, EX, U = _tables(states)
    floats = [np.array([getattr(st, a) for st in states], dtype=float) for a in ("u_min", "u_max", "max_tA")]
    rest = np.array([st.rest for st in states], dtype=float).reshape(len(states), 2)
    t0, w = (np.ascontiguousarray(x, dtype=float) for x in (items.t0, items.w))
    decisions = run_events(t0, w, float(speed), float(width), group, RA, RC, EX, U, *floats, rest, int(form.order),
                           int(form.share), int(form.horizon), cols.picked_by, cols.meet, cols.u_meet, cols.start,
                           cols.finish)
    return cols, int(decisions)
