"""Fuzzed session files: corrupt, hostile and inconsistent ones end in SessionFormatError (or load).

A file that loads must also give its robots (or a named error), rebuild its trajectories
(or a named error), and save again into a fresh folder, writing nothing but the target,
to a file that loads equal. Nothing is ever written while loading.
"""

from __future__ import annotations

import io
import json
import os
import warnings
import zipfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from fuzz_support import EXPLORE, listing, outcome
from pinarms import planning, robots, viz
from pinarms.errors import PinarmsError
from pinarms.viz import SessionFormatError

LEVER_URDF = """<robot name="lever">
  <link name="base_link"><visual><geometry><box size="0.1 0.1 0.1"/></geometry></visual></link>
  <link name="arm"><visual><origin xyz="0.2 0 0"/><geometry><box size="0.4 0.04 0.04"/></geometry></visual></link>
  <link name="tcp"/>
  <joint name="j1" type="revolute"><parent link="base_link"/><child link="arm"/><axis xyz="0 0 1"/>
    <origin xyz="0 0 0.1"/><limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
  <joint name="tool" type="fixed"><parent link="arm"/><child link="tcp"/><origin xyz="0.4 0 0"/></joint>
</robot>"""


def _build_base() -> bytes:
    """A small session touching every kind: registry + embedded robots (one with a payload), box, trajectories,
    cloud, points, history, reachability map."""
    gantry = robots.load("gantry_flower")
    s = viz.Session(gantry, title="fuzz base", metadata={"line": "roses", "n": 3})
    s.add_trajectory("move", planning.multi_quintic(np.array([0.0, 0.5, 1.0]), gantry.random_q(3, seed=1)), hz=10)
    s.add_trajectory("raw", (np.linspace(0.0, 1.0, 4), gantry.random_q(4, seed=2)))
    q = gantry.random_q(5, seed=3)
    s.add_workspace("cloud", points=gantry.position(q), manipulability=np.linspace(0.0, 1.0, 5))
    s.add_points("targets", [[0.1, 0.2, 0.3]], kind="target")
    s.add_history("ga", {"best": [3.0, 2.0], "mean": [np.inf, 2.5]})
    s.add_robot(robots.from_urdf_text(LEVER_URDF).with_payload(0.5, com=[0.0, 0.0, 0.02]), base_to_world=np.eye(4))
    s.add_box("crate", [0.3, 0.2, 0.1])
    # the kinds added by others later are fuzzed the same way: a payload and a small reachability map
    from pinarms.robots.reach.reachability import ReachabilityRequest, reachability_map

    s.add_reachability("reach", reachability_map(ReachabilityRequest(gantry, 0.25, 2, tool_down=0.1, roll_steps=2)), robot="gantry_flower")
    import tempfile

    with tempfile.TemporaryDirectory() as d:
        return s.save(Path(d) / "base.pinarms").read_bytes()


BASE = _build_base()


def _members(data: bytes) -> dict[str, bytes]:
    with zipfile.ZipFile(io.BytesIO(data)) as zf:
        return {n: zf.read(n) for n in zf.namelist()}


BASE_MEMBERS = _members(BASE)
BASE_DOC = json.loads(BASE_MEMBERS["session.json"])


def _zip(members: list[tuple[str, bytes]], method: int = zipfile.ZIP_DEFLATED) -> bytes:
    buf = io.BytesIO()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # duplicate names are the point of some cases
        with zipfile.ZipFile(buf, "w", compression=method) as zf:
            for name, data in members:
                zf.writestr(name, data)
    return buf.getvalue()


def _check_load(tmp_path: Path, data: bytes) -> None:
    """The one property: load → named error or a session that works and saves again."""
    src = tmp_path / "in" / "fuzz.pinarms"
    src.parent.mkdir(exist_ok=True)
    src.write_bytes(data)
    before = listing(tmp_path)
    session, err = outcome(viz.load_session, src, seconds=10)
    assert listing(tmp_path) == before, "loading wrote a file"
    if err is not None:
        assert isinstance(err, SessionFormatError) or "does not exist" in str(err), err
        return
    for key in session.robots:
        outcome(session.robot, key)
    for rec in session.trajectories.values():
        if rec.definition is not None:
            traj, _ = outcome(rec.rebuild)
            if traj is not None:
                outcome(traj.sample, rec.t)
    out = tmp_path / "out"
    out.mkdir(exist_ok=True)
    for p in out.iterdir():
        p.unlink()
    saved, err = outcome(session.save, out / "again.pinarms")
    assert err is None, f"a session that loaded cannot be saved: {err}"
    assert sorted(os.listdir(out)) == ["again.pinarms"]
    again, err = outcome(viz.load_session, saved)
    assert err is None and again == session


# ---------------------------------------------------------------------------- bytes
@settings(max_examples=60 * EXPLORE)
@given(cut=st.integers(0, len(BASE)))
@example(cut=0)
@example(cut=len(BASE) - 22)  # exactly the end-of-directory record removed
def test_truncated(tmp_path_factory, cut):
    _check_load(tmp_path_factory.mktemp("t"), BASE[:cut])


@settings(max_examples=80 * EXPLORE)
@given(flips=st.lists(st.tuples(st.integers(0, len(BASE) - 1), st.integers(0, 7)), min_size=1, max_size=8))
def test_bit_flips(tmp_path_factory, flips):
    data = bytearray(BASE)
    for pos, bit in flips:
        data[pos] ^= 1 << bit
    _check_load(tmp_path_factory.mktemp("f"), bytes(data))


# ---------------------------------------------------------------------------- session.json
_json_leaf = st.one_of(
    st.none(), st.booleans(), st.integers(-(2**70), 2**70), st.floats(allow_nan=False, allow_infinity=False),
    st.text(max_size=20), st.sampled_from(["<f8", "<f4", "|O", "<i8", ">f8", "f8", "../x.npy", "/etc/passwd",
                                            "session.json", "robots/0.urdf", "\ud800", "a/b", ""]),
)
_json_value = st.recursive(_json_leaf, lambda c: st.one_of(st.lists(c, max_size=4),
                                                          st.dictionaries(st.text(max_size=8), c, max_size=4)),
                           max_leaves=12)


def _paths(obj, prefix=()):
    yield prefix
    if isinstance(obj, dict):
        for k, v in obj.items():
            yield from _paths(v, prefix + (k,))
    elif isinstance(obj, list):
        for i, v in enumerate(obj):
            yield from _paths(v, prefix + (i,))


BASE_PATHS = [p for p in _paths(BASE_DOC) if p]


def _set(doc, path, value, op):
    parent = doc
    for k in path[:-1]:
        parent = parent[k]
    k = path[-1]
    if op == "set":
        parent[k] = value
    elif op == "delete":
        del parent[k]
    elif op == "duplicate" and isinstance(parent, list):
        parent.append(json.loads(json.dumps(parent[k])))
    elif op == "shape" and isinstance(parent[k], dict) and "shape" in parent[k]:
        parent[k]["shape"] = value if isinstance(value, list) else [2**40, 3]


@settings(max_examples=150 * EXPLORE)
@given(edits=st.lists(st.tuples(st.sampled_from(range(len(BASE_PATHS))), _json_value,
                                st.sampled_from(["set", "delete", "duplicate", "shape"])), min_size=1, max_size=4))
@example(edits=[(BASE_PATHS.index(("version",)), 2, "set")])
@example(edits=[(BASE_PATHS.index(("version",)), True, "set")])
@example(edits=[(BASE_PATHS.index(("trajectories", 0, "q", "dtype")), "|O", "set")])
@example(edits=[(BASE_PATHS.index(("trajectories", 0, "q", "member")), "../../escape.npy", "set")])
@example(edits=[(BASE_PATHS.index(("trajectories", 0, "q", "member")), "arrays/trajectories/0/t.npy", "set")])
@example(edits=[(BASE_PATHS.index(("workspaces", 0, "points")), [2**40, 3], "shape")])
@example(edits=[(BASE_PATHS.index(("metadata", "title")), "\ud800", "set")])
@example(edits=[(BASE_PATHS.index(("metadata", "user", "n")), 10**400, "set")])
@example(edits=[(BASE_PATHS.index(("robots", 1, "urdf_member")), "robots/0.urdf", "set")])
@example(edits=[(BASE_PATHS.index(("trajectories", 0)), None, "duplicate")])
@example(edits=[(BASE_PATHS.index(("trajectories", 0, "definition", "kind")), "3-5-3", "set")])
@example(edits=[(BASE_PATHS.index(("robots", 1, "payload", "mass_kg")), -1.0, "set")])
@example(edits=[(BASE_PATHS.index(("robots", 1, "payload", "inertia_kg_m2")), [[1, 2], [3]], "set")])
@example(edits=[(BASE_PATHS.index(("robots", 1, "payload", "frame")), "no_such_frame", "set")])
@example(edits=[(BASE_PATHS.index(("reachability", 0, "centres")), [2**40, 3], "shape")])
@example(edits=[(BASE_PATHS.index(("reachability", 0, "robot")), "nobody", "set")])
def test_session_json_edits(tmp_path_factory, edits):
    doc = json.loads(json.dumps(BASE_DOC))
    for idx, value, op in edits:
        try:
            _set(doc, BASE_PATHS[idx], value, op)
        except (KeyError, IndexError, TypeError):
            pass  # an earlier edit removed or retyped the parent: keep going
    try:
        payload = json.dumps(doc, ensure_ascii=False).encode("utf-8", "surrogatepass")
    except (ValueError, OverflowError):
        return
    members = dict(BASE_MEMBERS, **{"session.json": payload})
    _check_load(tmp_path_factory.mktemp("j"), _zip(list(members.items())))


@pytest.mark.parametrize("payload", [
    b"[" * 100_000 + b"]" * 100_000,                                     # deep JSON (recursion)
    b'{"format": "pinarms-session", "version": 1, "x": ' + b"[" * 70 + b"]" * 70 + b"}",
    b'{"format": "pinarms-session", "version": NaN}',
    b'{"format": "pinarms-session", "version": 1, "version": 1}',         # duplicate key
    b'{"format": "pinarms-session", "version": 1e999}',
    b'{"format": "pinarms-session", "version": ' + b"9" * 5000 + b"}",   # int beyond Python's digit limit
    b"\xff\xfe{}",
    b"",
    "{\"format\": \"pinarms-session\", \"version\": 1, \"metadata\": \"\\ud800\"}".encode(),
])
def test_hostile_json_text(tmp_path, payload):
    members = dict(BASE_MEMBERS, **{"session.json": payload})
    with pytest.raises(SessionFormatError):
        viz.load_session(_write(tmp_path, _zip(list(members.items()))))


def _write(tmp_path: Path, data: bytes) -> Path:
    p = tmp_path / "case.pinarms"
    p.write_bytes(data)
    return p


# ---------------------------------------------------------------------------- members
def _npy(arr, **kw) -> bytes:
    buf = io.BytesIO()
    np.save(buf, arr, **kw)
    return buf.getvalue()


def _npy_header(shape, descr="<f8", fortran=False, version=(1, 0)) -> bytes:
    buf = io.BytesIO()
    d = {"descr": descr, "fortran_order": fortran, "shape": tuple(shape)}
    if version == (1, 0):
        np.lib.format.write_array_header_1_0(buf, d)
    else:
        np.lib.format.write_array_header_2_0(buf, d)
    return buf.getvalue()


_obj = np.empty(3, dtype=object)
_obj[:] = [{"a": 1}, None, "x"]
Q_MEMBER = BASE_DOC["trajectories"][0]["q"]["member"]
Q_SHAPE = tuple(BASE_DOC["trajectories"][0]["q"]["shape"])
Q_BYTES = int(np.prod(Q_SHAPE)) * 8
_member_payloads = {
    "pickled": _npy(_obj, allow_pickle=True),
    "pickled_padded": _npy(_obj, allow_pickle=True) + bytes(Q_BYTES),
    "object_header": _npy_header(Q_SHAPE, descr="|O") + bytes(Q_BYTES),
    "float32": _npy(np.zeros(Q_SHAPE, np.float32)),
    "big_endian": _npy(np.zeros(Q_SHAPE, ">f8")),
    "int64": _npy(np.zeros(Q_SHAPE, np.int64)),
    "complex": _npy(np.zeros(Q_SHAPE, np.complex128)),
    "structured": _npy(np.zeros(Q_SHAPE[0], [("a", "<f8"), ("b", "<f8")])),
    "fortran": _npy(np.asfortranarray(np.arange(Q_BYTES // 8, dtype="<f8").reshape(Q_SHAPE))),
    "v2_header": _npy_header(Q_SHAPE, version=(2, 0)) + bytes(Q_BYTES),
    "huge_header_shape": _npy_header((2**40, 3)) + bytes(Q_BYTES - 32),
    "negative": b"\x93NUMPY\x01\x00v\x00{'descr': '<f8', 'fortran_order': False, 'shape': (-1, 3), }" + b" " * 50 + b"\n",
    "header_code": b"\x93NUMPY\x01\x00v\x00{'descr': __import__('os').getcwd(), }" + b" " * 70 + b"\n" + bytes(Q_BYTES),
    "truncated": _npy(np.zeros(Q_SHAPE))[:-9],
    "extra_bytes": _npy(np.zeros(Q_SHAPE)) + b"\x00" * 8,
    "nan": _npy(np.full(Q_SHAPE, np.nan)),
    "inf": _npy(np.full(Q_SHAPE, np.inf)),
    "not_npy": b"PK\x03\x04" + bytes(Q_BYTES + 100),
    "empty": b"",
}


@pytest.mark.parametrize("case", sorted(_member_payloads))
def test_hostile_array_members(tmp_path, case):
    members = dict(BASE_MEMBERS, **{Q_MEMBER: _member_payloads[case]})
    src = _write(tmp_path, _zip(list(members.items())))
    if case == "fortran":  # a valid .npy in Fortran order is read correctly
        s = viz.load_session(src)
        np.testing.assert_array_equal(s.trajectories["move"].q, np.arange(Q_BYTES // 8).reshape(Q_SHAPE))
        return
    if case == "v2_header":  # a version 2.0 header is valid .npy too
        assert not viz.load_session(src).trajectories["move"].q.any()
        return
    with pytest.raises(SessionFormatError, match=Q_MEMBER):
        viz.load_session(src)


@pytest.mark.parametrize("case", ["duplicate_member", "duplicate_json", "dotdot", "absolute", "backslash",
                                  "bzip2", "lzma", "stored", "urdf_doctype", "urdf_entities", "urdf_not_utf8",
                                  "urdf_big", "urdf_mesh_escape", "urdf_mesh_absolute", "urdf_mesh_device",
                                  "urdf_mesh_own_root"])
def test_hostile_archives(tmp_path, case):
    members = list(BASE_MEMBERS.items())
    method = zipfile.ZIP_DEFLATED
    doc = json.loads(json.dumps(BASE_DOC))
    urdf = "robots/1.urdf"
    match = None
    expect_ok = False
    if case == "duplicate_member":
        members.append((Q_MEMBER, _npy(np.zeros(Q_SHAPE))))
        match = "appears twice in the zip directory"
    elif case == "duplicate_json":
        members.append(("session.json", b"{}"))
        match = "appears twice"
    elif case in ("dotdot", "absolute", "backslash"):
        name = {"dotdot": "../../outside.npy", "absolute": "/tmp/outside.npy", "backslash": "arrays\\..\\x.npy"}[case]
        doc["trajectories"][0]["q"]["member"] = name
        members.append((name, BASE_MEMBERS[Q_MEMBER]))
        match = "not a plain relative path"
    elif case in ("bzip2", "lzma"):
        method = zipfile.ZIP_BZIP2 if case == "bzip2" else zipfile.ZIP_LZMA
        match = "compression method"
    elif case == "stored":
        method = zipfile.ZIP_STORED
        expect_ok = True
    elif case == "urdf_doctype":
        members.append((urdf, b'<?xml version="1.0"?><!DOCTYPE robot SYSTEM "http://example.com/x.dtd">' + BASE_MEMBERS[urdf]))
        match = "DOCTYPE"
    elif case == "urdf_entities":
        lol = '<!DOCTYPE r [<!ENTITY a "aaaaaaaaaa">' + "".join(
            f'<!ENTITY a{i} "{("&a%d;" % (i - 1) if i > 1 else "&a;") * 10}">' for i in range(1, 9)) + "]>"
        members.append((urdf, (lol + BASE_MEMBERS[urdf].decode()).encode()))
        match = "entit"
    elif case == "urdf_not_utf8":
        members.append((urdf, b"\xff\xfe<robot/>"))
        match = "not UTF-8"
    elif case == "urdf_big":
        members.append((urdf, BASE_MEMBERS[urdf] + b" " * (17 << 20)))
        match = "max_text_bytes"
    elif case.startswith("urdf_mesh"):
        other = tmp_path.parent / f"{tmp_path.name}_other"  # a folder beside the session's, holding a part
        fname = {"urdf_mesh_escape": "package://lever/../../../etc/shadow.stl",
                 "urdf_mesh_absolute": "/etc/hosts.stl", "urdf_mesh_device": "package://zero.stl",
                 "urdf_mesh_own_root": f"package://{other}/secret_part.stl"}[case]
        text = BASE_MEMBERS[urdf].decode().replace('<box size="0.1 0.1 0.1"/>', f'<mesh filename="{fname}"/>')
        members.append((urdf, text.encode()))
        pkg = tmp_path / "pkg"
        pkg.mkdir()
        if case == "urdf_mesh_device":
            os.symlink("/dev/zero", pkg / "zero.stl")
        doc["robots"][1]["package_dirs"] = [str(pkg)]
        if case == "urdf_mesh_own_root":  # the file names "/" as its package folder: it allows nothing by itself
            other.mkdir()
            (other / "secret_part.stl").write_bytes(b"solid s\nendsolid s\n")
            doc["robots"][1]["package_dirs"] = ["/"]
        expect_ok = True  # the file loads; the robot is refused when it is built
    members = [(n, d) for n, d in members if not (n == urdf and case.startswith("urdf") and d == BASE_MEMBERS[urdf])]
    members = [(n, json.dumps(doc).encode() if n == "session.json" and d == BASE_MEMBERS["session.json"] else d)
               for n, d in members]
    src = _write(tmp_path, _zip(members, method))
    if expect_ok:
        s = viz.load_session(src)
        if case.startswith("urdf_mesh"):
            with pytest.raises(SessionFormatError, match="outside|leaves|not a regular file"):
                s.robot("lever")
        return
    with pytest.raises(SessionFormatError, match=match):
        viz.load_session(src)


def test_too_many_members(tmp_path):
    members = list(BASE_MEMBERS.items()) + [(f"junk/{i}", b"") for i in range(20_001)]
    with pytest.raises(SessionFormatError, match="max_members"):
        viz.load_session(_write(tmp_path, _zip(members, zipfile.ZIP_STORED)))


# ---------------------------------------------------------------------------- the builder
GANTRY = robots.load("gantry_flower")
_anything = st.one_of(st.none(), st.booleans(), st.integers(-3, 3), st.floats(), st.text(max_size=12),
                      st.sampled_from(["\ud800", "a/b", "", " ", "x" * 101, "../../x", "\x00"]),
                      st.lists(st.floats(), max_size=7), st.dictionaries(st.text(max_size=5), st.floats(), max_size=3),
                      st.just(np.zeros((2, 3), dtype=complex)), st.just(object()))


@settings(max_examples=120 * EXPLORE)
@given(data=st.data(), method=st.sampled_from(["add_points", "add_box", "add_workspace", "add_history",
                                               "add_trajectory", "add_robot", "init", "save"]))
@example(data=None, method="metadata-surrogate")
@example(data=None, method="save-nul")
def test_builder_arguments(tmp_path_factory, data, method):
    folder = tmp_path_factory.mktemp("b")
    s = viz.Session(GANTRY)
    if method == "metadata-surrogate":
        call = (viz.Session, (GANTRY,), {"metadata": {"k": "\ud800"}})
    elif method == "save-nul":
        call = (s.save, (folder / "a\x00b.pinarms",), {})
    elif method == "init":
        call = (viz.Session, (data.draw(st.one_of(st.just(GANTRY), st.just("ur5"), _anything)),),
                {"title": data.draw(st.one_of(st.text(max_size=12), _anything)),
                 "metadata": data.draw(st.one_of(st.none(), st.dictionaries(st.text(max_size=5), st.integers()),
                                                 _anything))})
    elif method == "save":
        name = data.draw(st.one_of(st.text(max_size=12), st.sampled_from(["", ".", "..", "sub/x", "/", "x\x00"])))
        call = (s.save, (folder / name if name and "\x00" not in name else name,), {})
    else:
        odd = data.draw(st.sampled_from(["none", "none", "name", "value", "all"]))
        name = data.draw(_anything if odd in ("name", "all") else st.text(
            st.characters(blacklist_categories=("Cc", "Cs"), blacklist_characters="/"), min_size=1, max_size=12
        ).filter(str.strip))
        n = data.draw(st.integers(1, 4))
        pts = st.lists(st.lists(st.floats(-2, 2), min_size=3, max_size=3), min_size=n, max_size=n).map(np.array)
        valid = {
            "add_points": st.tuples(pts),
            "add_box": st.tuples(st.lists(st.floats(0.01, 2), min_size=3, max_size=3)),
            "add_workspace": st.tuples(st.just(robots.sample_workspace(GANTRY, 5, seed=1))),
            "add_history": st.tuples(st.fixed_dictionaries({"best": st.lists(st.floats(0, 9), min_size=n, max_size=n)})),
            "add_trajectory": st.tuples(st.just((np.linspace(0.0, 1.0, n + 1), GANTRY.random_q(n + 1, seed=n)))),
            "add_robot": st.tuples(st.sampled_from(["ur5", "scara_mushroom"])),
        }[method]
        n_odd = {"add_box": 3, "add_workspace": 1}.get(method, 1)
        values = data.draw(st.tuples(*[_anything] * data.draw(st.integers(1, n_odd))) if odd in ("value", "all")
                           else valid)
        if method == "add_robot":
            call = (s.add_robot, values, {"key": name})
        else:
            call = (getattr(s, method), (name, *values), {})
    before = listing(folder)
    fn, args, kwargs = call
    result, err = outcome(fn, *args, **kwargs)
    after = listing(folder)
    if method in ("save", "save-nul") and err is None:
        assert after[str(folder)] - before[str(folder)] <= {str(Path(result).relative_to(folder))}
    else:
        assert after == before, "a refused or non-saving call wrote a file"
    if err is None and method not in ("save", "save-nul", "init"):
        saved, err2 = outcome(s.save, folder / "ok.pinarms")
        assert err2 is None, err2
        assert viz.load_session(saved) == s
