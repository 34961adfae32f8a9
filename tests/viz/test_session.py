"""Saved sessions: exact round trip, payloads, atomic writes, threads."""

from __future__ import annotations

import io
import json
import os
import subprocess
import sys
import textwrap
import zipfile

import numpy as np
import pytest

from pinarms import viz
import pinarms.viz.session as vs
from pinarms.errors import InvalidInput, PinarmsError
from pinarms.viz import SessionFormatError

from session_files import LEVER_URDF, document, rewrite


def test_round_trip_is_exact(session, tmp_path):
    path = session.save(tmp_path / "study.pinarms")
    back = viz.load_session(path)
    assert back == session
    # bit-equal arrays, equal JSON, same order
    for name, rec in session.trajectories.items():
        got = back.trajectories[name]
        assert got.q.dtype == np.float64 and got.q.tobytes() == rec.q.tobytes()
        assert got.t.tobytes() == rec.t.tobytes() and got.definition == rec.definition
    assert list(back.trajectories) == ["P1-P4 quintic", "raw"]
    assert back.metadata == session.metadata
    assert back.metadata["user"] == {"line": "enoki", "speeds": [1.5, 2]}
    assert back.robots["ur5"].source == "registry" and back.robots["lever"].source == "urdf"
    assert back.robots["lever"].urdf_text == LEVER_URDF
    np.testing.assert_array_equal(back.robots["lever"].base_to_world[:3, 3], [1.0, 0.5, 0.0])
    # saving what was loaded gives the same document again
    again = viz.load_session(back.save(tmp_path / "again.pinarms"))
    assert again == session


def test_loaded_trajectory_rebuilds_and_robots_reload(session, tmp_path):
    back = viz.load_session(session.save(tmp_path / "s.pinarms"))
    rec = back.trajectories["P1-P4 quintic"]
    traj = rec.rebuild()
    np.testing.assert_allclose(traj.sample(rec.t)[0], rec.q, atol=1e-12)
    np.testing.assert_array_equal(rec.knot_times, [0.0, 1.0, 3.0, 4.0])
    assert set(rec.knot_times) <= set(rec.t)  # knots are sampled exactly
    with pytest.raises(InvalidInput, match="samples only"):
        back.trajectories["raw"].rebuild()
    lever = back.robot("lever")  # rebuilt from the embedded URDF
    np.testing.assert_allclose(lever.position(np.array([0.0])), [0.4, 0.0, 0.1])
    assert back.robot("ur5").nq == 6


def test_members_are_json_and_npy_never_pickle(session, tmp_path):
    path = session.save(tmp_path / "s.pinarms")
    with zipfile.ZipFile(path) as zf:
        names = zf.namelist()
        doc = json.loads(zf.read("session.json"))
        assert doc["format"] == "pinarms-session" and doc["version"] == viz.FORMAT_VERSION
        npys = [n for n in names if n.endswith(".npy")]
        assert len(npys) == 2 + 3 * 2 + 2 + 2 + 3 + 2  # bases, trajectories, cloud, points, history, box
        for n in npys:
            arr = np.load(io.BytesIO(zf.read(n)), allow_pickle=False)
            assert arr.dtype == np.float64
        assert "robots/1.urdf" in names


def test_session_format_error_is_a_pinarms_error():
    assert issubclass(SessionFormatError, PinarmsError)


def test_atomic_write_failure_leaves_nothing(session, tmp_path, monkeypatch):
    calls = {"n": 0}
    real_save = np.save

    def failing_save(*args, **kwargs):
        calls["n"] += 1
        if calls["n"] == 4:
            raise OSError("disk full (simulated)")
        return real_save(*args, **kwargs)

    monkeypatch.setattr(vs.np, "save", failing_save)
    target = tmp_path / "new.pinarms"
    with pytest.raises(OSError, match="simulated"):
        session.save(target)
    assert calls["n"] == 4
    assert os.listdir(tmp_path) == []  # no target, no temporary file


def test_atomic_write_failure_keeps_previous_file(session, tmp_path, monkeypatch):
    target = session.save(tmp_path / "s.pinarms")
    before = target.read_bytes()
    session.add_points("more", [[0.0, 0.0, 1.0]])

    def failing_save(*args, **kwargs):
        raise KeyboardInterrupt  # even an interrupt mid-write leaves the old file intact

    monkeypatch.setattr(vs.np, "save", failing_save)
    with pytest.raises(KeyboardInterrupt):
        session.save(target)
    assert target.read_bytes() == before
    assert os.listdir(tmp_path) == ["s.pinarms"]
    assert "more" not in viz.load_session(target).point_sets


def test_payload_is_kept_and_checked(tmp_path):
    from pinarms import robots as _robots
    from pinarms.viz import Session, load_session

    arm = _robots.load("aubo_i3").with_payload(3.0, com=[0.0, 0.0, 0.04], inertia=[0.01, 0.01, 0.006])
    path = Session(arm, title="3 kg food pack").save(tmp_path / "pack.pinarms")
    doc = document(path)
    assert doc["robots"][0]["source"] == "registry" and doc["robots"][0]["payload"]["mass_kg"] == 3.0
    again = load_session(path).robot()
    assert again.payload.mass == 3.0
    np.testing.assert_array_equal(again.payload.com, [0.0, 0.0, 0.04])
    q = arm.random_q(5, seed=2)
    np.testing.assert_allclose(again.gravity(q), arm.gravity(q), rtol=1e-14, atol=1e-14)
    # a bare arm writes no payload field (sessions without one read as before)
    bare = Session(_robots.load("aubo_i3")).save(tmp_path / "bare.pinarms")
    assert "payload" not in document(bare)["robots"][0] and load_session(bare).robot().payload is None
    # a hostile payload is refused with the reason
    doc["robots"][0]["payload"]["mass_kg"] = -3.0
    bad = rewrite(path, tmp_path / "bad.pinarms", replace={"session.json": json.dumps(doc).encode()})
    with pytest.raises(SessionFormatError, match=r"robots\[0\]\.payload: payload mass must be >= 0"):
        load_session(bad)


_CRASH = textwrap.dedent("""
    import os, signal, sys
    import numpy as np
    from pinarms import viz
    s = viz.Session("ur5")
    s.add_points("p", [[0.0, 0.0, 0.0]])
    real = np.save
    def dying_save(*a, **k):
        real(*a, **k)
        os.kill(os.getpid(), signal.SIGKILL)  # as a power cut or the OOM killer would
    np.save = dying_save
    s.save(sys.argv[1])
""")


def test_part_files_of_a_killed_save_are_removed_by_the_next_save(session, tmp_path):
    from pinarms import files as _atomic

    target = tmp_path / "s.pinarms"
    proc = subprocess.run([sys.executable, "-c", _CRASH, str(target)], capture_output=True, timeout=120)
    assert proc.returncode == -9
    leftovers = [p for p in os.listdir(tmp_path) if p.endswith(".part")]
    assert len(leftovers) == 1 and leftovers[0].startswith(".s.pinarms.") and not target.exists()
    # a leftover becomes stale once unlocked and STALE_AFTER_S old
    old = os.path.getmtime(tmp_path / leftovers[0]) - 10 * _atomic.STALE_AFTER_S
    os.utime(tmp_path / leftovers[0], (old, old))
    # ... unlike a save of the same file in progress (locked), a fresh one, or another file's
    live = tmp_path / ".s.pinarms.live0001.part"
    live.write_bytes(b"x")
    os.utime(live, (old, old))
    fresh = tmp_path / ".s.pinarms.fresh001.part"
    fresh.write_bytes(b"x")
    other = tmp_path / ".other.pinarms.abcd1234.part"
    other.write_bytes(b"x")
    os.utime(other, (old, old))
    import fcntl

    with open(live, "rb") as held:
        fcntl.flock(held, fcntl.LOCK_EX)
        session.save(target)
    assert sorted(os.listdir(tmp_path)) == sorted(["s.pinarms", live.name, fresh.name, other.name])
    assert viz.load_session(target) == session


def test_sessions_from_several_threads(session, tmp_path):
    """Loading, reading, asking for robots and saving from 8 threads: one Robot per key, whole files only.

    The interpreter switches threads every microsecond to make interleavings likely.
    """
    from concurrent.futures import ThreadPoolExecutor

    path = session.save(tmp_path / "shared.pinarms")
    back = viz.load_session(path)
    old = sys.getswitchinterval()
    sys.setswitchinterval(1e-6)
    try:
        with ThreadPoolExecutor(8) as pool:
            loaded = list(pool.map(lambda _: viz.load_session(path), range(8)))
            got = list(pool.map(lambda _: back.robot("lever"), range(8)))
            saved = list(pool.map(lambda i: back.save(tmp_path / "out.pinarms"), range(8)))
    finally:
        sys.setswitchinterval(old)
    assert all(s == session for s in loaded)
    assert all(r is got[0] for r in got)  # the same Robot for every thread
    assert saved[0] == tmp_path / "out.pinarms" and viz.load_session(saved[0]) == session
    assert sorted(os.listdir(tmp_path)) == ["out.pinarms", "shared.pinarms"]  # no .part left behind
