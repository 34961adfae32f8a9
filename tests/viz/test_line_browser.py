"""A belt line's standalone page in headless Chromium: the belt, the arms, the items moving with time."""

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
WIDTH, HEIGHT = 1000, 700
DOCS = Path(__file__).resolve().parents[2] / "docs"
HIDE = """(paths) => { for (const p of paths) viewer.set_property(p, 'visible', false); viewer.set_dirty(); }"""
SHOW = """(paths) => { for (const p of paths) viewer.set_property(p, 'visible', true); viewer.set_dirty(); }"""

pytestmark = [
    pytest.mark.browser,
    pytest.mark.skipif(not os.path.exists(CHROMIUM), reason=f"{CHROMIUM} is absent: install Debian's chromium (make browser)"),
]

READY = """() => {
  const m = window.viewer && viewer.scene_tree.children.meshcat;
  const r = m && m.children.pinarms;
  const line = r && r.children.lines && r.children.lines.children.belt;
  const items = line && line.children.items;
  return !!(items && line.children.belt.children['<object>'] && Object.keys(items.children).length >= N
            && r.children.robots && Object.keys(r.children.robots.children).length == 2
            && viewer.animator.actions.length > 0 && document.getElementById('pinarms-title'));
}"""

POSITIONS = """(t) => {
  const a = viewer.animator; a.play(); a.pause(); a.seek(t); viewer.render();
  const items = viewer.scene_tree.children.meshcat.children.pinarms.children.lines.children.belt.children.items;
  const out = {};
  for (const [k, v] of Object.entries(items.children)) { const p = v.object.position; out[k] = [p.x, p.y, p.z]; }
  return out;
}"""

BELT = [["meshcat", "pinarms", "lines", "belt", "belt"]]
ITEMS = [["meshcat", "pinarms", "lines", "belt", "items"], ["meshcat", "pinarms", "lines", "belt", "missed"]]
ROBOTS = [["meshcat", "pinarms", "robots"]]


def _shot(page, t: float) -> np.ndarray:
    """Screenshot (H, W, 3) of the page, the animation paused at ``t`` [s]."""
    from PIL import Image

    page.evaluate(f"() => {{ const a = viewer.animator; a.play(); a.pause(); a.seek({t}); viewer.render(); }}")
    page.evaluate("() => new Promise(r => requestAnimationFrame(() => requestAnimationFrame(r)))")
    return np.asarray(Image.open(io.BytesIO(page.screenshot())).convert("RGB"), dtype=int)


def _diff(a: np.ndarray, b: np.ndarray, level: int = 24) -> np.ndarray:
    return np.any(np.abs(a - b) > level, axis=2)


def _offline_page(browser, url: str):
    """The page at ``url`` with every request off this machine refused (and listed)."""
    page = browser.new_page(viewport={"width": WIDTH, "height": HEIGHT})
    blocked: list[str] = []

    def only_local(route):
        if route.request.url.startswith(("file:", "data:", "blob:")):
            route.continue_()
        else:
            blocked.append(route.request.url)
            route.abort()

    page.route("**/*", only_local)
    page.goto(url)
    return page, blocked


@pytest.fixture(scope="module")
def browser():
    sync_api = pytest.importorskip("playwright.sync_api")
    with sync_api.sync_playwright() as p:
        b = p.chromium.launch(executable_path=CHROMIUM, args=ARGS)
        yield b
        b.close()


def test_page_shows_belt_arms_and_moving_items(browser, belt_session, belt_line, tmp_path):
    spec, _ = belt_line
    rec = belt_session.lines["belt"]
    out = viz.export_html(belt_session, tmp_path / "belt.html")
    page, blocked = _offline_page(browser, Path(out).resolve().as_uri())
    page.wait_for_function(READY.replace("N", str(rec.items.shape[0])), timeout=60000)
    # items' positions (world, from the animation) differ between two instants, as the belt moves them
    early, late = page.evaluate(POSITIONS, 1.0), page.evaluate(POSITIONS, 4.0)
    belt = spec.belt
    moved = 0
    for k, row in enumerate(rec.items):
        a, b = np.array(early[str(k)]), np.array(late[str(k)])
        if row[0] <= 1.0 and (row[6] < 0 or row[7] > 4.0) and belt.speed * (4.0 - row[0]) < rec.u_miss:
            # riding the belt all along: moved 3 s × the belt speed along it
            np.testing.assert_allclose(b - a, 3.0 * belt.velocity, atol=2e-3)
            moved += 1
    assert moved >= 2
    assert sum(np.linalg.norm(np.subtract(early[k], late[k])) > 0.05 for k in early) >= 4
    # pixels: the belt, the arms and the items are seen; the items' pixels change with time
    for nodes, least in ((BELT, 0.03), (ROBOTS, 0.02), (ITEMS, 0.001)):
        shown = _shot(page, 1.0)
        page.evaluate(HIDE, nodes)
        hidden = _shot(page, 1.0)
        page.evaluate(SHOW, nodes)
        assert _diff(shown, hidden).mean() > least, f"{nodes[0][-1]} hardly visible"
    page.evaluate(HIDE, ROBOTS)
    assert _diff(_shot(page, 1.0), _shot(page, 4.0)).sum() > 500, "the items did not move on the page"
    page.evaluate(SHOW, ROBOTS)
    # missed items: a red twin each (MeshCat animates no colours), red from the miss strip on
    red = page.evaluate("""() => Object.values(viewer.scene_tree.children.meshcat.children.pinarms.children.lines
        .children.belt.children.missed.children).map(n => n.children['<object>'].object.material.color.getHex())""")
    assert red == [0xD62728] * rec.n_missed
    title = page.inner_text("#pinarms-title")
    assert f"{rec.n_picked} picked, {rec.n_missed} missed (red)" in title
    picture = _shot(page, 4.0)
    assert picture.shape == (HEIGHT, WIDTH, 3)
    if os.environ.get("PINARMS_DOCS_PICTURES") == "1":  # make docs-pictures
        from PIL import Image

        Image.fromarray(picture.astype(np.uint8)).save(DOCS / "viz_belt_line.png", optimize=True)
    assert blocked == []
    page.close()
