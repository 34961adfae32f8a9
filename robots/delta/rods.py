"""Where the six rods of a delta are: their ball centres, for drawing, animating and collision checking.

The tree carries one mid-line forearm per leg; each leg's two rods run between the frames the
family's xacro puts at the ball centres (``leg{i}_rod_top_a/b`` on the elbow,
``platform_ball{i}_a/b`` on the platform). At a closed configuration the two rods of a leg are
parallel, as long as the forearm, and ``rod_spacing`` apart.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from pinarms.robots.delta.geometry import LEG_COUNT, leg_frames
from pinarms.robots.delta.model import DeltaRobot

__all__ = ["rod_endpoints"]


def rod_endpoints(delta: DeltaRobot, q) -> np.ndarray:
    """Ball centres [m] of every rod at configuration(s) ``q``: shape (3 legs, 2 rods, 2 ends, 3) for one
    ``q`` (nq,), (N, 3, 2, 2, 3) for a batch; end 0 at the elbow, end 1 at the platform."""
    qs = np.atleast_2d(np.asarray(q, dtype=float))
    model, data = delta.model, delta.model.createData()
    ids = [[(model.getFrameId(leg_frames(i)[f"top_{r}"]), model.getFrameId(leg_frames(i)[f"bottom_{r}"]))
            for r in "ab"] for i in range(1, LEG_COUNT + 1)]
    out = np.empty((len(qs), LEG_COUNT, 2, 2, 3))
    for n, qn in enumerate(qs):
        pin.framesForwardKinematics(model, data, qn)
        for i, leg in enumerate(ids):
            for r, ends in enumerate(leg):
                for e, fid in enumerate(ends):
                    out[n, i, r, e] = data.oMf[fid].translation
    return out[0] if np.ndim(q) == 1 else out
