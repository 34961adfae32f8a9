"""Standalone HTML export: MeshCat's static page of a session's scene, in one file."""

from __future__ import annotations

import contextlib
import io
from pathlib import Path
from typing import TYPE_CHECKING

from pinarms.files import atomic_write

from pinarms.viz.page import with_page
from pinarms.viz.scene import SceneInfo, build_scene
from pinarms.viz.scene_options import SceneOptions
from pinarms.viz.server import MeshcatServer

if TYPE_CHECKING:
    from pinarms.viz.session import Session

__all__ = ["export_html", "scene_html"]


def scene_html(session: Session, options: SceneOptions | None = None) -> tuple[str, SceneInfo]:
    """The session's scene as one self-contained HTML page, and what was drawn.

    A MeshCat server runs for a moment (MeshCat replays its scene tree into the page);
    the page carries pinarms' title, colour bar and controls (:mod:`pinarms.viz.page`).
    """
    with MeshcatServer() as server, contextlib.redirect_stdout(io.StringIO()):
        info = build_scene(server.visualizer, session, options)
        html = server.static_html()
    return with_page(html, info.page["title"]), info


def export_html(session: Session, path: str | Path, options: SceneOptions | None = None) -> Path:
    """Write the session's scene as one self-contained HTML file (opens offline); return the path.

    The page holds MeshCat's JavaScript, the geometry, the clouds, the paths and the
    animation, framed on the robots, with the study's title, the clouds' colour bar, and
    play/pause, a time slider and a cloud switch at the bottom. ``options``: a
    :class:`pinarms.viz.scene_options.SceneOptions` for :func:`pinarms.viz.scene.build_scene`. The file is written atomically.
    """
    html, _ = scene_html(session, options)
    data = html.encode("utf-8")
    return atomic_write(path, lambda f: f.write(data))
