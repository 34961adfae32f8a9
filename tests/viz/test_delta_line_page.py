"""`pinarms belt run --robot delta_flexpicker --session/--html`: the line's page with deltas above the belt.

One command (module fixture) writes the session and the page; read back: the deltas stored as their
actuated angles, their tcp (closed form) where Pinocchio's FK of the tree puts it, each picked item
met by the tool on the belt and carried by it, the page drawing every delta's parts.
"""

from __future__ import annotations

import numpy as np
import pytest
from click.testing import CliRunner

from pinarms.cli import cli
from pinarms.viz.delta_scene import delta_parts, session_delta_tcp
from pinarms.viz.line_record import MISSED
from pinarms.viz.line_scene import item_positions
from pinarms.viz.session import load_session

pytestmark = pytest.mark.slow  # one `belt run` with its task map: about 5 s of CPU


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    out = tmp_path_factory.mktemp("delta_line")
    args = ["belt", "run", "--robot", "delta_flexpicker", "--arms", "1", "--rate", "30", "--seeds", "1",
            "--duration", "20", "--map-grid", "4,3", "--window", "6", "--session", str(out / "line.pinarms"),
            "--html", str(out / "line.html")]
    r = CliRunner().invoke(cli, args)
    assert r.exit_code == 0, (r.output, r.exception)
    return load_session(out / "line.pinarms"), (out / "line.html").read_text(encoding="utf-8")


def test_deltas_stored_as_actuated_angles(written):
    s, _ = written
    assert not s.robots and not s.trajectories  # the deltas are not trees posed at zero
    rec = s.deltas["delta 1"]
    assert rec.delta == "delta_flexpicker" and rec.actuated.shape[1] == 4
    assert s.lines["line"].arms == ("delta 1",)
    assert rec.duration == pytest.approx(6.0) and np.ptp(rec.theta, axis=0).min() > 0.05  # it moves


def test_tcp_and_picked_items_follow_the_delta(written):
    """The tcp of the page (closed form plus the tool's offset) equals Pinocchio's FK of the tree's tcp frame;
    at each grasp the tcp is on the item's top (1 mm: the motion is stored at 30 Hz), and an
    item carried sits under the tcp."""
    s, _ = written
    rec, line = s.deltas["delta 1"], s.lines["line"]
    delta = s.delta("delta 1")
    times = np.linspace(0.0, rec.duration, 37)
    tcp = session_delta_tcp(s, "delta 1", times)
    act = rec.sample(times)
    q = delta.configuration(act[:, :3], tool=0.0)
    q[:, delta.tool_q] = act[:, 3]
    T = rec.base_to_world
    np.testing.assert_allclose(tcp, delta.tcp_position(q) @ T[:3, :3].T + T[:3, 3], atol=1e-9)
    picked = np.flatnonzero((line.items[:, 6] == 0) & (line.items[:, 7] > 0) & (line.items[:, 7] < rec.duration))
    assert picked.size >= 1
    B = line.belt_to_world
    for i in picked:
        t0, w, h, tg = line.items[i, 0], line.items[i, 1], line.items[i, 5], line.items[i, 7]
        at = session_delta_tcp(s, "delta 1", [tg])[0] - B[:3, 3]
        np.testing.assert_allclose(at @ B[:3, :3], [line.speed * (tg - t0), w, h], atol=1e-3)
    normal, _ = item_positions(line, times, {0: tcp})
    i = picked[0]
    carried = (times >= line.items[i, 7]) & (times < line.items[i, 8])
    assert carried.any()
    np.testing.assert_allclose(normal[i, carried], tcp[carried] - [0.0, 0.0, line.items[i, 5] / 2.0], atol=1e-12)
    assert not np.any(line.items[:, 6] == MISSED)


def test_page_draws_the_deltas(written):
    s, html = written
    import base64
    import re

    import msgpack

    blobs = re.findall(r'fetch\("data:application/octet-binary;base64,([A-Za-z0-9+/=]+)"\)', html)
    cmds = [msgpack.unpackb(base64.b64decode(b), raw=False, strict_map_key=False) for b in blobs]
    root = "/meshcat/pinarms/deltas/delta 1/"
    drawn = {c["path"][len(root):] for c in cmds if c.get("type") == "set_object" and c["path"].startswith(root)}
    assert drawn == set(delta_parts(s.delta("delta 1")))
    anim = [c for c in cmds if c.get("type") == "set_animation"]
    animated = {a["path"][len(root):] for a in anim[0]["animations"] if a["path"].startswith(root)}
    assert animated == drawn
    import json

    page = [json.loads(c["value"]) for c in cmds if c.get("type") == "set_property" and c.get("property") == "pinarms_page"]
    assert "1 arms along the belt (delta_flexpicker), each through its picks" in page[0]["lines"]
