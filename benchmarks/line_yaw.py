"""Task maps and the item's yaw on a 6-axis arm with a slow wrist: the Kinova Jaco2 (example-robot-data).

One Jaco2 (j2s6s200, tool point ``j2s6s200_end_effector``, wrist joints 0.84 rad/s) 0.4 m beside
a 0.3 m belt at 0.1 m/s, its base at the belt's height, its box at (-0.1, +0.25, +0.15) m from its
base, tracking descend 0.6 s. Its task map is built with ``yaw="auto"`` (NU x NW grid over du in
[-0.3, 0.3] m, YAW_NODES yaw nodes, YAW_REFINE passes, serial) and compared with exact planning at
N random picks at random yaw (seed 3): once as built (a yaw coordinate) and once as the same map's
yaw-0 layer alone (what the maps were before: no yaw coordinate). Prints each map error with its
figures per bin of tool yaw, and the build time.

Run: python benchmarks/line_yaw.py [NU NW YAW_NODES YAW_REFINE N]   (default 8 4 9 1 30)
"""

from __future__ import annotations

import sys
import time

import numpy as np


def main(nu: int = 8, nw: int = 4, nodes: int = 9, refine: int = 1, n: int = 30) -> None:
    from pinarms import robots
    from pinarms.optim.line import (Belt, PlaceBox, Station, TaskMap, TrackingSpec, base_pose, build_task_map,
                                    map_error)
    from pinarms.robots.registry import example_robot_data_share

    share = example_robot_data_share()
    jaco = robots.from_urdf(share / "robots/kinova_description/robots/kinova.urdf", tcp="j2s6s200_end_effector",
                            package_dirs=(str(share.parent),))
    belt = Belt((0.0, 0.0, 0.80), speed=0.1, width=0.3, length=2.0)
    station = Station("jaco", jaco, base_pose(1.0, 0.40, 0.80), PlaceBox((0.9, 0.65, 0.95), "box"))
    spec = TrackingSpec(descend=0.6)
    start = time.perf_counter()
    m = build_task_map(station, belt, spec, nu=nu, nw=nw, du_range=(-0.3, 0.3), yaw_nodes=nodes, yaw_refine=refine)
    print(f"{m}\nbuilt in {time.perf_counter() - start:.1f} s; yaw nodes [deg]: "
          f"{np.round(np.degrees(m.yaw), 1).tolist() if m.yaw is not None else None}")
    flat = TaskMap(m.station, m.du, m.w, m.approach, m.leave, m.track, m.release, m.speed, m.mass, 0.0, m.branches,
                   m.branch_approach, m.branch_leave)
    for name, one in (("without a yaw coordinate (before)", flat), ("with its yaw coordinate (after)", m)):
        err = map_error(one, station, belt, spec, n=n, seed=3)
        print(f"{name}: {err}\n{err.table(6)}")


if __name__ == "__main__":
    main(*(int(a) for a in sys.argv[1:6]))
