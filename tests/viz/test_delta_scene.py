"""A delta's page: the closed chain drawn from the rods' ball centres and the closed form, and animated."""

from __future__ import annotations

import numpy as np
import pytest

from pinarms.robots.delta import forward_position, load_delta
from pinarms.errors import InvalidInput
from pinarms.viz.delta_scene import delta_page, delta_parts, delta_poses


@pytest.fixture(scope="module")
def delta():
    return load_delta("delta_flexpicker")


def _theta(n: int = 12) -> np.ndarray:
    t = np.linspace(0.0, 1.0, n)[:, None]
    return 0.3 + 0.25 * np.sin(2 * np.pi * t + np.array([0.0, 2.1, 4.2]))


def test_scene_data_is_the_closed_chain(delta):
    """Read back from the transforms: every rod as long as the forearm, its two ends on the elbow side and
    on the platform at the closed-form position (r from its centre, +-h/2 along the motor axis); the
    upper arm from the motor axis to the elbow; the platform at the closed form, in the world frame."""
    g, th = delta.geometry, _theta()
    T = np.eye(4)
    T[:3, 3] = [2.0, 0.5, 1.9]
    poses = delta_poses(delta, th, T)
    assert set(poses) == set(delta_parts(delta))
    p = forward_position(g, th) + T[:3, 3]
    np.testing.assert_allclose(poses["platform"][:, :3, 3], p, atol=1e-12)
    for i in range(3):
        e, u = g.radial[i], g.tangential[i]
        for tag in "ab":
            R = poses[f"rod_{i + 1}{tag}"]
            y, mid = R[:, :3, 1], R[:, :3, 3]
            bottom = mid + 0.5 * g.forearm * y
            np.testing.assert_allclose(np.linalg.norm(y, axis=1), 1.0, atol=1e-12)
            # the platform end: r along the leg's radial, +-h/2 along its motor axis
            off = bottom - p - g.platform_radius * e
            np.testing.assert_allclose(np.abs(off @ u), 0.5 * g.rod_spacing, atol=1e-9)
            np.testing.assert_allclose(off - np.outer(off @ u, u), 0.0, atol=1e-9)
        arm = poses[f"upper_arm_{i + 1}"]
        motor = arm[:, :3, 3] - 0.5 * g.upper_arm * arm[:, :3, 1]
        np.testing.assert_allclose(motor, np.broadcast_to(g.base_radius * e + T[:3, 3], motor.shape), atol=1e-9)
    # the two rods of a leg are parallel (a parallelogram) and the animation moves them
    np.testing.assert_allclose(poses["rod_1a"][:, :3, 1], poses["rod_1b"][:, :3, 1], atol=1e-9)
    assert np.ptp(poses["rod_2a"][:, :3, 3], axis=0).max() > 0.05


def test_bad_angles_refused(delta):
    with pytest.raises(InvalidInput, match=r"\(F, 3\)"):
        delta_poses(delta, [0.1, 0.2, 0.3])
    with pytest.raises(InvalidInput, match="finite"):
        delta_poses(delta, [[0.1, 0.2, 0.3], [np.nan, 0.0, 0.0]])


def _page_commands(text: str) -> list[dict]:
    """The MeshCat commands a standalone page replays (base64 msgpack blobs)."""
    import base64
    import re

    import msgpack

    blobs = re.findall(r'fetch\("data:application/octet-binary;base64,([A-Za-z0-9+/=]+)"\)', text)
    return [msgpack.unpackb(base64.b64decode(b), raw=False, strict_map_key=False) for b in blobs]


def test_page_holds_the_parts_and_the_animation(delta, tmp_path):
    """Read back from the page: each part drawn at its first pose, and an animation of every part over the frames."""
    th = _theta(6)
    out = delta_page(delta, th, tmp_path / "delta.html", fps=10.0)
    cmds = _page_commands(out.read_text(encoding="utf-8"))
    poses = delta_poses(delta, th)
    root = "/meshcat/pinarms/deltas/delta_flexpicker/"
    shown = {c["path"][len(root):]: np.array(c["matrix"], float).reshape(4, 4).T
             for c in cmds if c.get("type") == "set_transform" and c["path"].startswith(root)}
    assert set(shown) == set(poses)
    for part, T in poses.items():
        np.testing.assert_allclose(shown[part], T[0], atol=1e-6)  # float32 on the page
    anim = [c for c in cmds if c.get("type") == "set_animation"]
    assert len(anim) == 1
    clips = {a["path"][len(root):]: a["clip"] for a in anim[0]["animations"] if a["path"].startswith(root)}
    assert set(clips) == set(poses)
    track = {t["name"]: t["keys"] for t in clips["rod_2b"]["tracks"]}[".position"]
    assert len(track) == 6  # one key a frame, at the rod's middle
    np.testing.assert_allclose([k["value"] for k in track], poses["rod_2b"][:, :3, 3], atol=1e-6)
