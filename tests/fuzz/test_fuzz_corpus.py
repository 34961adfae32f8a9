"""Regression corpus: every failure the fuzz suite found, replayed as an explicit case.

Each entry is a call that once raised something other than a named PinarmsError (or
returned NaN, or warned about silently dropped data) and the error it must raise now.
"""

from __future__ import annotations

import numpy as np
import pytest

from fuzz_support import outcome
from pinarms import optim, planning, robots, viz
from pinarms.optim.errors import InvalidLimits
from pinarms.planning.errors import TrajectoryError
from pinarms.errors import InvalidInput, ModelError

_ur5 = None


def ur5():
    global _ur5
    if _ur5 is None:
        _ur5 = robots.load("ur5")
    return _ur5


_MQ = {"kind": "multi_quintic", "times": [0.0, 0.5, 1.0], "positions": [[0.0], [1.0], [0.5]],
       "velocities": None, "accelerations": None}


def _deep(n):
    d = _MQ
    for _ in range(n):
        d = {"kind": "scaled", "factor": 1.0, "base": d}
    return d


_C = np.zeros(6, dtype=complex)
_TWO = ('<robot name="r"><link name="a"/><link name="b"/><joint name="j" type="revolute"><parent link="a"/>'
        '<child link="b"/><axis xyz="0 0 1"/><limit lower="{lo}" upper="{hi}" effort="1" velocity="{v}"/></joint></robot>')

CORPUS = [
    # (id, call, expected error type, message fragment)
    ("definition-kind-unhashable", lambda: planning.from_definition(dict(_MQ, kind=[])), TrajectoryError,
     "unknown trajectory kind"),
    ("definition-nested-10000", lambda: planning.from_definition(_deep(10_000)), TrajectoryError, "nest deeper"),
    ("definition-parts-not-a-list", lambda: planning.from_definition({"kind": "concatenated", "parts": "ab"}),
     TrajectoryError, "non-empty 'parts' list"),
    ("trajectory-complex-times", lambda: planning.multi_quintic(np.array([0, 1, 2], dtype=complex), [0.0, 1.0, 0.0]),
     TrajectoryError, "real"),
    ("trajectory-sample-complex", lambda: planning.multi_quintic([0.0, 1.0], [0.0, 1.0]).sample(_C), TrajectoryError,
     "real"),
    ("scaled-overflow", lambda: planning.multi_quintic([0.0, 1.0], [0.0, 1.0]).scaled(1e300), TrajectoryError,
     "beyond"),
    ("scaled-underflow", lambda: planning.multi_quintic([0.0, 1.0], [0.0, 1.0]).scaled(5e-324), TrajectoryError,
     "beyond float64"),
    ("trapezoidal-amax-1e300", lambda: planning.trapezoidal([0.0], [1.0], 1.0, 1e300), None, None),
    ("trapezoidal-vmax-5e-324", lambda: planning.trapezoidal([0.0], [1.0], 5e-324, 1.0), TrajectoryError,
     "would last"),
    ("trapezoidal-amax-5e-324", lambda: planning.trapezoidal([0.0], [1.0], 1.0, 5e-324), TrajectoryError,
     "would last"),
    ("double-s-vmax-1.8e-198", lambda: planning.double_s([0.0], [1.0], 1.8e-198, 1.0, 1.0), TrajectoryError,
     "would last"),
    ("robot-fk-complex", lambda: ur5().fk(_C), InvalidInput, "real"),
    ("robot-within-limits-complex", lambda: ur5().within_limits(_C), InvalidInput, "real"),
    ("robot-ik-complex-target", lambda: ur5().ik_all(np.eye(4, dtype=complex)), InvalidInput, "real"),
    ("robot-ik-empty-seed-batch", lambda: ur5().ik(ur5().fk(ur5().neutral), np.zeros((0, 6))), InvalidInput,
     "q_seed"),
    ("random-q-1e15", lambda: ur5().random_q(10**15), InvalidInput, "more than 50,000,000"),
    ("workspace-1e15", lambda: robots.sample_workspace(ur5(), 10**15), InvalidInput, "more than 50,000,000"),
    ("minimize-time-complex-limit", lambda: optim.minimize_time(optim.TimingRequest([[0.0] * 6, [1.0] * 6], "multi-quintic", _C)),
     InvalidLimits, "not numeric"),
    ("minimize-time-vmax-5e-324", lambda: optim.minimize_time(optim.TimingRequest([[0.0], [1.0]], "multi-quintic", 5e-324)),
     InvalidLimits, "outside [1e-09, 1e+12]"),
    ("urdf-mimic-multiplier-0", lambda: robots.from_urdf_text(
        '<robot name="r"><link name="a"/><link name="b"/><link name="c"/>'
        '<joint name="j0" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/>'
        '<limit lower="0" upper="1" effort="1" velocity="1"/></joint>'
        '<joint name="j1" type="revolute"><parent link="b"/><child link="c"/><axis xyz="0 0 1"/>'
        '<limit lower="0" upper="1" effort="1" velocity="1"/><mimic joint="j0" multiplier="0"/></joint></robot>'),
     ModelError, "non-zero multiplier"),
    ("urdf-not-a-string", lambda: robots.from_urdf_text(None), InvalidInput, "string"),
    ("urdf-lower-above-upper", lambda: robots.from_urdf_text(_TWO.format(lo=1, hi=-1, v=1)), ModelError, "swap"),
    ("urdf-negative-velocity", lambda: robots.from_urdf_text(_TWO.format(lo=-1, hi=1, v=-2)), ModelError,
     "velocity"),
    ("urdf-internal-entity", lambda: robots.from_urdf_text(
        '<!DOCTYPE robot [<!ENTITY n "b">]>' + _TWO.format(lo=-1, hi=1, v=1).replace('child link="b"', 'child link="&n;"')),
     ModelError, "entit"),
    ("jacobian-1-dof-batch", lambda: robots.from_urdf_text(_TWO.format(lo=-1, hi=1, v=1)).jacobian(np.zeros((3, 1))),
     None, None),
    ("urdf-joint-to-undefined-link", lambda: robots.from_urdf_text(_TWO.format(lo=-1, hi=1, v=1).replace(
        'child link="b"', 'child link="zzz"')), ModelError, "not defined"),
    ("urdf-duplicate-link", lambda: robots.from_urdf_text(_TWO.format(lo=-1, hi=1, v=1).replace(
        '<link name="b"/>', '<link name="b"/><link name="b"/>')), ModelError, "defined twice"),
    ("session-metadata-not-a-mapping", lambda: viz.Session(metadata=True), InvalidInput, "mapping"),
    ("session-metadata-lone-surrogate", lambda: viz.Session(metadata={"k": "\ud800"}), InvalidInput, "JSON-able"),
    ("session-points-complex", lambda: viz.Session().add_points("p", np.zeros((1, 3), complex)), InvalidInput,
     "real"),
    ("session-save-nul", lambda: viz.Session().save("a\x00b.pinarms"), InvalidInput, "not a file name"),
    ("session-save-int", lambda: viz.Session().save(3), InvalidInput, "path"),
]


@pytest.mark.parametrize("call, error, fragment", [c[1:] for c in CORPUS], ids=[c[0] for c in CORPUS])
def test_corpus(call, error, fragment):
    result, err = outcome(call)
    if error is None:
        assert err is None, err
        return
    assert isinstance(err, error), err
    assert fragment in str(err), str(err)
