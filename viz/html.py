"""Standalone HTML export: MeshCat's static page of a session's scene, in one file."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ._atomic import atomic_write
from .scene import scene_html

__all__ = ["export_html"]


def export_html(session: Any, path: str | Path, **scene_options: Any) -> Path:
    """Write the session's scene as one self-contained HTML file (opens offline); return the path.

    The page holds MeshCat's JavaScript, the geometry, the clouds, the paths and the
    animation (play/pause/scrub in the page's Animations panel). ``scene_options`` go to
    :func:`viz.scene.build_scene`. The file is written atomically.
    """
    html, _ = scene_html(session, **scene_options)
    data = html.encode("utf-8")
    return atomic_write(path, lambda f: f.write(data))
