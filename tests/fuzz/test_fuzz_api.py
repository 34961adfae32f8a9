"""Random arguments to the public API: a named PinarmsError or a finite answer, never another exception.

Covers Robot.fk / position / jacobian / manipulability / ik / ik_all, sample_workspace,
the trajectory constructors (and sampling what they build), from_definition with
mutated definitions, and optim.minimize_time. Each call is bounded in time.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from fuzz_support import EXPLORE, outcome
from pinarms import optim, planning, robots
from pinarms.planning import definition as planning_definition
from pinarms.errors import PinarmsError

ARMS = ("ur5", "scara_mushroom", "gantry_flower", "koji_turner")


@pytest.fixture(scope="module")
def arms():
    return {name: robots.load(name) for name in ARMS}


# ---------------------------------------------------------------------------- values
_floats = st.one_of(
    st.floats(-10, 10, allow_nan=False),
    st.sampled_from([np.nan, np.inf, -np.inf, 0.0, -0.0, 1e300, -1e300, 5e-324, 1e-12]),
)
_scalars = st.one_of(_floats, st.integers(-3, 3), st.booleans(), st.none(), st.just("1.0"), st.just("tcp"),
                     st.just(1 + 2j), st.just(b"x"), st.just(object()))


def _arrays(shapes=st.lists(st.integers(0, 7), min_size=0, max_size=3)):
    return shapes.flatmap(lambda s: st.lists(_floats, min_size=int(np.prod(s)), max_size=int(np.prod(s)))
                          .map(lambda v, s=s: np.array(v, dtype=float).reshape(s)))


_weird = st.one_of(
    _scalars,
    _arrays(),
    st.lists(_scalars, max_size=7),
    st.lists(st.lists(_floats, max_size=7), max_size=4),     # ragged
    st.just(np.zeros((2, 3), dtype=object)),
    st.just(np.array(["a", "b"])),
    st.just(np.zeros(6, dtype=np.int64)),
    st.just(np.zeros(6, dtype=bool)),
    st.just(np.zeros(6, dtype=np.complex128)),
    st.just({"q": 1}),
)


def usually(valid, odd):
    """``valid`` three times in four: hostile values everywhere would stop every call at its first argument."""
    return st.one_of(valid, valid, valid, odd)


class Plan:
    """Which arguments of one call are hostile: none (2/5), exactly one (2/5), or any (1/5).

    Drawing every argument hostile at random would stop nearly every call at its first
    check; this way each check is reached alone, and valid calls run to the end.
    """

    def __init__(self, data, names):
        self.data = data
        mode = data.draw(st.sampled_from(["valid", "one", "valid", "one", "any"]), label="plan")
        if mode == "one":
            self.odd = {data.draw(st.sampled_from(names), label="hostile argument")}
        elif mode == "any":
            self.odd = {n for n in names if data.draw(st.booleans(), label=f"{n} hostile")}
        else:
            self.odd = set()

    def __call__(self, name, valid, odd):
        return self.data.draw(odd if name in self.odd else valid, label=name)


def _q_for(robot, data):
    """A joint argument: mostly right-sized (finite, inside, outside the limits, NaN), sometimes anything."""
    kind = data.draw(st.sampled_from(["inside", "outside", "batch", "weird", "nan"]))
    if kind == "inside":
        return robot.random_q(1, seed=data.draw(st.integers(0, 10**6)))[0]
    if kind == "outside":
        return data.draw(st.lists(st.floats(-100, 100), min_size=robot.nq, max_size=robot.nq).map(np.array))
    if kind == "batch":
        n = data.draw(st.integers(0, 5))
        return robot.random_q(max(n, 1), seed=1)[:n]
    if kind == "nan":
        q = robot.neutral.copy()
        q[data.draw(st.integers(0, robot.nq - 1))] = data.draw(st.sampled_from([np.nan, np.inf, -np.inf]))
        return q
    return data.draw(_weird)


_frames = st.one_of(st.just("tcp"), st.text(max_size=12), st.none(), st.integers(), st.just("base_link"))


# ---------------------------------------------------------------------------- robots
@settings(max_examples=150 * EXPLORE)
@given(data=st.data(), arm=st.sampled_from(ARMS),
       method=st.sampled_from(["fk", "position", "jacobian", "manipulability", "fk_pinocchio", "within_limits",
                               "q_to_pinocchio"]))
def test_kinematics_arguments(arms, data, arm, method):
    robot = arms[arm]
    q = _q_for(robot, data)
    args = [q]
    if method in ("fk", "position", "jacobian", "manipulability", "fk_pinocchio") and data.draw(st.booleans()):
        args.append(data.draw(_frames))
    result, err = outcome(getattr(robot, method), *args)
    if err is None and method in ("fk", "position", "jacobian", "manipulability"):
        assert np.all(np.isfinite(result)), f"{method} returned a non-finite value for {q!r}"


def _targets(robot, data):
    kind = data.draw(st.sampled_from(["reachable", "far", "position", "weird", "nonrigid", "nan"]))
    if kind == "reachable":
        return robot.fk(robot.random_q(1, seed=data.draw(st.integers(0, 10**6)))[0])
    if kind == "far":
        T = np.eye(4)
        T[:3, 3] = data.draw(st.lists(st.floats(-50, 50), min_size=3, max_size=3))
        return T
    if kind == "position":
        return np.array(data.draw(st.lists(st.floats(-2, 2), min_size=3, max_size=3)))
    if kind == "nonrigid":
        return np.diag([2.0, 1.0, 1.0, 1.0])
    if kind == "nan":
        T = np.eye(4)
        T[data.draw(st.integers(0, 2)), 3] = np.nan
        return T
    return data.draw(_weird)


@settings(max_examples=80 * EXPLORE)
@given(data=st.data(), arm=st.sampled_from(ARMS), method=st.sampled_from(["ik", "ik_all", "ik_branches"]))
def test_ik_arguments(arms, data, arm, method):
    robot = arms[arm]
    target = _targets(robot, data)
    kwargs = {}
    if data.draw(st.booleans()):
        kwargs["q_seed" if method == "ik" else "q_ref"] = _q_for(robot, data)
    if method == "ik":
        if data.draw(st.booleans()):
            kwargs["tol"] = data.draw(st.one_of(_floats, _scalars))
        if data.draw(st.booleans()):
            kwargs["max_restarts"] = data.draw(st.one_of(st.integers(-2, 3), _scalars))
        if data.draw(st.booleans()):
            kwargs["position_only"] = data.draw(st.one_of(st.booleans(), _scalars))
        kwargs.setdefault("max_restarts", 3)  # bounded time on unreachable targets
    result, err = outcome(getattr(robot, method), target, **kwargs, seconds=20)
    if err is None and method == "ik" and isinstance(target, np.ndarray) and target.shape == (4, 4):
        assert robot.within_limits(result, tol=1e-6)


@settings(max_examples=40 * EXPLORE)
@given(data=st.data(), arm=st.sampled_from(ARMS))
def test_sample_workspace_arguments(arms, data, arm):
    arg = Plan(data, ["n", "seed", "frame", "chunk"])
    n = arg("n", st.integers(1, 300), st.one_of(st.integers(-2, 0), _scalars, st.just(10**15)))
    seed = arg("seed", st.integers(0, 2**63), st.one_of(st.integers(-2, -1), st.just(2**64), _scalars))
    frame = arg("frame", st.sampled_from(["tcp", *arms[arm].frame_names[:3]]), _frames)
    chunk = arg("chunk", st.integers(1, 50), st.one_of(st.integers(-1, 0), _scalars))
    ws, err = outcome(robots.sample_workspace, arms[arm], n, seed=seed, frame=frame, chunk=chunk)
    if err is None:
        assert np.all(np.isfinite(ws.points)) and np.all(ws.manipulability >= 0)


# ---------------------------------------------------------------------------- trajectories
_times_valid = st.lists(st.floats(0.01, 3), min_size=1, max_size=5).map(lambda h: np.concatenate([[0.0], np.cumsum(h)]))
_times_odd = st.one_of(st.lists(st.floats(-1, 10, allow_nan=False), min_size=0, max_size=6).map(sorted).map(np.array),
                       _weird)
_times = usually(_times_valid, _times_odd)
_finite = st.floats(-3, 3)


def _positions(data, n_points):
    if n_points and data.draw(st.integers(0, 3)):
        nj = data.draw(st.integers(1, 3))
        values = usually(_finite, _floats)
        return np.array(data.draw(st.lists(st.lists(values, min_size=nj, max_size=nj), min_size=n_points,
                                           max_size=n_points)))
    return data.draw(_weird)


def _sample_all(traj, data):
    """Sample what a constructor built, inside and outside its time range."""
    t0, t1 = float(traj.knot_times[0]), float(traj.knot_times[-1])
    t = np.array(data.draw(st.lists(st.floats(t0, t1), min_size=1, max_size=5)))
    out, err = outcome(traj.sample, t)
    assert err is None, f"sampling inside [{t0}, {t1}] failed: {err}"
    outcome(traj.sample, data.draw(st.one_of(_weird, st.just(np.array([t1 + 1.0])))))
    outcome(traj.scaled, data.draw(st.one_of(_floats, _scalars)))
    outcome(traj.shifted, data.draw(st.one_of(_floats, _scalars)))
    outcome(traj.check_limits, planning.JointLimits(velocity=1.0)) if hasattr(traj, "check_limits") else None


@settings(max_examples=150 * EXPLORE)
@given(data=st.data(), ctor=st.sampled_from(["polynomial", "piecewise_polynomial", "multi_quintic",
                                             "quintic_bspline", "trapezoidal", "double_s"]))
def test_trajectory_constructors(data, ctor):
    if ctor in ("trapezoidal", "double_s"):
        names = ["q0", "q1", "vmax", "amax", "jmax", "synchronized"][: 5 if ctor == "trapezoidal" else 6]
        names = [n for n in names if n != "jmax" or ctor == "double_s"]
        arg = Plan(data, names)
        nj = data.draw(st.integers(1, 3))
        odd = st.one_of(st.lists(_floats, min_size=nj, max_size=nj).map(np.array), _floats, _weird)
        ends = st.lists(_finite, min_size=nj, max_size=nj).map(np.array)
        limit = st.one_of(st.floats(0.05, 20), st.lists(st.floats(0.05, 20), min_size=nj, max_size=nj))
        args = [arg("q0", ends, odd), arg("q1", ends, odd)]
        args += [arg(k, limit, odd) for k in ("vmax", "amax", "jmax") if k in names]
        kwargs = {"synchronized": arg("synchronized", st.booleans(), _scalars)}
    else:
        arg = Plan(data, ["times", "positions", "extra"])
        times = arg("times", _times_valid, _times_odd)
        n = len(times) if isinstance(times, np.ndarray) and times.ndim == 1 else data.draw(st.integers(0, 5))
        nj = data.draw(st.integers(1, 3))
        rows = st.lists(st.lists(_finite, min_size=nj, max_size=nj), min_size=n, max_size=n).map(np.array)
        args = [times, arg("positions", rows, st.one_of(
            st.lists(st.lists(_floats, min_size=nj, max_size=nj), min_size=n, max_size=n).map(np.array), _weird))]
        kwargs = {}
        if ctor == "polynomial":
            args.append(arg("extra", st.integers(max(n - 1, 1), 7), st.one_of(st.integers(-1, 12), _scalars)))
        elif ctor == "piecewise_polynomial":
            m = max(n - 1, 1)
            args.append(arg("extra", st.sampled_from(["3-5-3", "4-3-4", "cubic", "quintic", (3, 5, 3)]),
                            st.one_of(st.lists(st.integers(-1, 8), min_size=m, max_size=m), st.just("?"), _scalars)))
            if data.draw(st.booleans()):
                kwargs = {"continuity": arg("extra", st.integers(1, 2), st.one_of(st.integers(-1, 4), _scalars)),
                          "end_order": arg("extra", st.integers(1, 2), st.one_of(st.integers(-1, 4), _scalars))}
        elif ctor == "multi_quintic" and data.draw(st.booleans()):
            args += [arg("extra", st.just(None), _weird), arg("extra", st.just(None), _weird)]
        elif ctor == "quintic_bspline" and data.draw(st.booleans()):
            kwargs = {"start_velocity": arg("extra", st.floats(-1, 1), st.one_of(_floats, _weird))}
    traj, err = outcome(getattr(planning, ctor), *args, **kwargs)
    if err is None:
        _sample_all(traj, data)


def _valid_definitions():
    q = np.array([[0.0, 0.1], [0.5, -0.2], [1.0, 0.3], [0.2, 0.0]])
    t = np.array([0.0, 1.0, 2.5, 3.0])
    mq = planning.multi_quintic(t, q)
    return [
        planning.polynomial(t[:2], q[:2], 5).definition,
        planning.piecewise_polynomial(t, q).definition,
        mq.definition,
        planning.quintic_bspline(t, q).definition,
        planning.trapezoidal(q[0], q[1], 1.0, 2.0).definition,
        planning.double_s(q[0], q[1], 1.0, 2.0, 10.0).definition,
        mq.scaled(2.0).shifted(1.0).definition,
        mq.concatenated(planning.multi_quintic(t + 3.0, q[::-1])).definition,
    ]


DEFINITIONS = _valid_definitions()


def _def_paths(obj, prefix=()):
    if prefix:
        yield prefix
    if isinstance(obj, dict):
        for k, v in obj.items():
            yield from _def_paths(v, prefix + (k,))
    elif isinstance(obj, list):
        for i, v in enumerate(obj):
            yield from _def_paths(v, prefix + (i,))


_json = st.recursive(st.one_of(st.none(), st.booleans(), st.integers(-5, 10**6), st.floats(-1e3, 1e3),
                               st.text(max_size=6), st.sampled_from(list(planning_definition.KINDS))),
                     lambda c: st.one_of(st.lists(c, max_size=4), st.dictionaries(st.text(max_size=6), c, max_size=3)),
                     max_leaves=8)


@settings(max_examples=200 * EXPLORE)
@given(data=st.data(), which=st.integers(0, len(DEFINITIONS) - 1))
@example(data=None, which=-1)  # kind as a list (unhashable) once crashed from_definition
@example(data=None, which=-2)  # derived definitions nested 10 000 deep
def test_from_definition_mutated(data, which):
    if which == -1:
        d = dict(DEFINITIONS[2], kind=[])
    elif which == -2:
        d = DEFINITIONS[2]
        for _ in range(10_000):
            d = {"kind": "scaled", "factor": 1.0, "base": d}
    else:
        d = json.loads(json.dumps(DEFINITIONS[which]))
        paths = list(_def_paths(d))
        for _ in range(data.draw(st.integers(1, 3))):
            path = data.draw(st.sampled_from(paths))
            parent = d
            try:
                for k in path[:-1]:
                    parent = parent[k]
                if data.draw(st.booleans()):
                    parent[path[-1]] = data.draw(_json)
                elif isinstance(parent, dict):
                    del parent[path[-1]]
            except (KeyError, IndexError, TypeError):
                pass
    traj, err = outcome(planning.from_definition, d)
    if err is None and data is not None:
        _sample_all(traj, data)


# ---------------------------------------------------------------------------- optim
@settings(max_examples=40 * EXPLORE)
@given(data=st.data())
def test_minimize_time_arguments(data):
    arg = Plan(data, ["positions", "kind", "vmax", "amax", "jmax", "method", "seed", "max_generations", "time_limit"])
    kind = arg("kind", st.sampled_from(["3-5-3", "multi-quintic", "quintic-bspline"]),
               st.sampled_from(["4-3-4", "", None, 3]))
    n = 4 if kind == "3-5-3" else data.draw(st.integers(2, 5))
    nj = data.draw(st.integers(1, 3))
    positions = arg("positions", st.lists(st.lists(_finite, min_size=nj, max_size=nj), min_size=n, max_size=n)
                    .map(np.array), st.one_of(_weird, st.just(np.zeros((n, nj)))))
    limit = st.one_of(st.floats(0.1, 5), st.lists(st.floats(0.1, 5), min_size=nj, max_size=nj))
    limits = [arg(k, limit, st.one_of(_floats, _weird)) for k in ("vmax", "amax", "jmax")]
    if data.draw(st.booleans()):
        limits[2] = None
    kwargs = dict(method=arg("method", st.sampled_from(["ga", "exact"]), st.sampled_from(["simplex", None])),
                  seed=arg("seed", st.integers(0, 5), _scalars),
                  max_generations=arg("max_generations", st.integers(1, 3), _scalars),
                  # a wall-clock limit would make the answer depend on the machine's load: only its checks are fuzzed
                  time_limit=arg("time_limit", st.sampled_from([None, 600.0]), _scalars))
    def minimize(*args, **keywords):  # the request is checked when built, the call runs it
        return optim.minimize_time(optim.TimingRequest(*args, **keywords))

    result, err = outcome(minimize, positions, kind, *limits, **kwargs, seconds=30)
    if err is None:
        assert np.all(np.asarray(result.durations) > 0)


# ---------------------------------------------------------------------------- planning and cycle settings
# Seeded random settings (optim.caps): each call returns a valid result or raises a named
# PinarmsError within its time bound: never a MemoryError, an OverflowError, a hang.
_PICK, _PLACE = [0.30, 0.25, 0.10], [-0.20, 0.35, 0.08]
_huge_or_tiny = st.sampled_from([0, -1, 10**9, 10**18, 2**70, 1e-300, 5e-324, 1e300, np.nan, np.inf, -np.inf])
_odd_setting = st.one_of(_huge_or_tiny, _scalars)


@settings(max_examples=15 * EXPLORE)
@given(data=st.data())
def test_plan_cycle_settings(arms, data):
    robot = arms["scara_mushroom"]
    arg = Plan(data, ["lift", "dwell", "kind", "vmax", "amax", "jmax", "tool_speed", "approach", "seed"])
    spec, err = outcome(optim.PickPlace, _PICK, _PLACE, lift=arg("lift", st.floats(0.01, 0.08), _odd_setting),
                        dwell=arg("dwell", st.floats(0.0, 1.0), _odd_setting))
    if err is not None:
        return
    limit = st.floats(0.5, 5.0).map(lambda k: k * robot.velocity_limit)
    timing = dict(
        kind=arg("kind", st.sampled_from(["multi-quintic", "quintic-bspline", "3-5-3"]), _odd_setting),
        vmax=arg("vmax", limit, st.one_of(_odd_setting, _weird)),
        amax=arg("amax", st.one_of(st.none(), limit.map(lambda v: 4.0 * v)), st.one_of(_odd_setting, _weird)),
        jmax=arg("jmax", st.one_of(st.none(), limit.map(lambda v: 40.0 * v)), st.one_of(_odd_setting, _weird)),
        seed=arg("seed", st.integers(0, 5), _odd_setting),
    )
    approach = dict(approach=arg("approach", st.just("joint"), st.sampled_from(["straight", "curved", None])),
                    tool_speed=arg("tool_speed", st.one_of(st.none(), st.floats(0.1, 2.0)), _odd_setting))

    def plan_cycle() -> optim.CycleResult:  # the settings checked when the request is built, then planned
        request = optim.CycleRequest(robot, spec, timing=optim.CycleTiming(**timing),
                                     approach=optim.CycleApproach(**approach))
        return optim.plan_cycle(request)

    result, err = outcome(plan_cycle, seconds=30)
    if err is None and result.solved:
        assert result.cycle_time > 0 and np.isfinite(result.cycle_time)
    elif err is None:  # no cycle: a status saying why (bad input raised above)
        assert result.reason and isinstance(result.error, PinarmsError) and result.trajectory is None


@pytest.fixture(scope="module")
def line_cycles():
    from pinarms.robots.cell import load_cell

    cell = load_cell("mushroom_line")
    tasks = {"left": ((-0.05, -0.03, 0.84), (0.22, 0.68, 0.84)), "right": ((0.05, 0.03, 0.84), (0.22, -0.68, 0.84))}
    cycles = {}
    for name, (pick, place) in tasks.items():
        arm = cell.arm(name)
        spec = optim.PickPlace(arm.to_base(np.array(pick)), arm.to_base(np.array(place)), lift=0.09, dwell=0.15)
        cycles[name] = optim.plan_cycle(optim.CycleRequest(arm.robot, spec))
    return cell, cycles


@settings(max_examples=10 * EXPLORE)
@given(data=st.data())
def test_schedule_line_settings(line_cycles, data):
    cell, cycles = line_cycles
    arg = Plan(data, ["n_offsets", "margin", "clearance"])
    # valid scans of 2 offsets: a second when the first period clears, 22 checks when none does
    n_offsets = arg("n_offsets", st.just(2), st.one_of(_odd_setting, st.just(10**9)))
    margin = arg("margin", st.floats(0.01, 0.05), _odd_setting)
    clearance = arg("clearance", st.just(0.0), _odd_setting)
    result, err = outcome(optim.schedule_line, cell, cycles, n_offsets=n_offsets, margin=margin,
                          clearance=clearance, seconds=60)
    if err is None:
        assert result.period > 0 and set(result.offsets) == set(cycles)


def _layout_summary(*args, **kwargs):
    """search_layout's ranking (picks/min is 0 where a placement fails; its cycle time is NaN there by design)."""
    res = optim.search_layout(optim.LayoutRequest(*args, **kwargs))
    return res.failure, res.picks_per_minute, res.best_picks_per_minute, res.margin


@settings(max_examples=6 * EXPLORE)
@given(data=st.data())
def test_search_layout_settings(arms, data):
    robot = arms["scara_mushroom"]
    arg = Plan(data, ["axis", "refine", "refine_evaluations", "workspace_samples", "chunk_size", "min_margin", "n"])
    axis = arg("axis", st.just(0.0),  # one placement: one cycle per valid call
               st.one_of(st.tuples(st.just(0.0), st.sampled_from([1.0, 1e300]), _huge_or_tiny), _odd_setting))
    if data.draw(st.booleans(), label="random placements"):
        n = arg("n", st.just(1), st.one_of(_odd_setting, st.just(10**12)))
        bounds = axis if isinstance(axis, float) else (0.0, 0.05)
        cand, err = outcome(optim.random_candidates, n, x=bounds, y=0.0, seed=1)
    else:
        cand, err = outcome(optim.grid_candidates, x=axis, y=0.0)
    if err is not None:
        return
    kwargs = dict(refine=arg("refine", st.just(0), st.one_of(_odd_setting, st.just(10**9))),
                  refine_evaluations=arg("refine_evaluations", st.integers(1, 2), _odd_setting),
                  workspace_samples=arg("workspace_samples", st.just(1000), st.one_of(_odd_setting, st.just(10**15))),
                  chunk_size=arg("chunk_size", st.integers(1, 4), _odd_setting),
                  min_margin=arg("min_margin", st.floats(0.0, 0.01), _odd_setting))
    result, err = outcome(_layout_summary, robot, _PICK, _PLACE, cand, **kwargs, seconds=40)
    if err is None:
        assert len(result[0]) == len(cand)


@settings(max_examples=30 * EXPLORE)
@given(data=st.data(), which=st.sampled_from(["time_optimal", "time_scaled"]))
def test_path_timing_settings(data, which):
    path = planning.joint_spline(np.array([[0.0, 0.0], [0.5, 0.2], [1.0, -0.3]]))
    cons = [planning.JointVelocityConstraint(np.array([1.0, 1.5])),
            planning.JointAccelerationConstraint(np.array([4.0, 5.0]))]
    if which == "time_optimal":
        arg = Plan(data, ["grid", "max_rounds", "rtol", "kappa", "start_speed", "jerk"])
        kwargs = dict(grid=arg("grid", st.integers(2, 200), st.one_of(_odd_setting, st.just(10**9))),
                      max_rounds=arg("max_rounds", st.integers(0, 8), _odd_setting),
                      rtol=arg("rtol", st.floats(1e-4, 0.4), _odd_setting),
                      kappa=arg("kappa", st.floats(0.1, 1.0), _odd_setting),
                      start_speed=arg("start_speed", st.just(0.0), _odd_setting),
                      jerk=arg("jerk", st.one_of(st.none(), st.floats(10.0, 100.0)), st.one_of(_odd_setting, _weird)))
        result, err = outcome(optim.time_optimal, path, cons, **kwargs, seconds=20)
    else:
        arg = Plan(data, ["samples", "shape"])
        kwargs = dict(samples=arg("samples", st.integers(3, 3000), st.one_of(_odd_setting, st.just(10**10))),
                      shape=arg("shape", st.sampled_from(["quintic"]), st.one_of(st.text(max_size=5), _scalars)))
        result, err = outcome(optim.time_scaled, path, cons, **kwargs, seconds=20)
    if err is None:
        assert result.duration > 0 and np.isfinite(result.duration)


@settings(max_examples=30 * EXPLORE)
@given(data=st.data())
def test_ga_and_exact_settings(data):
    arg = Plan(data, ["population", "max_generations", "stall", "n_random", "maxiter", "polish"])
    settings_, err = outcome(optim.GASettings, population=arg("population", st.integers(4, 12), _odd_setting),
                             max_generations=arg("max_generations", st.integers(1, 5), _odd_setting),
                             stall_generations=arg("stall", st.one_of(st.none(), st.integers(1, 5)), _odd_setting))
    if err is None:
        result, err = outcome(lambda *args, **kwargs: optim.run_ga(optim.GARequest(*args, **kwargs)),
                              lambda x: np.sum(x * x, axis=1), [(-1.0, 1.0), (-1.0, 1.0)],
                              settings_, max_generations=arg("max_generations", st.integers(1, 5),
                                                             st.one_of(_odd_setting, st.just(10**12))))
        if err is None:
            assert np.isfinite(result.f)
    problem = optim.TimingProblem(np.array([[0.0], [1.0], [0.5]]), "multi-quintic", 2.0, 8.0)
    result, err = outcome(optim.solve_exact, problem, n_random=arg("n_random", st.integers(0, 2), _odd_setting),
                          maxiter=arg("maxiter", st.integers(1, 30), _odd_setting),
                          polish_evaluations=arg("polish", st.one_of(st.none(), st.integers(0, 50)), _odd_setting),
                          seconds=20)
    if err is None:
        assert result.total > 0
