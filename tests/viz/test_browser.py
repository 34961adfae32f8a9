"""The scene in a real browser: Debian's headless Chromium driven by Playwright.

Checks the exported HTML offline (file://, every other request blocked) and the live
viewer (127.0.0.1), and that the server leaves no process behind.
"""

from __future__ import annotations

import io
import os
from pathlib import Path

import numpy as np
import pytest

from pinarms import viz

CHROMIUM = "/usr/bin/chromium"
ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
        "--disable-background-networking", "--disable-component-update", "--disable-sync"]

pytestmark = [
    pytest.mark.browser,
    pytest.mark.skipif(not os.path.exists(CHROMIUM), reason=f"{CHROMIUM} is absent: install Debian's chromium (make browser)"),
]

TRAJ = "pick-place 3-5-3"
CLOUD = "scara cloud"

# JS: the pinarms subtree once the scene, its objects and the animation have been replayed
READY = f"""() => {{
  const m = window.viewer && viewer.scene_tree.children.meshcat;
  const r = m && m.children.pinarms;
  if (!r || !r.children.robots || !r.children.paths || !r.children.workspace) return false;
  const p = r.children.paths.children[{TRAJ!r}], w = r.children.workspace.children[{CLOUD!r}];
  const vis = r.children.robots.children.scara && r.children.robots.children.scara.children.visuals;
  return !!(p && p.children['<object>'] && w && w.children['<object>'] && vis
            && Object.keys(vis.children).length >= 8 && viewer.animator.actions.length > 0);
}}"""

CONTENTS = f"""() => {{
  const r = viewer.scene_tree.children.meshcat.children.pinarms;
  const vis = r.children.robots.children.scara.children.visuals.children;
  const kinds = {{}};
  for (const [k, v] of Object.entries(vis)) kinds[k] = v.children['<object>'] ? v.children['<object>'].object.type : null;
  return {{
    links: kinds,
    path: r.children.paths.children[{TRAJ!r}].children['<object>'].object.type,
    cloud: r.children.workspace.children[{CLOUD!r}].children['<object>'].object.type,
    cloudCount: r.children.workspace.children[{CLOUD!r}].children['<object>'].object.geometry.attributes.position.count,
    boxes: Object.keys(r.children.objects.children),
    actions: viewer.animator.actions.length,
    duration: viewer.animator.actions[0]._clip.duration,
  }};
}}"""


@pytest.fixture(scope="module")
def browser():
    sync_api = pytest.importorskip("playwright.sync_api")
    with sync_api.sync_playwright() as p:
        b = p.chromium.launch(executable_path=CHROMIUM, args=ARGS)
        yield b
        b.close()


def _plain_shot(page, t: float) -> np.ndarray:
    """Screenshot (H, W, 3) at animation time ``t`` (s) with background, grid and axes hidden."""
    from PIL import Image

    page.evaluate("""() => { for (const n of [['Background'], ['Grid'], ['Axes']]) viewer.set_property(n, 'visible', false);
                             const c = document.querySelector('.dg.main'); if (c) c.style.display = 'none'; }""")
    page.evaluate(f"() => {{ const a = viewer.animator; a.play(); a.pause(); a.seek({t}); viewer.render(); }}")
    png = page.screenshot()
    return np.asarray(Image.open(io.BytesIO(png)).convert("RGB"), dtype=int)


def _check_page(page, line_session) -> None:
    page.wait_for_function(READY, timeout=20000)
    got = page.evaluate(CONTENTS)
    assert set(got["links"]) == {"base_link_0", "upper_arm_link_0", "upper_arm_link_1", "j2_drive_0",
                                 "forearm_link_0", "j34_drives_0", "quill_link_0", "hand_link_0", "gripper_0"}
    assert all(kind == "Mesh" for kind in got["links"].values())
    assert got["path"] == "Line"
    assert got["cloud"] == "Points"
    assert got["cloudCount"] == line_session.workspaces[CLOUD].points.shape[0]
    assert sorted(got["boxes"]) == ["conveyor", "crate"]
    assert got["actions"] == 9  # one track group per visual geometry
    assert got["duration"] == pytest.approx(3.607, abs=1.0 / 30 + 1e-6)

    start, middle = _plain_shot(page, 0.0), _plain_shot(page, 1.8)
    background = start[-1, -1]
    drawn = np.any(np.abs(start - background) > 24, axis=2)
    assert drawn.mean() > 0.01, "the page looks blank"
    changed = np.any(np.abs(start - middle) > 24, axis=2)
    assert changed.sum() > 500, "the robot did not move between t = 0 s and t = 1.8 s"


def test_exported_html_offline(browser, line_session, tmp_path):
    out = viz.export_html(line_session, tmp_path / "line.html")
    page = browser.new_page(viewport={"width": 800, "height": 600})
    blocked: list[str] = []

    def only_local(route):
        url = route.request.url
        if url.startswith(("file:", "data:", "blob:")):
            route.continue_()
        else:
            blocked.append(url)
            route.abort()

    page.route("**/*", only_local)
    page.goto(Path(out).resolve().as_uri())
    _check_page(page, line_session)
    assert blocked == []  # the page needed nothing from the network
    page.close()


def test_live_viewer(browser, line_session):
    viewer = viz.show(line_session, port=None)
    pid = viewer.pid
    try:
        assert viewer.url.startswith("http://127.0.0.1:")
        page = browser.new_page(viewport={"width": 800, "height": 600})
        outside: list[str] = []

        def only_loopback(route):
            url = route.request.url
            if url.startswith(("http://127.0.0.1:", "data:", "blob:")):
                route.continue_()
            else:
                outside.append(url)
                route.abort()

        page.route("**/*", only_loopback)
        page.goto(viewer.url)
        _check_page(page, line_session)
        assert outside == []
        page.close()
    finally:
        viewer.close()
    assert not viewer.running
    assert not os.path.exists(f"/proc/{pid}"), "the MeshCat server process is still there"
