"""The scene in a real browser: Debian's headless Chromium driven by Playwright.

Checks the exported HTML offline (file://, every other request blocked) and the live
viewer (127.0.0.1) as a user sees them when they open: the robot in view and not hidden by
the workspace cloud, the tcp path drawn, the title, the colour bar, the animation playing
with its controls on the page; and that the server leaves no process behind.

With ``PINARMS_DOCS_PICTURES=1`` the screenshots taken here are also written to ``docs/``
(the pictures of README.md and docs/viz.md): ``make docs-pictures``.
"""

from __future__ import annotations

import io
import json
import os
from pathlib import Path

import numpy as np
import pytest

from pinarms import viz

CHROMIUM = "/usr/bin/chromium"
ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
        "--disable-background-networking", "--disable-component-update", "--disable-sync"]
DOCS = Path(__file__).resolve().parents[2] / "docs"
WIDTH, HEIGHT = 1000, 700

pytestmark = [
    pytest.mark.browser,
    pytest.mark.skipif(not os.path.exists(CHROMIUM), reason=f"{CHROMIUM} is absent: install Debian's chromium (make browser)"),
]

TRAJ = "pick-place 3-5-3"
CLOUD = "scara cloud"

# JS: the pinarms subtree once the scene, its objects, the animation and the page overlay are there
READY = f"""() => {{
  const m = window.viewer && viewer.scene_tree.children.meshcat;
  const r = m && m.children.pinarms;
  if (!r || !r.children.robots || !r.children.paths || !r.children.workspace) return false;
  const p = r.children.paths.children[{TRAJ!r}], w = r.children.workspace.children[{CLOUD!r}];
  const vis = r.children.robots.children.scara && r.children.robots.children.scara.children.visuals;
  return !!(p && p.children['<object>'] && w && w.children['<object>'] && vis
            && Object.keys(vis.children).length >= 8 && viewer.animator.actions.length > 0
            && document.getElementById('pinarms-title'));
}}"""

CONTENTS = f"""() => {{
  const r = viewer.scene_tree.children.meshcat.children.pinarms;
  const vis = r.children.robots.children.scara.children.visuals.children;
  const kinds = {{}};
  for (const [k, v] of Object.entries(vis)) kinds[k] = v.children['<object>'] ? v.children['<object>'].object.type : null;
  const cloud = r.children.workspace.children[{CLOUD!r}].children['<object>'].object;
  const box = (id) => {{ const e = document.getElementById(id); if (!e || e.offsetParent === null) return null;
                        const b = e.getBoundingClientRect(); return [b.left, b.top, b.right, b.bottom]; }};
  const t = viewer.controls.target;
  return {{
    links: kinds,
    path: r.children.paths.children[{TRAJ!r}].children['<object>'].object.type,
    cloud: cloud.type,
    cloudCount: cloud.geometry.attributes.position.count,
    cloudOpacity: cloud.material.opacity,
    cloudTransparent: cloud.material.transparent,
    boxes: Object.keys(r.children.objects.children),
    actions: viewer.animator.actions.length,
    duration: viewer.animator.actions[0]._clip.duration,
    playing: viewer.animator.playing,
    title: document.title,
    heading: document.querySelector('#pinarms-title h1').textContent,
    colorbar: document.getElementById('pinarms-colorbar').innerText,
    colorbarBox: box('pinarms-colorbar'),
    controlsBox: box('pinarms-controls'),
    page: JSON.parse(r.object.pinarms_page),
    orbitTarget: [t.x, -t.z, t.y],
  }};
}}"""

HIDE = """(paths) => { for (const p of paths) viewer.set_property(p, 'visible', false); viewer.set_dirty(); }"""
SHOW = """(paths) => { for (const p of paths) viewer.set_property(p, 'visible', true); viewer.set_dirty(); }"""
ROBOT = [["meshcat", "pinarms", "robots"]]
CLOUD_NODE = [["meshcat", "pinarms", "workspace"]]
PATH_NODE = [["meshcat", "pinarms", "paths"]]


@pytest.fixture(scope="module")
def browser():
    sync_api = pytest.importorskip("playwright.sync_api")
    with sync_api.sync_playwright() as p:
        b = p.chromium.launch(executable_path=CHROMIUM, args=ARGS)
        yield b
        b.close()


def _shot(page, t: float | None = None) -> np.ndarray:
    """Screenshot (H, W, 3) of the page as shown, the animation paused at ``t`` (s) if given."""
    from PIL import Image

    if t is not None:
        page.evaluate(f"() => {{ const a = viewer.animator; a.play(); a.pause(); a.seek({t}); viewer.render(); }}")
    page.evaluate("() => new Promise(r => requestAnimationFrame(() => requestAnimationFrame(r)))")
    return np.asarray(Image.open(io.BytesIO(page.screenshot())).convert("RGB"), dtype=int)


def _diff(a: np.ndarray, b: np.ndarray, level: int = 24) -> np.ndarray:
    return np.any(np.abs(a - b) > level, axis=2)


def _mask_of(page, nodes: list, t: float) -> np.ndarray:
    """Pixels that change when ``nodes`` are hidden (what of them the user sees), at time ``t``."""
    shown = _shot(page, t)
    page.evaluate(HIDE, nodes)
    hidden = _shot(page, t)
    page.evaluate(SHOW, nodes)
    return _diff(shown, hidden)


def _save_picture(image: np.ndarray, name: str) -> None:
    if os.environ.get("PINARMS_DOCS_PICTURES") == "1":
        from PIL import Image

        Image.fromarray(image.astype(np.uint8)).save(DOCS / name, optimize=True)


def _visual_geometry_names(name: str) -> set[str]:
    """Every visual geometry of a built-in arm's URDF, as Pinocchio names them (the page draws each)."""
    import pinocchio as pin

    from pinarms.robots.registry import builtin_urdf_path

    _, _, visual = pin.buildModelsFromUrdf(str(builtin_urdf_path(name)))
    names = {g.name for g in visual.geometryObjects}
    assert len(names) >= 6
    return names


def _check_page(page, session, picture: str | None = None) -> None:
    page.wait_for_function(READY, timeout=30000)
    got = page.evaluate(CONTENTS)
    assert set(got["links"]) == _visual_geometry_names("scara_mushroom")
    assert all(kind == "Mesh" for kind in got["links"].values())
    assert got["path"] == "Mesh"  # a tube: WebGL draws lines one pixel wide
    assert got["cloud"] == "Points"
    assert got["cloudCount"] == session.workspaces[CLOUD].points.shape[0]
    assert got["cloudTransparent"] and got["cloudOpacity"] == pytest.approx(0.3)
    assert sorted(got["boxes"]) == ["conveyor", "crate"]
    assert got["actions"] == len(got["links"])  # one track group per visual geometry
    assert got["duration"] == pytest.approx(3.607, abs=1.0 / 30 + 1e-6)
    assert got["playing"], "the animation does not play when the page opens"
    # the title names the study, the colour bar says what the colours mean, the controls are on the page
    assert got["title"] == got["heading"] == session.title
    assert "manipulability" in got["colorbar"]
    w_max = float(session.workspaces[CLOUD].manipulability.max())
    assert f"{w_max:.3g}".lstrip("0") in got["colorbar"] or f"{w_max:.2e}" in got["colorbar"]
    for box in (got["colorbarBox"], got["controlsBox"]):
        assert box is not None and 0 <= box[0] < box[2] <= WIDTH and 0 <= box[1] < box[3] <= HEIGHT
    # the orbit is centred on the robot and its path (world frame), not on the world origin
    np.testing.assert_allclose(got["orbitTarget"], got["page"]["target"], atol=1e-6)
    arm = session.robot("scara")
    tcp = arm.position(session.trajectories[TRAJ].q)
    assert np.linalg.norm(np.asarray(got["page"]["target"]) - tcp.mean(axis=0)) < 0.35

    # robot pixels: seen as the page opens (cloud shown), framed, and not hidden by the cloud
    robot_seen = _mask_of(page, ROBOT, 0.0)
    page.evaluate(HIDE, CLOUD_NODE)
    robot_alone = _mask_of(page, ROBOT, 0.0)
    path_alone = _mask_of(page, PATH_NODE, 0.0)
    page.evaluate(SHOW, CLOUD_NODE)
    area = robot_alone.mean()
    assert area > 0.03, f"the robot covers {area:.1%} of the page: not framed on it"
    rows, cols = np.nonzero(robot_alone)
    assert rows.min() > 0 and rows.max() < HEIGHT - 1 and cols.min() > 0 and cols.max() < WIDTH - 1, "robot cut off"
    assert abs(cols.mean() / WIDTH - 0.5) < 0.25 and abs(rows.mean() / HEIGHT - 0.5) < 0.25, "robot off centre"
    seen = (robot_seen & robot_alone).sum() / robot_alone.sum()
    assert seen > 0.9, f"the cloud hides {1 - seen:.0%} of the robot"
    assert path_alone.sum() > 1500, "the tcp path is hardly visible"

    # the animation: the robot moves; the page's controls pause it and move it in time
    start, middle = _shot(page, 0.0), _shot(page, 1.8)
    assert _diff(start, middle).sum() > 2000, "the robot did not move between t = 0 s and t = 1.8 s"
    page.evaluate("() => viewer.animator.play()")
    page.click("#pinarms-play")
    assert page.evaluate("() => viewer.animator.playing") is False
    page.fill("#pinarms-time", "1.8")
    page.dispatch_event("#pinarms-time", "input")
    t_now = page.evaluate("() => Math.max(...viewer.animator.actions.map(a => a.time))")
    assert t_now == pytest.approx(1.8, abs=1e-6)
    # the cloud switch hides and shows the cloud
    page.click("#pinarms-cloud")
    assert page.evaluate(f"() => viewer.scene_tree.children.meshcat.children.pinarms.children.workspace"
                         f".children[{CLOUD!r}].object.visible") is False
    page.click("#pinarms-cloud")
    if picture:
        _save_picture(_shot(page, 1.8), picture)


def _offline_page(browser, url: str):
    page = browser.new_page(viewport={"width": WIDTH, "height": HEIGHT})
    blocked: list[str] = []

    def only_local(route):
        if route.request.url.startswith(("file:", "data:", "blob:", "http://127.0.0.1:")):
            route.continue_()
        else:
            blocked.append(route.request.url)
            route.abort()

    page.route("**/*", only_local)
    page.goto(url)
    return page, blocked


def test_exported_html_offline(browser, line_session, tmp_path):
    out = viz.export_html(line_session, tmp_path / "line.html")
    page, blocked = _offline_page(browser, Path(out).resolve().as_uri())
    _check_page(page, line_session, picture="viz_scene.png")
    assert blocked == []  # the page needed nothing from the network
    page.close()


def test_live_viewer(browser, line_session):
    viewer = viz.show(line_session, port=None)
    pid = viewer.pid
    try:
        assert viewer.url.startswith("http://127.0.0.1:")
        page, outside = _offline_page(browser, viewer.url)
        _check_page(page, line_session)
        assert outside == []
        page.close()
    finally:
        viewer.close()
    assert not viewer.running
    assert not os.path.exists(f"/proc/{pid}"), "the MeshCat server process is still there"


@pytest.mark.slow
@pytest.mark.xdist_group("demo-studies")  # shares the quick studies (tests/conftest.py)
def test_demo_seed001_page(browser, tmp_path, quick_study):
    """The first page a user opens (``make demo``: html/seed001.html): the AUBO-i3 inside its workspace cloud."""
    s = quick_study("001").session
    out = viz.export_html(s, tmp_path / "seed001.html")
    page, blocked = _offline_page(browser, Path(out).resolve().as_uri())
    page.wait_for_function("() => document.getElementById('pinarms-title') && viewer.animator.actions.length > 0",
                           timeout=30000)
    page.wait_for_function("() => Object.keys(viewer.scene_tree.children.meshcat.children.pinarms.children.robots"
                           ".children.aubo_i3.children.visuals.children).length >= 10", timeout=30000)
    info = json.loads(page.evaluate("() => viewer.scene_tree.children.meshcat.children.pinarms.object.pinarms_page"))
    assert info["colorbar"]["unit"] == "m³" and page.title() == info["title"] == s.title
    assert page.evaluate("() => viewer.animator.playing")
    seen = _mask_of(page, ROBOT, 0.0)
    page.evaluate(HIDE, CLOUD_NODE)
    alone = _mask_of(page, ROBOT, 0.0)
    page.evaluate(SHOW, CLOUD_NODE)
    assert alone.mean() > 0.01, f"the arm covers {alone.mean():.1%} of the page"
    assert (seen & alone).sum() / alone.sum() > 0.9, "the cloud hides the arm"
    _save_picture(_shot(page, 2.0), "demo_seed001_page.png")
    assert blocked == []
    page.close()
