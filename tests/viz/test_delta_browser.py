"""A delta's page in headless Chromium: the closed chain drawn where pinarms' kinematics put it, and animated.

The page is a saved session's (a delta and its motion, :mod:`pinarms.viz.delta_record`) exported as
one HTML file. Read back from three.js in the browser at animation frames: every part's world
transform. Compared with an independent route: Pinocchio's forward kinematics of the tree at the
configuration Newton's projection onto the closures gives (:meth:`DeltaRobot.project`), not the closed
form the page was drawn from.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from pinarms import viz
from pinarms.robots.delta import load_delta, rod_endpoints

CHROMIUM = "/usr/bin/chromium"
ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
        "--disable-background-networking", "--disable-component-update", "--disable-sync"]
KEY = "picker"
FPS = 30.0
#: Positions on the page are float32 (about 1e-7 relative at 2 m) and seeking lands within 1e-6 s of a frame.
TOL_M = 1e-5

pytestmark = [
    pytest.mark.browser,
    pytest.mark.skipif(not os.path.exists(CHROMIUM), reason=f"{CHROMIUM} is absent: install Debian's chromium (make browser)"),
]

PARTS = [f"upper_arm_{i}" for i in (1, 2, 3)] + [f"rod_{i}{r}" for i in (1, 2, 3) for r in "ab"] + ["platform", "tool"]

READY = f"""() => {{
  const m = window.viewer && viewer.scene_tree.children.meshcat;
  const d = m && m.children.pinarms && m.children.pinarms.children.deltas;
  const k = d && d.children[{KEY!r}];
  return !!(k && Object.keys(k.children).length == {len(PARTS)} && viewer.animator.actions.length > 0
            && document.getElementById('pinarms-title'));
}}"""

# every part's world transform relative to the /meshcat node (pinarms' world frame), at time t
POSES = f"""(t) => {{
  const a = viewer.animator; a.play(); a.pause(); a.seek(t); viewer.render();
  const m = viewer.scene_tree.children.meshcat;
  m.object.updateMatrixWorld(true);
  const out = {{root: m.object.matrixWorld.elements.slice(), parts: {{}}, kinds: {{}}}};
  for (const [k, v] of Object.entries(m.children.pinarms.children.deltas.children[{KEY!r}].children)) {{
    out.parts[k] = v.object.matrixWorld.elements.slice();
    const o = v.children['<object>'];
    out.kinds[k] = o ? [o.object.type, o.object.geometry.type] : null;
  }}
  return out;
}}"""


def _motion() -> tuple[np.ndarray, np.ndarray]:
    """2 s at 30 Hz (a sample a frame): motor angles within the range, the tool turning by 1.5 rad."""
    t = np.arange(61) / FPS
    th = 0.35 + 0.35 * np.sin(np.pi * t[:, None] + np.array([0.0, 2.1, 4.2]))
    return t, np.column_stack([th, 0.75 * t])


@pytest.fixture(scope="module")
def page_and_session(tmp_path_factory):
    sync_api = pytest.importorskip("playwright.sync_api")
    s = viz.Session(title="delta: the closed chain")
    base = np.eye(4)
    c, sn = np.cos(0.4), np.sin(0.4)
    base[:3, :3] = [[c, -sn, 0.0], [sn, c, 0.0], [0.0, 0.0, 1.0]]  # turned about z: the world frame is not the base's
    base[:3, 3] = [0.5, -0.3, 1.9]
    s.add_delta("delta_flexpicker", key=KEY, base_to_world=base, motion=_motion())
    path = s.save(tmp_path_factory.mktemp("delta_page") / "delta.pinarms")
    out = viz.export_html(viz.load_session(path), path.with_suffix(".html"))  # the page of the file, not the object
    with sync_api.sync_playwright() as p:
        browser = p.chromium.launch(executable_path=CHROMIUM, args=ARGS)
        page = browser.new_page(viewport={"width": 900, "height": 640})
        blocked = []
        page.route("**/*", lambda r: r.continue_() if r.request.url.startswith(("file:", "data:", "blob:"))
                   else (blocked.append(r.request.url), r.abort()))
        page.goto(Path(out).resolve().as_uri())
        page.wait_for_function(READY, timeout=15000)
        yield page, s, blocked
        browser.close()


def _world(got: dict) -> dict[str, np.ndarray]:
    """Each part's (4, 4) pose in pinarms' world frame, from three.js' column-major world matrices."""
    root_inv = np.linalg.inv(np.array(got["root"]).reshape(4, 4).T)
    return {k: root_inv @ np.array(v).reshape(4, 4).T for k, v in got["parts"].items()}


def test_delta_page_draws_the_closed_chain(page_and_session):
    """At three animation frames: the platform where Pinocchio's FK of the projected tree puts it, every
    rod's two ends on its elbow and platform ball centres, every upper arm from its motor axis to its
    elbow, the tool turned by its angle; the meshes are there and the platform moves."""
    page, s, blocked = page_and_session
    rec = s.deltas[KEY]
    delta = load_delta(rec.delta)
    g = delta.geometry
    T = rec.base_to_world
    model, data = delta.model, delta.model.createData()
    plat = model.getFrameId("platform_link")
    frames = (0, 17, 44)
    q = delta.project(rec.theta[list(frames)], chain=True)  # Newton on the closures, not the closed form
    q[:, delta.tool_q] = rec.tool[list(frames)]
    rods = rod_endpoints(delta, q)  # ball centres from Pinocchio's frames (base frame)
    platforms = []
    for n, k in enumerate(frames):
        got = page.evaluate(POSES, k / FPS)
        assert set(got["kinds"]) == set(PARTS)
        assert all(v is not None and v[0] == "Mesh" for v in got["kinds"].values()), got["kinds"]
        assert got["kinds"]["tool"][1] == "BoxGeometry" and got["kinds"]["rod_1a"][1] == "CylinderGeometry"
        pose = _world(got)
        pin.framesForwardKinematics(model, data, q[n])
        p_fk = T[:3, :3] @ data.oMf[plat].translation + T[:3, 3]
        np.testing.assert_allclose(pose["platform"][:3, 3], p_fk, atol=TOL_M)
        platforms.append(p_fk)
        for i in range(3):
            for r, tag in enumerate("ab"):
                P = pose[f"rod_{i + 1}{tag}"]
                ends = P[:3, 3] + np.outer([-0.5, 0.5], g.forearm * P[:3, 1])  # MeshCat's cylinder axis: y
                want = rods[n, i, r] @ T[:3, :3].T + T[:3, 3]
                np.testing.assert_allclose(ends, want, atol=TOL_M)
            A = pose[f"upper_arm_{i + 1}"]
            arm_ends = A[:3, 3] + np.outer([-0.5, 0.5], g.upper_arm * A[:3, 1])
            elbow = 0.5 * (rods[n, i, 0, 0] + rods[n, i, 1, 0])  # the elbow: midway between its two rod tops
            motor = g.base_radius * g.radial[i]
            np.testing.assert_allclose(arm_ends, np.array([motor, elbow]) @ T[:3, :3].T + T[:3, 3], atol=TOL_M)
        # the tool's paddle turns as Pinocchio's tcp frame does, and ends at the tcp
        tcp = data.oMf[model.getFrameId("tcp")]
        R_tcp = T[:3, :3] @ tcp.rotation
        if n == 0:
            x0, R0 = pose["tool"][:3, 0], R_tcp
        np.testing.assert_allclose(pose["tool"][:3, 0], R_tcp @ R0.T @ x0, atol=1e-5)
        tip = pose["tool"][:3, 3] + 0.5 * np.linalg.norm(delta.tcp_position(q[n]) - data.oMf[plat].translation) \
            * pose["tool"][:3, 1]
        np.testing.assert_allclose(tip, T[:3, :3] @ tcp.translation + T[:3, 3], atol=TOL_M)
    assert abs(rec.tool[frames[-1]] - rec.tool[0]) > 1.0  # the tool did turn between the frames compared
    assert np.linalg.norm(platforms[1] - platforms[0]) > 0.05, "the platform did not move"
    assert blocked == []
