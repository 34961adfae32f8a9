"""Saved sessions: exact round trip, validation of damaged files, future versions, atomic writes."""

from __future__ import annotations

import io
import json
import os
import re
import zipfile

import numpy as np
import pytest

from pinarms import planning
from pinarms import robots
from pinarms import viz
import pinarms.viz.session as vs
from pinarms.robots.errors import InvalidInput, PinarmsError
from pinarms.viz import SessionFormatError

LEVER_URDF = """<robot name="lever">
  <link name="base_link"><visual><geometry><box size="0.1 0.1 0.1"/></geometry></visual></link>
  <link name="arm"><visual><origin xyz="0.2 0 0"/><geometry><box size="0.4 0.04 0.04"/></geometry></visual></link>
  <link name="tcp"/>
  <joint name="j1" type="revolute"><parent link="base_link"/><child link="arm"/><axis xyz="0 0 1"/>
    <origin xyz="0 0 0.1"/><limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
  <joint name="tool" type="fixed"><parent link="arm"/><child link="tcp"/><origin xyz="0.4 0 0"/></joint>
</robot>"""


@pytest.fixture(scope="module")
def ur5():
    return robots.load("ur5")


@pytest.fixture()
def session(ur5):
    s = viz.Session(ur5, title="pick & place", metadata={"line": "enoki", "speeds": (1.5, 2)})
    times = np.array([0.0, 1.0, 3.0, 4.0])
    via = ur5.random_q(4, seed=1)
    s.add_trajectory("P1-P4 quintic", planning.multi_quintic(times, via), hz=50)
    s.add_trajectory("raw", (np.linspace(0, 1, 7), ur5.random_q(7, seed=2)))
    q = ur5.random_q(300, seed=3)
    s.add_workspace("cloud", points=ur5.position(q), manipulability=ur5.manipulability(q))
    s.add_points("targets", [[0.4, 0.1, 0.2], [0.3, -0.2, 0.25]], kind="target")
    s.add_points("vias", [[0.1, 0.2, 0.3]], robot="ur5")
    s.add_history("ga", {"best": [5.0, 4.0, 3.6], "mean": [7.0, 5.5, 4.0], "feasible_share": [0.2, 0.6, 1.0]})
    lever = robots.from_urdf_text(LEVER_URDF)
    T = np.eye(4)
    T[:3, 3] = [1.0, 0.5, 0.0]
    s.add_robot(lever, base_to_world=T)
    s.add_box("conveyor", [1.2, 0.3, 0.05], pose=T, color=(0.2, 0.3, 0.8, 0.5))
    return s


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


def _rewrite(src, dst, *, drop=(), replace=None):
    """Copy the session zip ``src`` to ``dst`` without the ``drop`` members and with ``replace`` {member: bytes}."""
    replace = replace or {}
    with zipfile.ZipFile(src) as zin, zipfile.ZipFile(dst, "w") as zout:
        for item in zin.infolist():
            if item.filename in drop:
                continue
            zout.writestr(item.filename, replace.get(item.filename, zin.read(item.filename)))
    return dst


def _doc(path):
    with zipfile.ZipFile(path) as zf:
        return json.loads(zf.read("session.json"))


def _npy(arr):
    buf = io.BytesIO()
    np.save(buf, arr)
    return buf.getvalue()


@pytest.fixture()
def saved(session, tmp_path):
    return session.save(tmp_path / "good.pinarms")


def test_truncated_file(saved, tmp_path):
    data = saved.read_bytes()
    for cut in (len(data) // 2, len(data) - 10, 30):
        bad = tmp_path / f"cut{cut}.pinarms"
        bad.write_bytes(data[:cut])
        with pytest.raises(SessionFormatError, match="not a zip archive, or truncated"):
            viz.load_session(bad)


def test_garbage_and_empty_files(tmp_path):
    bad = tmp_path / "garbage.pinarms"
    bad.write_bytes(np.random.default_rng(0).bytes(5000))
    with pytest.raises(SessionFormatError, match="not a zip"):
        viz.load_session(bad)
    empty = tmp_path / "empty.pinarms"
    empty.write_bytes(b"")
    with pytest.raises(SessionFormatError):
        viz.load_session(empty)
    with pytest.raises(InvalidInput, match="does not exist"):
        viz.load_session(tmp_path / "missing.pinarms")


def test_corrupt_member_bytes(saved, tmp_path):
    data = bytearray(saved.read_bytes())
    with zipfile.ZipFile(saved) as zf:
        info = zf.getinfo("session.json")
    start = info.header_offset + 30 + len(info.filename) + len(info.extra)
    data[start + 5 : start + 25] = bytes(20)  # damage the compressed session.json in place
    bad = tmp_path / "crc.pinarms"
    bad.write_bytes(bytes(data))
    with pytest.raises(SessionFormatError, match="session.json"):
        viz.load_session(bad)


def test_missing_members(saved, tmp_path):
    with pytest.raises(SessionFormatError, match="'session.json' is missing"):
        viz.load_session(_rewrite(saved, tmp_path / "a.pinarms", drop={"session.json"}))
    member = _doc(saved)["trajectories"][0]["q"]["member"]
    with pytest.raises(SessionFormatError, match=f"{member}' is missing"):
        viz.load_session(_rewrite(saved, tmp_path / "b.pinarms", drop={member}))
    with pytest.raises(SessionFormatError, match="robots/1.urdf' is missing"):
        viz.load_session(_rewrite(saved, tmp_path / "c.pinarms", drop={"robots/1.urdf"}))


def test_bad_json(saved, tmp_path):
    cases = {
        b"{not json": "not valid UTF-8 JSON",
        b"[1, 2]": "must hold a JSON object",
        json.dumps({"format": "other", "version": 1}).encode(): "format 'other'",
        json.dumps({"format": "pinarms-session", "version": "1"}).encode(): "not a positive integer",
    }
    for i, (payload, message) in enumerate(cases.items()):
        bad = _rewrite(saved, tmp_path / f"j{i}.pinarms", replace={"session.json": payload})
        with pytest.raises(SessionFormatError, match=message):
            viz.load_session(bad)
    doc = _doc(saved)
    del doc["workspaces"][0]["manipulability"]
    bad = _rewrite(saved, tmp_path / "field.pinarms", replace={"session.json": json.dumps(doc).encode()})
    with pytest.raises(SessionFormatError, match=r"workspaces\[0\] lacks the field 'manipulability'"):
        viz.load_session(bad)
    doc = _doc(saved)
    doc["trajectories"][1]["robot"] = "nobody"
    bad = _rewrite(saved, tmp_path / "robot.pinarms", replace={"session.json": json.dumps(doc).encode()})
    with pytest.raises(SessionFormatError, match="'nobody' is not one of the session's robots"):
        viz.load_session(bad)


def test_wrong_array_shape_and_dtype(saved, tmp_path):
    doc = _doc(saved)
    q_ref = doc["trajectories"][0]["q"]
    n, nq = q_ref["shape"]
    # a q of 5 columns for a 6-joint robot, consistently declared in the index
    doc["trajectories"][0]["q"]["shape"] = [n, nq - 1]
    bad = _rewrite(saved, tmp_path / "shape.pinarms", replace={
        "session.json": json.dumps(doc).encode(), q_ref["member"]: _npy(np.zeros((n, nq - 1)))})
    with pytest.raises(SessionFormatError, match=rf"shape \({n}, {nq - 1}\), expected \({n}, {nq}\)"):
        viz.load_session(bad)
    # array disagrees with the index
    bad = _rewrite(saved, tmp_path / "index.pinarms", replace={q_ref["member"]: _npy(np.zeros((n + 1, nq)))})
    with pytest.raises(SessionFormatError, match="but session.json says"):
        viz.load_session(bad)
    # integer array
    bad = _rewrite(saved, tmp_path / "dtype.pinarms", replace={q_ref["member"]: _npy(np.zeros((n, nq), dtype=np.int64))})
    with pytest.raises(SessionFormatError, match="dtype int64, expected float64"):
        viz.load_session(bad)
    # a pickled object array is refused, never unpickled
    obj = np.empty(2, dtype=object)
    obj[:] = [{"a": 1}, None]
    buf = io.BytesIO()
    np.save(buf, obj, allow_pickle=True)
    padded = buf.getvalue() + bytes(n * nq * 8)  # the zip entry's size is then what the index's shape needs
    bad = _rewrite(saved, tmp_path / "pickle.pinarms", replace={q_ref["member"]: padded})
    with pytest.raises(SessionFormatError, match="object array: pickled data is never loaded"):
        viz.load_session(bad)
    bad = _rewrite(saved, tmp_path / "pickle2.pinarms", replace={q_ref["member"]: buf.getvalue()})
    with pytest.raises(SessionFormatError, match=r"holds \d+ bytes in the zip directory, but session.json's shape"):
        viz.load_session(bad)
    # NaN
    nan = np.zeros((n, nq))
    nan[1, 2] = np.nan
    bad = _rewrite(saved, tmp_path / "nan.pinarms", replace={q_ref["member"]: _npy(nan)})
    with pytest.raises(SessionFormatError, match="NaN"):
        viz.load_session(bad)


def test_future_format_version(saved, tmp_path):
    doc = _doc(saved)
    doc["version"] = viz.FORMAT_VERSION + 1
    doc["something_new"] = {"x": 1}
    bad = _rewrite(saved, tmp_path / "future.pinarms", replace={"session.json": json.dumps(doc).encode()})
    with pytest.raises(SessionFormatError, match=rf"version {viz.FORMAT_VERSION + 1}, newer .* upgrade pinarms"):
        viz.load_session(bad)


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


def test_bad_inputs_name_the_problem(ur5, tmp_path):
    s = viz.Session(ur5)
    with pytest.raises(InvalidInput, match="6 joints"):
        s.add_trajectory("x", (np.linspace(0, 1, 5), np.zeros((5, 4))))
    with pytest.raises(InvalidInput, match="strictly increasing"):
        s.add_trajectory("x", (np.array([0.0, 1.0, 1.0]), np.zeros((3, 6))))
    with pytest.raises(InvalidInput, match="not allowed"):
        s.add_points("a/b", [[0, 0, 0]])
    s.add_points("p", [[0, 0, 0]])
    with pytest.raises(InvalidInput, match="already exists"):
        s.add_points("p", [[0, 0, 0]])
    with pytest.raises(InvalidInput, match="kind"):
        s.add_points("q", [[0, 0, 0]], kind="waypoint")
    with pytest.raises(InvalidInput, match="rigid transform"):
        s.add_robot("panda", base_to_world=np.diag([2.0, 1, 1, 1]))
    with pytest.raises(InvalidInput, match="JSON-able"):
        viz.Session(ur5, metadata={"x": float("nan")})
    with pytest.raises(InvalidInput, match="folder"):
        s.save(tmp_path / "no" / "such" / "dir.pinarms")
    two = viz.Session(ur5)
    two.add_robot("ur5", key="ur5_b")
    with pytest.raises(InvalidInput, match="2 robots"):
        two.add_trajectory("t", (np.array([0.0, 1.0]), np.zeros((2, 6))))


def test_more_bad_inputs_name_the_problem(ur5):
    s = viz.Session(ur5)
    with pytest.raises(InvalidInput, match="must be a robots.Workspace"):
        s.add_workspace("w", 42)
    with pytest.raises(InvalidInput, match="no points"):
        s.add_workspace("w", points=np.zeros((0, 3)), manipulability=np.zeros(0))
    with pytest.raises(InvalidInput, match="no points"):
        s.add_points("p", np.zeros((0, 3)))
    with pytest.raises(InvalidInput, match="must be numbers"):
        s.add_points("p", "conveyor")
    with pytest.raises(InvalidInput, match="RGBA"):
        s.add_box("b", [1.0, 1.0, 1.0], color="red")
    with pytest.raises(InvalidInput, match="no generations"):
        s.add_history("h", {"best": []})
    with pytest.raises(InvalidInput, match="NaN"):
        s.add_history("h", {"best": [1.0, float("nan")]})
    # 1000 s at 1e5 Hz would be 1e8 samples (tens of GB): refused before sampling
    long = planning.multi_quintic(np.array([0.0, 1000.0]), ur5.random_q(2, seed=0))
    with pytest.raises(InvalidInput, match="lower hz"):
        s.add_trajectory("long", long, hz=1e5)
    assert s.trajectories == {} and s.workspaces == {} and s.point_sets == {} and s.histories == {}


def test_history_with_generations_without_finite_objective_round_trips(ur5, tmp_path):
    """optim's GA records inf as the mean of a generation with no finite objective."""
    s = viz.Session(ur5)
    s.add_history("ga", {"best": [np.inf, 4.0, 3.5], "mean": [np.inf, np.inf, 5.0]})
    back = viz.load_session(s.save(tmp_path / "h.pinarms"))
    assert back == s
    np.testing.assert_array_equal(back.histories["ga"].mean, [np.inf, np.inf, 5.0])
    out = viz.plot_ga_convergence(tmp_path / "ga.png", back.histories["ga"])
    assert out.stat().st_size > 0


# ---------------------------------------------------------------------------- hostile files
# A zip built byte by byte, so that a test can forge what zipfile would refuse to write:
# a raw deflate stream of 2 GiB of zeros (about 2 MB), a directory that lies about sizes,
# duplicate names, unknown compression methods.
import struct
import subprocess
import sys
import textwrap
import zlib

from pinarms.viz import session_format as sf

_ZEROS_1M = bytes(1 << 20)


def _deflate(prefix: bytes, n_zeros: int, *, with_crc: bool = True) -> tuple[bytes, int]:
    """Raw deflate of ``prefix + bytes(n_zeros)`` and its CRC-32, without ever holding the zeros.

    After a full flush the compressor's state is reset, so every following 1 MiB block of
    zeros compresses to the same bytes: compress one, repeat it.
    """
    c = zlib.compressobj(9, zlib.DEFLATED, -15)
    out = [c.compress(prefix) + c.flush(zlib.Z_FULL_FLUSH)]
    crc = zlib.crc32(prefix)
    full, rest = divmod(n_zeros, 1 << 20)
    if full:
        block = c.compress(_ZEROS_1M) + c.flush(zlib.Z_FULL_FLUSH)
        again = c.compress(_ZEROS_1M) + c.flush(zlib.Z_FULL_FLUSH)
        assert block == again  # the trick holds
        out.append(block * full)
        if with_crc:
            big = bytes(16 << 20)
            n16, n1 = divmod(full, 16)
            for _ in range(n16):
                crc = zlib.crc32(big, crc)
            for _ in range(n1):
                crc = zlib.crc32(_ZEROS_1M, crc)
    out.append(c.compress(bytes(rest)) + c.flush())
    if with_crc:
        crc = zlib.crc32(bytes(rest), crc)
    return b"".join(out), crc


def _raw_zip(entries) -> bytes:
    """A zip of ``entries`` = [(name, method, raw bytes, crc, uncompressed size[, central size])].

    The optional sixth value is the size written to the central directory (a lie, when it differs).
    """
    local, central = [], []
    offset = 0
    for e in entries:
        name, method, raw, crc, size = e[:5]
        dir_size = e[5] if len(e) > 5 else size
        nb = name.encode("utf-8")
        hdr = struct.pack("<4s5H3L2H", b"PK\x03\x04", 20, 0x800, method, 0, 0x21, crc, len(raw), dir_size, len(nb), 0)
        local.append(hdr + nb + raw)
        central.append(struct.pack("<4s6H3L5H2L", b"PK\x01\x02", 20, 20, 0x800, method, 0, 0x21, crc, len(raw),
                                   dir_size, len(nb), 0, 0, 0, 0, 0, offset) + nb)
        offset += len(hdr) + len(nb) + len(raw)
    cd = b"".join(central)
    eocd = struct.pack("<4s4H2LH", b"PK\x05\x06", 0, 0, len(entries), len(entries), len(cd), offset, 0)
    return b"".join(local) + cd + eocd


def _entries_of(path, skip=()):
    """Members of a saved session as raw deflate entries (to rebuild it with _raw_zip)."""
    out = []
    with zipfile.ZipFile(path) as zf:
        for info in zf.infolist():
            if info.filename in skip:
                continue
            data = zf.read(info.filename)
            c = zlib.compressobj(6, zlib.DEFLATED, -15)
            out.append((info.filename, 8, c.compress(data) + c.flush(), zlib.crc32(data), len(data)))
    return out


def _npy_header(shape, descr="<f8") -> bytes:
    buf = io.BytesIO()
    np.lib.format.write_array_header_1_0(buf, {"descr": descr, "fortran_order": False, "shape": tuple(shape)})
    return buf.getvalue()


@pytest.fixture(scope="module")
def cloud_session(tmp_path_factory):
    """A UR5 session with a 100-point workspace cloud (the member the bombs replace)."""
    ur5 = robots.load("ur5")
    s = viz.Session(ur5, title="bomb base")
    q = ur5.random_q(100, seed=4)
    s.add_workspace("cloud", points=ur5.position(q), manipulability=ur5.manipulability(q))
    return s.save(tmp_path_factory.mktemp("bomb") / "base.pinarms")


def test_raw_zip_builder_makes_files_zipfile_inflates(cloud_session, tmp_path):
    """The forged-zip helpers are sound: a small bomb (8 MiB of zeros) is a valid zip, CRC included."""
    doc = _doc(cloud_session)
    member = doc["workspaces"][0]["points"]["member"]
    n = (8 << 20) // 24
    hdr = _npy_header((n, 3))
    raw, crc = _deflate(hdr, 24 * n)
    doc["workspaces"][0]["points"]["shape"] = [n, 3]
    doc["workspaces"][0]["manipulability"]["shape"] = [n]
    js = json.dumps(doc).encode()
    c = zlib.compressobj(6, zlib.DEFLATED, -15)
    entries = _entries_of(cloud_session, skip={member, "session.json"})
    entries += [("session.json", 8, c.compress(js) + c.flush(), zlib.crc32(js), len(js)),
                (member, 8, raw, crc, len(hdr) + 24 * n)]
    path = tmp_path / "small_bomb.pinarms"
    path.write_bytes(_raw_zip(entries))
    assert path.stat().st_size < 20_000  # 8 MiB of zeros in under 20 kB
    with zipfile.ZipFile(path) as zf:
        assert zf.testzip() is None  # every CRC right
        data = zf.read(member)
    arr = np.load(io.BytesIO(data))
    assert arr.shape == (n, 3) and not arr.any()
    # the manipulability member still has 100 values: refused by size before any array is read
    with pytest.raises(SessionFormatError, match=r"manipulability.npy' holds 928 bytes in the zip directory"):
        viz.load_session(path)


@pytest.fixture(scope="module")
def bombs(cloud_session, tmp_path_factory):
    """Session files whose points member inflates to 2 GiB of zeros, lying in different places."""
    folder = tmp_path_factory.mktemp("bombs")
    doc = _doc(cloud_session)
    member = doc["workspaces"][0]["points"]["member"]
    n_big = ((2 << 30) - 128) // 24  # header (128 bytes) + data = 2 GiB
    hdr_big = _npy_header((n_big, 3))
    raw, crc = _deflate(hdr_big, 24 * n_big)
    size_big = len(hdr_big) + 24 * n_big
    assert size_big == 2 << 30
    base = _entries_of(cloud_session, skip={member, "session.json"})

    def build(name, index_rows, entry):
        d = json.loads(json.dumps(doc))
        d["workspaces"][0]["points"]["shape"] = [index_rows, 3]
        d["workspaces"][0]["manipulability"]["shape"] = [index_rows]
        js = json.dumps(d).encode()
        c = zlib.compressobj(6, zlib.DEFLATED, -15)
        path = folder / name
        path.write_bytes(_raw_zip(base + [("session.json", 8, c.compress(js) + c.flush(), zlib.crc32(js), len(js)),
                                          entry]))
        return path

    small = len(_npy_header((100, 3))) + 2400
    return {
        # everything agrees: a 2 GiB array, honestly declared
        "honest": build("honest.pinarms", n_big, (member, 8, raw, crc, size_big)),
        # session.json says 100 points; the zip directory and the .npy header say 2 GiB
        "index_small": build("index_small.pinarms", 100, (member, 8, raw, crc, size_big)),
        # index and zip directory say 100 points (2,528 bytes); the deflate stream holds 2 GiB
        "directory_lies": build("directory_lies.pinarms", 100, (member, 8, raw, crc, small)),
        # the same with the CRC of the first 2,528 bytes: zipfile's own check passes
        "crc_lies": build("crc_lies.pinarms", 100,
                          (member, 8, raw, zlib.crc32(hdr_big + bytes(small - len(hdr_big))), small)),
        # the local header says 2 GiB, the central directory 2,528 bytes
        "central_lies": build("central_lies.pinarms", 100, (member, 8, raw, crc, size_big, small)),
    }


_MEASURE = textwrap.dedent("""
    import json, resource, sys, time, tracemalloc
    from pinarms import viz
    out = []
    for path in sys.argv[1:]:
        before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
        tracemalloc.start()
        t = time.perf_counter()
        try:
            viz.load_session(path)
            err = None
        except Exception as exc:
            err = [type(exc).__name__, str(exc)]
        dt = time.perf_counter() - t
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
        rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
        out.append({"path": path, "s": dt, "peak_mb": peak / 2**20, "rss_growth_mb": (rss - before) / 1024,
                    "rss_mb": rss / 1024, "error": err})
    print(json.dumps(out))
""")


def test_zip_bombs_are_refused_fast_with_little_memory(bombs):
    """Issue 16: a 2 MB file inflating to 2 GiB of zeros is refused in < 1 s with < 200 MB peak memory.

    Measured in a fresh process (peak RSS by getrusage before/after, Python and NumPy
    allocations by tracemalloc); the old loader reached 4.1 GB and 21 s on such a file.
    """
    for path in bombs.values():
        assert path.stat().st_size < 2_300_000  # 2 GiB of zeros in about 2.1 MB
    proc = subprocess.run([sys.executable, "-c", _MEASURE, *map(str, bombs.values())],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    results = {r["path"].rsplit("/", 1)[1].split(".")[0]: r for r in json.loads(proc.stdout)}
    print(json.dumps({k: {m: round(v, 4) for m, v in r.items() if m in ("s", "peak_mb", "rss_growth_mb")} for k, r in results.items()}))
    expected = {
        "honest": r"points.npy' declares shape \(89478480, 3\) \(2,147,483,520 bytes\), more than the 536,870,912 allowed",
        "index_small": r"points.npy' holds 2,147,483,648 bytes in the zip directory, but session.json's shape \(100, 3\) needs 2,400",
        "directory_lies": r"points.npy' is corrupt \(Bad CRC-32",
        "crc_lies": r"points.npy' has shape \(89478480, 3\), but session.json says \(100, 3\)",
        "central_lies": r"points.npy' (has shape \(89478480, 3\), but session.json says \(100, 3\)|is corrupt)",
    }
    import re as _re

    for name, r in results.items():
        assert r["error"] is not None and r["error"][0] == "SessionFormatError", (name, r)
        assert _re.search(expected[name], r["error"][1]), (name, r["error"][1])
        assert r["s"] < 1.0, (name, r)
        assert r["peak_mb"] < 200 and r["rss_growth_mb"] < 200, (name, r)


def test_payload_is_kept_and_checked(tmp_path):
    from pinarms import robots as _robots
    from pinarms.viz import Session, load_session

    arm = _robots.load("aubo_i3").with_payload(3.0, com=[0.0, 0.0, 0.04], inertia=[0.01, 0.01, 0.006])
    path = Session(arm, title="3 kg food pack").save(tmp_path / "pack.pinarms")
    doc = _doc(path)
    assert doc["robots"][0]["source"] == "registry" and doc["robots"][0]["payload"]["mass_kg"] == 3.0
    again = load_session(path).robot()
    assert again.payload.mass == 3.0
    np.testing.assert_array_equal(again.payload.com, [0.0, 0.0, 0.04])
    q = arm.random_q(5, seed=2)
    np.testing.assert_allclose(again.gravity(q), arm.gravity(q), rtol=1e-14, atol=1e-14)
    # a bare arm writes no payload field (sessions without one read as before)
    bare = Session(_robots.load("aubo_i3")).save(tmp_path / "bare.pinarms")
    assert "payload" not in _doc(bare)["robots"][0] and load_session(bare).robot().payload is None
    # a hostile payload is refused with the reason
    doc["robots"][0]["payload"]["mass_kg"] = -3.0
    bad = _rewrite(path, tmp_path / "bad.pinarms", replace={"session.json": json.dumps(doc).encode()})
    with pytest.raises(SessionFormatError, match=r"robots\[0\]\.payload: payload mass must be >= 0"):
        load_session(bad)


# ---------------------------------------------------------------------------- limits, meshes, leftovers
def test_limits_refuse_big_sessions_and_say_how_to_raise_them(saved):
    doc = _doc(saved)
    q = doc["trajectories"][0]["q"]
    with pytest.raises(SessionFormatError, match=r"more than the 4,000 allowed for one array \(limit max_array_bytes\)"):
        viz.load_session(saved, limits=viz.SessionLimits(max_array_bytes=4000))
    with pytest.raises(SessionFormatError, match=r"add up to more than 10,000 bytes .*raise it with load_session"):
        viz.load_session(saved, limits=viz.SessionLimits(max_total_bytes=10_000))
    with pytest.raises(SessionFormatError, match="max_text_bytes"):
        viz.load_session(saved, limits=viz.SessionLimits(max_text_bytes=100))
    with pytest.raises(SessionFormatError, match="session.json.*more than the 1,000 allowed"):
        viz.load_session(saved, limits=viz.SessionLimits(max_json_bytes=1000))
    with pytest.raises(SessionFormatError, match="nests deeper than 3 levels"):
        viz.load_session(saved, limits=viz.SessionLimits(max_json_depth=3))
    with pytest.raises(SessionFormatError, match="max_members"):
        viz.load_session(saved, limits=viz.SessionLimits(max_members=5))
    assert q["shape"][0] * q["shape"][1] * 8 > 4000  # the first refusal is about this array, not a smaller one
    ok = viz.load_session(saved, limits=viz.SessionLimits(max_total_bytes=200_000, max_array_bytes=50_000))
    assert ok.trajectories.keys() == {"P1-P4 quintic", "raw"}
    with pytest.raises(InvalidInput, match="positive integer"):
        viz.SessionLimits(max_total_bytes=0)
    with pytest.raises(InvalidInput, match="SessionLimits"):
        viz.load_session(saved, limits={"max_total_bytes": 1})


MESH_URDF = LEVER_URDF.replace('<box size="0.1 0.1 0.1"/>', '<mesh filename="{}"/>')


@pytest.mark.parametrize("filename, ok", [
    ("package://lever/meshes/base.stl", True),
    ("meshes/base.stl", True),                               # relative: resolved against the package dirs
    ("{pkg}/lever/meshes/base.stl", True),                   # absolute, inside a package dir
    ("file://{pkg}/lever/meshes/base.stl", True),
    ("package://lever/meshes/missing.stl", True),            # missing: left to the viewer
    ("package://lever/../../../etc/passwd.stl", False),      # '..'
    ("/etc/hosts.stl", False),                               # absolute, outside
    ("file:///etc/hosts.stl", False),
    ("http://example.com/base.stl", False),                  # other schemes
    ("package://lever/escape.stl", False),                   # a symbolic link out of the package dir
    ("package://lever/meshes/base.txt", False),              # not a mesh file
    ("package://lever/fifo.stl", False),                     # not a regular file
])
def test_embedded_urdf_meshes_stay_inside_the_allowed_folders(tmp_path, filename, ok):
    study = tmp_path / "study"
    pkg = study / "pkg"
    (pkg / "lever" / "meshes").mkdir(parents=True)
    (pkg / "lever" / "meshes" / "base.stl").write_bytes(b"solid x\nendsolid x\n")
    (pkg / "lever" / "meshes" / "base.txt").write_text("x")
    outside = tmp_path / "secret.stl"
    outside.write_text("secret")
    os.symlink(outside, pkg / "lever" / "escape.stl")
    os.mkfifo(pkg / "lever" / "fifo.stl")
    urdf = MESH_URDF.format(filename.format(pkg=pkg))
    robot = robots.from_urdf_text(urdf, package_dirs=(str(pkg),))
    s = viz.Session(robot, key="lever")
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    # beside its package folder (inside the session's own folder), or elsewhere with the folder passed
    for back in (viz.load_session(s.save(study / "m.pinarms")),
                 viz.load_session(s.save(elsewhere / "m.pinarms"), package_dirs=[str(pkg)])):
        assert back.robots["lever"].source == "urdf"
        if ok:
            rob = back.robot("lever")
            assert rob.nq == 1 and str(pkg) in rob.package_dirs
        else:
            with pytest.raises(SessionFormatError, match="mesh"):
                back.robot("lever")
    # elsewhere without it: the folder the file names is never used by itself, and the message says what to pass
    far = viz.load_session(elsewhere / "m.pinarms")
    with pytest.raises(SessionFormatError, match="mesh") as info:
        far.robot("lever")
    if ok:
        assert "--package-dir" in str(info.value) and "package_dirs=" in str(info.value)


SECRET_STL = b"solid secret_part\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\n" \
             b"endfacet\nendsolid secret_part\n"


@pytest.mark.parametrize("form", ["absolute", "package_named"])
def test_a_session_cannot_allow_folders_by_itself(tmp_path, form):
    """Issue 29 item 2: package_dirs ["/"] in session.json and a mesh in another folder: refused, no page written."""
    from click.testing import CliRunner

    from pinarms.cli import cli

    other = tmp_path / "other"
    other.mkdir()
    secret = other / "secret_part.stl"
    secret.write_bytes(SECRET_STL)
    study = tmp_path / "study"
    study.mkdir()
    mesh = f"package://{other}/secret_part.stl" if form == "absolute" else f"package:/{other}/secret_part.stl"
    robot = robots.from_urdf_text(MESH_URDF.format(mesh), package_dirs=("/",))
    path = viz.Session(robot, key="lever").save(study / "s.pinarms")
    assert _doc(path)["robots"][0]["package_dirs"] == ["/"]
    page = study / "page.html"
    with pytest.raises(SessionFormatError, match=re.escape(repr(mesh))) as info:
        viz.export_html(viz.load_session(path), page)
    assert "package_dirs=" in str(info.value) and "--package-dir" in str(info.value)
    assert not page.exists() and not list(study.glob("*.part"))
    result = CliRunner().invoke(cli, ["export-html", str(path), str(page)])
    assert result.exit_code != 0 and "Traceback" not in result.output
    lines = [ln for ln in result.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("Error:") and "secret_part.stl" in lines[0], result.stderr
    assert not page.exists()
    if form == "absolute":  # the caller may allow the folder: then the mesh is read from it (and only then)
        assert viz.load_session(path, package_dirs=[str(other)]).robot("lever").nq == 1


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
    from pinarms.viz import _atomic

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


# ---------------------------------------------------------------------------- threads
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
