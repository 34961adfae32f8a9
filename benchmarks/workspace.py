"""Workspace sampling: pinarms' batched evaluation beside a Pinocchio per-sample loop.

Work measured (AUBO-i3, frame tcp): draw N joint vectors, compute each sample's tcp
position and the position manipulability sqrt(det(J_v J_vᵀ)) and inverse condition of
its Jacobian, then the summary (bounding box, outer-hull sphere fit, radial profile,
near-singular share).

The Pinocchio loop does the same per sample (framesForwardKinematics,
computeFrameJacobian, numpy det/SVD of the 3×nq block). It is timed on a subset of
LOOP_SUBSET samples and extrapolated linearly to N (the loop's cost per sample is
constant), which is printed as such.

Run: python benchmarks/workspace.py [N]
"""

from __future__ import annotations

import resource
import sys
import time

import numpy as np
import pinocchio as pin

from pinarms import robots
from pinarms.robots.reach.workspace import sample_workspace

LOOP_SUBSET = 20_000
TARGET_S = 3.0


def pinocchio_loop(robot, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    model = robot.model
    data = model.createData()
    fid = robot.frame_id("tcp")
    qp = robot.q_to_pinocchio(q)
    pts = np.empty((q.shape[0], 3))
    w = np.empty(q.shape[0])
    c = np.empty(q.shape[0])
    for k in range(q.shape[0]):
        pin.framesForwardKinematics(model, data, qp[k])
        pts[k] = data.oMf[fid].translation
        Jv = pin.computeFrameJacobian(model, data, qp[k], fid, pin.LOCAL_WORLD_ALIGNED)[:3]
        s = np.linalg.svd(Jv, compute_uv=False)
        w[k] = np.prod(s)
        c[k] = s[-1] / s[0]
    return pts, w, c


def main(n: int = 1_000_000) -> None:
    arm = robots.load("aubo_i3")
    sample_workspace(arm, n=20_000, seed=1).summary()  # warm-up (threads, caches)

    t0 = time.perf_counter()
    ws = sample_workspace(arm, n=n, seed=0)
    t1 = time.perf_counter()
    summary = ws.summary()
    t2 = time.perf_counter()
    ours = t2 - t0

    sub = min(LOOP_SUBSET, n)
    t3 = time.perf_counter()
    pts, w, c = pinocchio_loop(arm, ws.q[:sub])
    t4 = time.perf_counter()
    loop = (t4 - t3) * n / sub
    assert np.allclose(pts, ws.points[:sub], atol=1e-12)
    assert np.allclose(w, ws.manipulability[:sub], rtol=1e-9, atol=1e-12)

    print(f"workspace of aubo_i3 (tcp), N = {n:,} samples with manipulability and summary")
    print(f"  pinarms (batched numpy, threads)  : {ours:7.3f} s  (sampling {t1 - t0:.3f} s + summary {t2 - t1:.3f} s)"
          f"   target <= {TARGET_S:.0f} s: {'met' if ours <= TARGET_S else 'MISSED'}")
    print(f"  Pinocchio per-sample loop         : {loop:7.1f} s  (timed on {sub:,} samples: {t4 - t3:.2f} s, "
          f"extrapolated x{n / sub:g}; summary not included)")
    print(f"  ratio loop / pinarms              : {loop / ours:7.1f}x")
    print(f"  result arrays                     : {(ws.q.nbytes + ws.points.nbytes + 2 * ws.manipulability.nbytes) / 1e6:.0f} MB"
          f"; peak resident memory of this process: {resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.0f} MB")
    print()
    print(summary.text())


if __name__ == "__main__":
    main(int(float(sys.argv[1])) if len(sys.argv) > 1 else 1_000_000)
