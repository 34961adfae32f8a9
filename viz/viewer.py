"""The live MeshCat viewer: a server on 127.0.0.1, the session's scene, a clean stop.

>>> with viz.show(session) as viewer:      # server on a free port
...     print(viewer.url)                   # open it in a browser
...     input("press Enter to stop")
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING

from pinarms.viz.scene import SceneInfo, build_scene
from pinarms.viz.scene_options import SceneOptions
from pinarms.viz.server import MeshcatServer

if TYPE_CHECKING:
    from pinarms.viz.session import Session

__all__ = ["Viewer", "show"]


class Viewer(MeshcatServer):
    """A running viewer showing a session (see :func:`show`).

    Attributes (besides :class:`MeshcatServer`'s): ``scene`` — the :class:`pinarms.viz.scene.SceneInfo`
    of what was drawn (scene paths, animation length).
    """

    scene: SceneInfo

    def wait(self, poll_s: float = 0.5) -> None:
        """Block until Ctrl+C (or until the server process dies), then stop the server."""
        try:
            while self.running:
                time.sleep(poll_s)
        except KeyboardInterrupt:
            pass
        finally:
            self.close()


def show(session: Session, port: int | None = None, open_browser: bool = False, wait: bool = False,
         options: SceneOptions | None = None) -> Viewer:
    """Start MeshCat on 127.0.0.1 and show ``session``; return the running :class:`Viewer`.

    Args:
        session: a :class:`pinarms.viz.Session`.
        port: HTTP port (default: a free one).
        open_browser: open the page in the default web browser.
        wait: block until Ctrl+C, then stop the server (same as ``show(...).wait()``).
        options: a :class:`pinarms.viz.scene_options.SceneOptions` for :func:`pinarms.viz.scene.build_scene` (``animate``, ``fps``, ...).

    Stop it with ``viewer.close()`` or use it as a context manager; the server process is
    also stopped when the viewer is garbage-collected or Python exits.
    """
    viewer = Viewer(port)
    try:
        viewer.scene = build_scene(viewer.visualizer, session, options)
    except BaseException:
        viewer.close()
        raise
    if open_browser:
        import webbrowser

        webbrowser.open(viewer.url, new=2)
    if wait:
        viewer.wait()
    return viewer
