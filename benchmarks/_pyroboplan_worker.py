"""Run pyroboplan's RRT-Connect on queries given as JSON on stdin; print results as JSON.

Runs in pyroboplan's own virtual environment (pyroboplan pins pin 4.0.0, pinarms needs
pin >= 4.1): benchmarks/planning.py starts it with that environment's Python. Input::

    {"urdf": "<cell URDF text>", "pairs": [["geom_a", "geom_b"], ...], "padding": 0.01,
     "step": 0.05, "time_limit": 1.0, "seed": 0, "shortcut": true,
     "queries": [{"start": [...], "goal": [...]}, ...], "columns": [0, 1, ...]}

``columns``: where the planned joints sit in the model's configuration vector (the other
coordinates stay at ``hold``). Output: one record per query (``ok``, ``seconds``,
``length``, ``shortcut_length``, ``shortcut_seconds``).
"""

import contextlib
import json
import sys
import time

import numpy as np
import pinocchio as pin


def main() -> None:
    job = json.load(sys.stdin)
    from pyroboplan.planning.rrt import RRTPlanner, RRTPlannerOptions

    try:
        from pyroboplan.planning.path_shortcutting import shortcut_path
    except ImportError:  # pragma: no cover - older pyroboplan
        shortcut_path = None
    model = pin.buildModelFromXML(job["urdf"])
    gm = pin.buildGeomFromUrdfString(model, job["urdf"], pin.GeometryType.COLLISION)
    gm.removeAllCollisionPairs()
    for a, b in job["pairs"]:
        gm.addCollisionPair(pin.CollisionPair(gm.getGeometryId(a), gm.getGeometryId(b)))
    cols = np.asarray(job["columns"], dtype=int)
    hold = np.asarray(job["hold"], dtype=float)
    # pyroboplan plans in the model's whole configuration: freeze what is not planned by
    # giving those joints a zero-width range (its sampler draws within the limits)
    lower, upper = model.lowerPositionLimit.copy(), model.upperPositionLimit.copy()
    others = np.setdiff1d(np.arange(model.nq), cols)
    lower[others] = hold[others]
    upper[others] = hold[others]
    model.lowerPositionLimit, model.upperPositionLimit = lower, upper
    out = []
    for k, query in enumerate(job["queries"]):
        q0, q1 = hold.copy(), hold.copy()
        q0[cols] = query["start"]
        q1[cols] = query["goal"]
        options = RRTPlannerOptions(max_step_size=job["step"], rrt_connect=True, bidirectional_rrt=True,
                                    max_planning_time=job["time_limit"], rng_seed=job["seed"] + k,
                                    collision_distance_padding=job["padding"], fast_return=True)
        planner = RRTPlanner(model, gm, options=options)
        t0 = time.perf_counter()
        try:
            with contextlib.redirect_stdout(sys.stderr):  # pyroboplan prints its progress
                path = planner.plan(q0, q1)
        except Exception as exc:  # noqa: BLE001 - one failing query must not end the run
            path, error = None, f"{type(exc).__name__}: {exc}"
        else:
            error = None
        seconds = time.perf_counter() - t0
        # on a timeout pyroboplan's RRT returns [] (not None)
        ok = path is not None and len(path) > 0
        rec = {"ok": ok, "seconds": seconds, "timeout": path is not None and not ok}
        if error:
            rec["error"] = error
        if ok:
            P = np.asarray(path)[:, cols]
            rec["length"] = float(np.linalg.norm(np.diff(P, axis=0), axis=1).sum())
            if job.get("shortcut") and shortcut_path is not None:
                t0 = time.perf_counter()
                try:
                    with contextlib.redirect_stdout(sys.stderr):
                        short = shortcut_path(model, gm, path, max_step_size=job["step"])
                except Exception as exc:  # noqa: BLE001
                    rec["shortcut_error"] = f"{type(exc).__name__}: {exc}"
                else:
                    rec["shortcut_seconds"] = time.perf_counter() - t0
                    S = np.asarray(short)[:, cols]
                    rec["shortcut_length"] = float(np.linalg.norm(np.diff(S, axis=0), axis=1).sum())
        out.append(rec)
    json.dump({"pin": pin.__version__, "results": out}, sys.stdout)


if __name__ == "__main__":
    main()
