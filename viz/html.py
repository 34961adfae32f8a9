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
    html, info = scene_html(session, **scene_options)
    if info.reachability:  # reachability maps: colour bar and slice slider (viz.reach_overlay)
        from .reach_overlay import inject_overlay

        html = inject_overlay(html, session, info.reachability)
    data = html.encode("utf-8")
    return atomic_write(path, lambda f: f.write(data))
