"""A belt line in a session: round trip, what the animation shows, and hostile line sections refused by name."""

from __future__ import annotations

import io
import json
import zipfile

import numpy as np
import pytest

from pinarms import viz
from pinarms.errors import InvalidInput
from pinarms.viz.errors import SessionFormatError
from pinarms.viz.line_record import ITEM_COLUMNS, MAX_LINE_ITEMS, MISSED, LineRecord, make_line
from pinarms.viz.line_scene import item_positions


def _tcp_world(session, key: str, t: float) -> np.ndarray:
    rec = session.trajectories[f"{key} picks"]
    q = np.array([np.interp(t, rec.t, rec.q[:, j]) for j in range(rec.q.shape[1])])
    T = session.robots[key].base_to_world
    return session.robot(key).position(q) @ T[:3, :3].T + T[:3, 3]


def test_round_trip_is_exact(belt_session, tmp_path):
    path = belt_session.save(tmp_path / "belt.pinarms")
    back = viz.load_session(path)
    assert back == belt_session
    a, b = belt_session.lines["belt"], back.lines["belt"]
    assert a.items.tobytes() == b.items.tobytes() and a.arms == b.arms == ("scara 1", "scara 2")
    assert (a.length, a.width, a.speed, a.u_miss, a.duration) == (b.length, b.width, b.speed, b.u_miss, b.duration)
    assert set(back.trajectories) == {"scara 1 picks", "scara 2 picks"}


def test_items_follow_the_simulation(belt_line, belt_session):
    spec, result = belt_line
    run, rec = result.runs[0], belt_session.lines["belt"]
    assert rec.items.shape[1] == len(ITEM_COLUMNS) and rec.n_picked >= 3 and rec.n_missed >= 1
    by_t0 = {round(float(t), 9): k for k, t in enumerate(run.t0)}
    for row in rec.items:
        i = by_t0[round(float(row[0]), 9)]  # window starts at 0: times are the run's
        assert int(row[6]) == (MISSED if run.picked_by[i] < 0 else run.picked_by[i])
    # each grasp drawn inside the window: the tool is on the item's top (FK of the replanned joints) within 1 mm
    belt = spec.belt
    grasped = [row for row in rec.items if row[6] >= 0 and row[7] < rec.duration]
    assert len(grasped) >= 3
    for row in grasped:
        tool = _tcp_world(belt_session, rec.arms[int(row[6])], row[7])
        item_top = belt.to_world(belt.speed * (row[7] - row[0]), row[1], row[5])
        assert np.linalg.norm(tool - item_top) < 1e-3


def test_item_positions_on_belt_carried_and_missed(belt_line, belt_session):
    spec, _ = belt_line
    rec, belt = belt_session.lines["belt"], spec.belt
    times = np.linspace(0.0, rec.duration, 241)
    tcp = {k: np.array([_tcp_world(belt_session, key, t) for t in times]) for k, key in enumerate(rec.arms)}
    normal, red = item_positions(rec, times, tcp)
    for i, row in enumerate(rec.items):
        u = belt.speed * (times - row[0])
        riding = (u >= 0) & (u <= rec.length) & ((times < row[7]) if row[6] >= 0 else (u < rec.u_miss))
        expect = belt.to_world(u[riding], row[1], row[5] / 2.0)
        np.testing.assert_allclose(normal[i, riding], expect, atol=1e-9)
        hidden = ~((u >= 0) & (u <= rec.length)) & ((times < row[7]) if row[6] >= 0 else True)
        assert np.all(belt.to_belt(normal[i, hidden])[:, 2] < 0)  # inside the belt
        if row[6] == MISSED:
            past = (u >= rec.u_miss) & (u <= rec.length)
            np.testing.assert_allclose(red[i, past], belt.to_world(u[past], row[1], row[5] / 2.0), atol=1e-9)
            assert np.all(belt.to_belt(red[i, ~past])[:, 2] < 0)
        elif row[6] >= 0 and row[8] < rec.duration:
            carried = (times >= row[7]) & (times < row[8])
            np.testing.assert_allclose(normal[i, carried], tcp[int(row[6])][carried] - [0, 0, row[5] / 2.0], atol=1e-9)


def test_add_line_bad_input(belt_line):
    spec, result = belt_line
    s = viz.Session()
    with pytest.raises(InvalidInput, match="window"):
        s.add_line(spec, result, start=-1.0)
    with pytest.raises(InvalidInput, match="window"):
        s.add_line(spec, result, duration=float("nan"))
    with pytest.raises(InvalidInput, match="run must index"):
        s.add_line(spec, result, run=3)
    assert s.lines == {} and s.robots == {}


def test_make_line_takes_one_draft_record():
    """make_line checks a LineRecord draft: floats and read-only arrays out, InvalidInput naming the line."""
    item = [[0.5, 0.0, 0.0, 0.1, 0.1, 0.05, MISSED, 0.0, 0.0]]
    draft = LineRecord("belt", ("a",), np.eye(4).tolist(), length=2, width=0.6, thickness=0.05, speed=0.2,
                       u_miss=2, duration=5, items=item)
    rec = make_line(draft)
    assert (rec.length, rec.u_miss, rec.items.shape) == (2.0, 2.0, (1, len(ITEM_COLUMNS)))
    assert isinstance(rec.length, float) and not rec.items.flags.writeable and not rec.belt_to_world.flags.writeable
    bad_pose = LineRecord("belt", ("a",), np.full((4, 4), np.nan), 2, 0.6, 0.05, 0.2, 2, 5, item)
    with pytest.raises(InvalidInput, match="line 'belt': belt_to_world must be a finite"):
        make_line(bad_pose)
    off_belt = LineRecord("belt", ("a",), np.eye(4), 2, 0.6, 0.05, 0.2, 3, 5, item)
    with pytest.raises(InvalidInput, match="u_miss must lie on the belt"):
        make_line(off_belt)


# ---------------------------------------------------------------------------- hostile files
def _rewrite(src, dst, *, line=None, items=None):
    """Copy session ``src`` to ``dst`` with the first line's JSON fields updated and its items array replaced."""
    with zipfile.ZipFile(src) as zin:
        members = {n: zin.read(n) for n in zin.namelist()}
    doc = json.loads(members["session.json"])
    entry = doc["lines"][0]
    entry.update(line or {})
    if items is not None:
        member = entry["items"]["member"]
        buf = io.BytesIO()
        np.save(buf, np.ascontiguousarray(items, dtype="<f8"), allow_pickle=False)
        members[member] = buf.getvalue()
        entry["items"]["shape"] = list(items.shape)
    members["session.json"] = json.dumps(doc).encode()
    with zipfile.ZipFile(dst, "w", zipfile.ZIP_DEFLATED) as zout:
        for n, data in members.items():
            zout.writestr(n, data)
    return dst


@pytest.fixture(scope="module")
def saved(belt_session, tmp_path_factory):
    return belt_session.save(tmp_path_factory.mktemp("line") / "ok.pinarms")


@pytest.mark.parametrize("fields, message", [
    ({"length": -1.0}, r"lines\[0\]: length must be a number in \(0"),
    ({"speed": 0}, r"lines\[0\]: speed must be"),
    ({"width": 1e300}, r"lines\[0\]: width must be"),
    ({"u_miss": 1e6}, r"lines\[0\]: u_miss must lie on the belt"),
    ({"duration": "8"}, r"lines\[0\]\.duration has the wrong type"),
    ({"arms": ["scara 1", "scara 1"]}, r"lines\[0\]: arms must name"),
    ({"arms": "scara 1"}, r"lines\[0\]\.arms has the wrong type"),
])
def test_hostile_fields_refused(saved, tmp_path, fields, message):
    bad = _rewrite(saved, tmp_path / "bad.pinarms", line=fields)
    with pytest.raises(SessionFormatError, match=message):
        viz.load_session(bad)


def _items_with(saved, change):
    with zipfile.ZipFile(saved) as z:
        doc = json.loads(z.read("session.json"))
        data = z.read(doc["lines"][0]["items"]["member"])
    items = np.load(io.BytesIO(data), allow_pickle=False).copy()
    change(items)
    return items


@pytest.mark.parametrize("change, message", [
    (lambda a: a.__setitem__((0, 0), np.nan), r"holds NaN or infinite values"),
    (lambda a: a.__setitem__((0, 3), -0.1), r"lines\[0\]: items' length, width and height must be > 0"),
    (lambda a: a.__setitem__((0, 1), 0.2), r"lines\[0\]: an item lies off the belt"),
    (lambda a: a.__setitem__((0, 6), 7), r"lines\[0\]: items' arm must be an index"),
    (lambda a: a.__setitem__((0, 6), 0.5), r"lines\[0\]: items' arm must be an index"),
])
def test_hostile_items_refused(saved, tmp_path, change, message):
    bad = _rewrite(saved, tmp_path / "bad.pinarms", items=_items_with(saved, change))
    with pytest.raises(SessionFormatError, match=message):
        viz.load_session(bad)


def test_huge_and_misshapen_item_tables_refused(saved, tmp_path):
    row = _items_with(saved, lambda a: None)[:1]
    huge = np.repeat(row, MAX_LINE_ITEMS + 1, axis=0)
    with pytest.raises(SessionFormatError, match=f"more than the {MAX_LINE_ITEMS:,}"):
        viz.load_session(_rewrite(saved, tmp_path / "huge.pinarms", items=huge))
    with pytest.raises(SessionFormatError, match=r"items.npy. has shape \(3, 5\), expected \(3, 9\)"):
        viz.load_session(_rewrite(saved, tmp_path / "cols.pinarms", items=np.zeros((3, 5))))


def test_arms_naming_no_robot_refused_when_drawn(saved, tmp_path):
    from pinarms.viz.errors import ViewerError

    bad = viz.load_session(_rewrite(saved, tmp_path / "ghost.pinarms", line={"arms": ["ghost 1", "ghost 2"]}))
    with pytest.raises(ViewerError, match="arm 'ghost 1', which is not a robot or delta of this session"):
        viz.export_html(bad, tmp_path / "ghost.html")
    assert not (tmp_path / "ghost.html").exists()


def test_save_line_views_writes_session_page_and_schedule(belt_line, tmp_path):
    from pinarms.viz.line_views import save_line_views

    spec, result = belt_line
    paths = save_line_views(spec, result, session=tmp_path / "l.pinarms", html=tmp_path / "l.html",
                            schedule=tmp_path / "l.svg", duration=3.0)
    assert [p.name for p in paths] == ["l.pinarms", "l.html", "l.svg"]
    back = viz.load_session(tmp_path / "l.pinarms")
    rec = next(iter(back.lines.values()))
    assert rec.duration == 3.0 and rec.arms == tuple(st.name for st in spec.stations)
    assert "<title>belt line: 2 arm(s), 90 items/min, belt 0.2 m/s</title>" in (tmp_path / "l.html").read_text()
    assert "missed" in (tmp_path / "l.svg").read_text()


def test_long_line_opens_on_its_first_arms(belt_session, monkeypatch):
    from pinarms.viz import line_scene

    rec = belt_session.lines["belt"]
    T = rec.belt_to_world
    pts = T[:3, 3] + np.outer(np.linspace(0.0, rec.length, 11), T[:3, 0])  # along the whole belt
    assert line_scene.line_focus(belt_session, pts) is pts  # two arms: everything framed
    monkeypatch.setattr(line_scene, "FRAMED_ARMS", 1)
    u_first = (belt_session.robots["scara 1"].base_to_world[:3, 3] - T[:3, 3]) @ T[:3, 0]
    u = (line_scene.line_focus(belt_session, pts) - T[:3, 3]) @ T[:3, 0]
    assert u.max() == pytest.approx(u_first + 0.6) and u.min() == pytest.approx(0.0)
    assert np.count_nonzero(u <= u_first + 0.6 + 1e-9) == u.size
