"""Scene building and HTML export against a real MeshCat server (no browser needed)."""

from __future__ import annotations

import os
import re

import numpy as np
import pytest

from pinarms import viz
from pinarms.errors import InvalidInput
from pinarms.viz.scene import build_scene
from pinarms.viz.scene_options import SceneOptions
from pinarms.viz.server import MeshcatServer


def _listening_addresses(port: int) -> set[str]:
    """Local addresses (hex, /proc/net/tcp form) with a listening socket on ``port``."""
    out = set()
    for table in ("/proc/net/tcp", "/proc/net/tcp6"):
        if not os.path.exists(table):
            continue
        with open(table) as f:
            for line in f.readlines()[1:]:
                local, state = line.split()[1], line.split()[3]
                addr, p = local.split(":")
                if state == "0A" and int(p, 16) == port:
                    out.add(addr)
    return out


def test_scene_contents_and_animation(line_session):
    with MeshcatServer() as server:
        info = build_scene(server.visualizer, line_session, SceneOptions(fps=25))
        assert server.running
    arm = line_session.robot("scara")
    rec = line_session.trajectories["pick-place 3-5-3"]
    import pinocchio as pin

    from pinarms.robots.registry import builtin_urdf_path

    _, _, visual = pin.buildModelsFromUrdf(str(builtin_urdf_path("scara_mushroom")))
    assert info.robots["scara"] == [f"pinarms/robots/scara/visuals/{g.name}" for g in visual.geometryObjects]
    assert len(info.robots["scara"]) >= 6
    assert info.paths == {"pick-place 3-5-3": "pinarms/paths/pick-place 3-5-3"}
    assert info.clouds == {"scara cloud": "pinarms/workspace/scara cloud"}
    assert len(info.points["crate targets"]) == 2 and len(info.points["vias:pick-place 3-5-3"]) == 4
    assert info.animated == ("pick-place 3-5-3",)
    assert info.duration == pytest.approx(3.607)
    assert info.n_frames == int(np.floor(3.607 * 25)) + 2  # 25 fps plus the exact end pose
    # the bounds hold the TCP path and the boxes
    tcp = arm.position(rec.q)
    assert np.all(info.bounds[0] <= tcp.min(axis=0)) and np.all(info.bounds[1] >= tcp.max(axis=0))
    assert info.bounds[1][0] >= 0.35 + 0.6 - 1e-12  # conveyor's far end
    assert not server.running


def test_animate_choice_is_checked(line_session):
    with MeshcatServer() as server:
        with pytest.raises(InvalidInput, match="cannot animate"):
            build_scene(server.visualizer, line_session, SceneOptions(animate=["nope"]))
        info = build_scene(server.visualizer, line_session, SceneOptions(animate=()))
        assert info.animated == () and info.n_frames == 0


def test_server_binds_loopback_only_and_stops():
    server = MeshcatServer()
    port = int(re.search(r":(\d+)/", server.url).group(1))
    assert server.url == f"http://127.0.0.1:{port}/static/"
    assert server.zmq_url.startswith("tcp://127.0.0.1:")
    if os.path.exists("/proc/net/tcp"):
        assert _listening_addresses(port) == {"0100007F"}  # 127.0.0.1, nothing on 0.0.0.0
        zport = int(server.zmq_url.rsplit(":", 1)[1])
        assert _listening_addresses(zport) == {"0100007F"}
    pid = server.pid
    assert os.path.exists(f"/proc/{pid}")
    server.close()
    server.close()  # idempotent
    assert not server.running
    assert not os.path.exists(f"/proc/{pid}")
    assert _listening_addresses(port) == set()


def test_bad_port():
    with pytest.raises(InvalidInput, match="port"):
        MeshcatServer(port=70000)


def test_port_in_use_says_what_to_do():
    from pinarms.viz import ViewerError

    with MeshcatServer() as first:
        port = int(re.search(r":(\d+)/", first.url).group(1))
        with pytest.raises(ViewerError, match=f"port {port} may be in use.*no --port"):
            MeshcatServer(port=port)


def test_export_html_is_self_contained(line_session, tmp_path):
    out = viz.export_html(line_session, tmp_path / "line.html")
    html = out.read_text(encoding="utf-8")
    assert html.lstrip().lower().startswith("<!doctype html") or "<html" in html[:500].lower()
    assert "src=\"http" not in html and "href=\"http" not in html  # nothing fetched from a server
    assert html.count("fetch(\"data:application/octet-binary;base64,") > 20  # the replayed scene
    assert os.listdir(tmp_path) == ["line.html"]


def test_two_robots_with_base_placement(tmp_path):
    s = viz.Session("ur5")
    T = np.eye(4)
    T[:3, 3] = [1.0, 0.0, 0.0]
    s.add_robot("panda", base_to_world=T)
    panda = s.robot("panda")
    q = panda.random_q(20, seed=1)
    s.add_trajectory("panda move", (np.linspace(0.0, 1.0, 20), q), robot="panda")
    with MeshcatServer() as server:
        info = build_scene(server.visualizer, s, SceneOptions(fps=10))
    assert set(info.robots) == {"ur5", "panda"}
    assert info.animated == ("panda move",)
    # the path is drawn in the world frame: panda's TCP shifted by its base placement
    tcp_world = panda.position(q) + [1.0, 0.0, 0.0]
    assert np.all(info.bounds[1] >= tcp_world.max(axis=0) - 1e-12)
    assert info.bounds[1][0] >= 1.0


def test_page_info_frames_the_robot_and_names_the_colours(line_session):
    from pinarms.viz.page import manipulability_unit

    with MeshcatServer() as server:
        info = build_scene(server.visualizer, line_session, SceneOptions(max_cloud_points=1000))
        with pytest.raises(InvalidInput, match="cloud_opacity"):
            build_scene(server.visualizer, line_session, SceneOptions(cloud_opacity=0.0))
        with pytest.raises(InvalidInput, match="max_cloud_points"):
            build_scene(server.visualizer, line_session, SceneOptions(max_cloud_points=0))
        with pytest.raises(InvalidInput, match="point_pixels"):
            build_scene(server.visualizer, line_session, SceneOptions(point_pixels=-1.0))
    page = info.page
    assert page["title"] == "enoki packing line"
    assert "cloud scara cloud: 1000 of 1500 samples shown" in page["lines"]
    assert "▶ pick-place 3-5-3: 3.61 s" in page["lines"]
    bar = page["colorbar"]
    w = line_session.workspaces["scara cloud"].manipulability
    assert bar["min"] == 0.0 and bar["max"] == pytest.approx(float(w.max()))  # the whole cloud's maximum
    assert bar["unit"] == "" and len(bar["colors"]) == 11 and bar["colors"][0] == "#440154"  # viridis(0)
    assert manipulability_unit(("rad",) * 6) == "m³" and manipulability_unit(("m",) * 3) == "1"
    # the view is centred on the robot and its path, not on the conveyor's middle nor the origin
    tcp = line_session.robot("scara").position(line_session.trajectories["pick-place 3-5-3"].q)
    assert np.linalg.norm(info.target[:2] - tcp.mean(axis=0)[:2]) < 0.3
    assert info.page["target"] == info.target.tolist() and info.page["camera"] == info.camera.tolist()
    distance = np.linalg.norm(info.camera - info.target)
    assert 0.5 < distance < 3.0
    assert info.camera[2] > info.target[2]  # from above


def test_scene_options_are_one_checked_object(line_session):
    """build_scene takes one SceneOptions: a mapping of keywords is refused, each option checked when made."""
    with pytest.raises(InvalidInput, match="options must be a viz.SceneOptions, got dict"):
        build_scene(None, line_session, {"fps": 10})
    assert SceneOptions(animate=["a"]).animate == ("a",) and SceneOptions().fps == 30.0
    with pytest.raises(InvalidInput, match="fps must be a positive frame rate"):
        SceneOptions(fps=0.0)
    with pytest.raises(InvalidInput, match="unknown matplotlib colormap"):
        SceneOptions(colormap="no such map")
