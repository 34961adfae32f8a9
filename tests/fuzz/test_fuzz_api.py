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
                               st.text(max_size=6), st.sampled_from(list(planning.definition.KINDS))),
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
    result, err = outcome(optim.minimize_time, positions, kind, *limits, **kwargs, seconds=30)
    if err is None:
        assert np.all(np.asarray(result.durations) > 0)
