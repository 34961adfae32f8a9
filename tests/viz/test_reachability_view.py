"""Reachability maps in sessions, scenes and the standalone page (colour bar, slice slider in Chromium)."""

from __future__ import annotations

import os

import numpy as np
import pytest

from pinarms import robots, viz
from pinarms.errors import InvalidInput
from pinarms.robots.reach.reachability import ReachabilityRequest, reachability_map
from pinarms.viz.errors import SessionFormatError

CHROMIUM = "/usr/bin/chromium"
ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
        "--disable-background-networking", "--disable-component-update", "--disable-sync"]


@pytest.fixture(scope="module")
def reach_session():
    arm = robots.load("aubo_i3")
    m = reachability_map(ReachabilityRequest(arm, 0.1, 6, tool_down=np.radians(15), roll_steps=4))
    s = viz.Session(arm, title="AUBO-i3 tool-down reachability")
    s.add_reachability("tool down <15°>", m)
    return s, m


def test_session_keeps_the_reachable_voxels_and_round_trips(reach_session, tmp_path):
    s, m = reach_session
    rec = s.reachability["tool down <15°>"]
    assert rec.centres.shape[0] == int(np.count_nonzero(m.index > 0))
    np.testing.assert_array_equal(rec.index, m.index[m.index > 0])
    back = viz.load_session(s.save(tmp_path / "r.pinarms"))
    assert back == s
    np.testing.assert_array_equal(back.reachability["tool down <15°>"].centres, rec.centres)
    plain = viz.Session(robots.load("aubo_i3"))
    assert "reachability" not in plain.to_document()[0]  # sessions without maps are unchanged


def test_bad_reachability_inputs_and_files(reach_session, tmp_path):
    s, m = reach_session
    with pytest.raises(InvalidInput, match="ReachabilityMap"):
        s.add_reachability("x", object())
    with pytest.raises(InvalidInput, match="already exists"):
        s.add_reachability("tool down <15°>", m)
    import json
    import zipfile

    path = s.save(tmp_path / "bad.pinarms")
    with zipfile.ZipFile(path) as zf:
        members = {n: zf.read(n) for n in zf.namelist()}
    doc = json.loads(members["session.json"])
    doc["reachability"][0]["resolution"] = -1
    members["session.json"] = json.dumps(doc).encode()
    bad = tmp_path / "edited.pinarms"
    with zipfile.ZipFile(bad, "w") as zf:
        for n, data in members.items():
            zf.writestr(n, data)
    with pytest.raises(SessionFormatError, match="resolution"):
        viz.load_session(bad)


def test_scene_draws_one_layer_per_height_and_the_page_lists_them(reach_session):
    from pinarms.viz.html import scene_html

    s, m = reach_session
    _, info = scene_html(s)
    layers = info.reachability["tool down <15°>"]
    z = np.unique(np.round(s.reachability["tool down <15°>"].centres[:, 2], 6))
    assert len(layers) == z.size
    entry = info.page["reachability"][0]
    assert entry["name"] == "tool down <15°>" and len(entry["colors"]) >= 2
    assert [layer["path"] for layer in entry["layers"]] == layers
    assert [layer["z_mm"] for layer in entry["layers"]] == sorted(int(round(v * 1000)) for v in z)


@pytest.mark.browser
@pytest.mark.skipif(not os.path.exists(CHROMIUM), reason=f"{CHROMIUM} is absent: install Debian's chromium (make browser)")
def test_standalone_page_has_a_colour_bar_and_a_working_slice_slider(reach_session, tmp_path):
    sync_api = pytest.importorskip("playwright.sync_api")
    s, _ = reach_session
    page_path = viz.export_html(s, tmp_path / "reach.html")
    name = "tool down <15°>"
    n_layers = np.unique(np.round(s.reachability[name].centres[:, 2], 6)).size
    visible = f"""() => {{
      const L = viewer.scene_tree.children.meshcat.children.pinarms.children.reachability.children[{name!r}].children.layers.children;
      return Object.values(L).map(n => n.object ? n.object.visible : (n.children['<object>'] ? n.children['<object>'].object.visible : null));
    }}"""
    with sync_api.sync_playwright() as p:
        browser = p.chromium.launch(executable_path=CHROMIUM, args=ARGS)
        try:
            page = browser.new_page()
            page.route("**/*", lambda route: route.continue_() if route.request.url.startswith(("file:", "data:"))
                       else route.abort())
            page.goto(page_path.resolve().as_uri())
            page.wait_for_selector("#pinarms-reach-0 .pinarms-slice", timeout=20000)
            page.wait_for_function(f"""() => {{
              const r = viewer.scene_tree.children.meshcat.children.pinarms.children.reachability;
              return r && r.children[{name!r}] && Object.keys(r.children[{name!r}].children.layers.children).length === {n_layers};
            }}""", timeout=20000)
            title = page.text_content("#pinarms-reach-0")
            assert name in title and "reachability index" in title and "15° cone" in title
            gradient = page.eval_on_selector("#pinarms-reach-0 .pinarms-colorbar", "e => getComputedStyle(e).backgroundImage")
            assert "linear-gradient" in gradient
            kind = page.evaluate(f"""() => viewer.scene_tree.children.meshcat.children.pinarms.children.reachability
                .children[{name!r}].children.layers.children[Object.keys(viewer.scene_tree.children.meshcat.children.pinarms
                .children.reachability.children[{name!r}].children.layers.children)[0]].children['<object>'].object.type""")
            assert kind == "Points"
            page.select_option("#pinarms-reach-0 .pinarms-slice-mode", "only")
            page.eval_on_selector("#pinarms-reach-0 .pinarms-slice", "e => { e.value = 2; e.dispatchEvent(new Event('input')); }")
            shown = page.evaluate(visible)
            assert sum(bool(v) for v in shown) == 1 and len(shown) == n_layers
            assert "z = " in page.text_content("#pinarms-reach-0 .pinarms-slice-label")
            page.select_option("#pinarms-reach-0 .pinarms-slice-mode", "all")
            assert all(page.evaluate(visible))
        finally:
            browser.close()
