"""A delta in a saved session: its actuated angles over time kept, its passive joints solved on load,
and the reader's refusals of a hostile file's delta (names, columns, range, assembly, sizes, pickle)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from pinarms.robots.delta import DeltaRobot, forward_position, load_delta
from pinarms.errors import InvalidInput
from pinarms.viz import SessionFormatError
from pinarms.viz.session import Session, SessionLimits, load_session
from session_files import document, npy_bytes, rewrite

KEY = "delta 1"


@pytest.fixture(scope="module")
def delta():
    return load_delta("delta_flexpicker")


def _motion(n: int = 31) -> tuple[np.ndarray, np.ndarray]:
    """1 s of motor angles inside the range and the tool turning by 1 rad: (t, actuated (n, 4))."""
    t = np.linspace(0.0, 1.0, n)
    th = 0.35 + 0.3 * np.sin(2 * np.pi * t[:, None] + np.array([0.0, 2.1, 4.2]))
    return t, np.column_stack([th, t])


@pytest.fixture(scope="module")
def saved(tmp_path_factory):
    s = Session(title="a delta")
    base = np.eye(4)
    base[:3, 3] = [1.0, 0.5, 1.9]
    s.add_delta("delta_flexpicker", key=KEY, base_to_world=base, motion=_motion())
    s.add_delta(load_delta("delta_flexpicker"), key="at rest")
    return s, s.save(tmp_path_factory.mktemp("delta") / "delta.pinarms")


def test_round_trip_keeps_the_motion_and_solves_the_chain(saved, delta):
    """Reloaded: equal to the saved session (arrays bit-equal); only actuated columns are stored; the
    platform from the closed form equals Pinocchio's projection of the closures (independent route)."""
    s, path = saved
    s2 = load_session(path)
    assert s2 == s
    rec = s2.deltas[KEY]
    assert rec.actuated.shape == (31, 4) and rec.delta == "delta_flexpicker"
    members = [m["member"] for m in (document(path)["deltas"][0][k] for k in ("t", "actuated", "base_to_world"))]
    assert members == ["arrays/deltas/0/t.npy", "arrays/deltas/0/actuated.npy", "arrays/deltas/0/base_to_world.npy"]
    q_closed = s2.delta(KEY).configuration(rec.theta, tool=0.0)
    q_proj = delta.project(rec.theta, chain=True)
    np.testing.assert_allclose(q_closed[:, delta.platform_q], q_proj[:, delta.platform_q], atol=1e-9)
    np.testing.assert_allclose(delta.closure_residuals(q_closed), 0.0, atol=1e-9)
    rest = s2.deltas["at rest"]
    assert rest.t.shape == (1,) and rest.duration == 0.0
    np.testing.assert_allclose(rest.theta[0], delta.home()[delta.motor_q])


def test_add_delta_refuses_bad_motions(delta):
    s = Session()
    t, act = _motion(5)
    with pytest.raises(InvalidInput, match="4 .*tool axis"):
        s.add_delta(delta, motion=(t, act[:, :3]))
    with pytest.raises(InvalidInput, match="strictly increasing"):
        s.add_delta(delta, motion=(t[::-1], act))
    with pytest.raises(InvalidInput, match="outside the range"):
        s.add_delta(delta, motion=(t, act + [2.0, 0.0, 0.0, 0.0]))
    with pytest.raises(InvalidInput, match="not a shipped delta"):
        s.add_delta(DeltaRobot(delta.model, delta.closures, name="mine", acceleration=1.0))
    with pytest.raises(InvalidInput, match="DeltaRobot"):
        s.add_delta(object(), key="x")
    s.add_delta(delta, motion=(t, act))
    with pytest.raises(InvalidInput, match="already exists"):
        s.add_delta(delta)


def _with_doc(src, dst, edit, replace=None):
    doc = document(src)
    edit(doc["deltas"][0])
    return rewrite(src, dst, replace={"session.json": json.dumps(doc).encode(), **(replace or {})})


def test_hostile_deltas_refused(saved, tmp_path):
    """Each refusal names the delta item and what is wrong; nothing is drawn from such a file."""
    _, path = saved
    t, act = _motion()

    def name(d):
        d["delta"] = "../../etc/passwd"

    cases = {
        "unknown delta": (name, None, "not a delta this pinarms ships"),
        "columns": (lambda d: d["actuated"].update(shape=[31, 3]), {"arrays/deltas/0/actuated.npy": npy_bytes(act[:, :3])},
                    "3 actuated columns; delta_flexpicker has 4"),
        "range": (lambda d: None, {"arrays/deltas/0/actuated.npy": npy_bytes(act + [3.0, 0, 0, 0])}, "outside the range"),
        "time": (lambda d: None, {"arrays/deltas/0/t.npy": npy_bytes(t[::-1].copy())}, "strictly increasing"),
        "pose": (lambda d: None, {"arrays/deltas/0/base_to_world.npy": npy_bytes(2.0 * np.eye(4))}, "rigid transform"),
        "pickle": (lambda d: None, {"arrays/deltas/0/t.npy": npy_bytes(np.array([object()] * 31))}, "pickled data is never loaded"),
    }
    for label, (edit, members, message) in cases.items():
        bad = _with_doc(path, tmp_path / f"{label}.pinarms", edit, members)
        with pytest.raises(SessionFormatError, match=message):
            load_session(bad)
    # a row that does not assemble: in this delta's range every row does, so a delta of shorter forearms
    from dataclasses import replace
    from types import SimpleNamespace

    from pinarms.viz.delta_record import assembly_problem

    d = load_delta("delta_flexpicker")
    short = SimpleNamespace(name="short", has_tool_axis=True, limits=d.limits,
                            geometry=replace(d.geometry, forearm=0.6))
    rows = np.array([[-0.69, 1.3, 1.3, 0.0], [-0.6, 1.3, 1.3, 0.0], [0.35, 0.35, 0.35, 0.0]])
    assert np.isfinite(forward_position(short.geometry, rows[:2, :3])).all()
    assert not np.isfinite(forward_position(short.geometry, rows[2:, :3])).any()
    assert assembly_problem(d, rows) is None
    assert "row 2: motor angles [0.35, 0.35, 0.35] rad do not assemble" in assembly_problem(short, rows)
    # bounded sizes: a motion declared larger than the caller's limit is refused before it is read
    with pytest.raises(SessionFormatError, match="allowed for one array"):
        load_session(path, limits=SessionLimits(max_array_bytes=31 * 4 * 8 - 1))
