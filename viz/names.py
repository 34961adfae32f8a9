"""The rule for names inside a session file (robots, trajectories, belt arms, table columns), and the
scene's root folder every drawing lives under.

Its own module so that the session format and the records of each kind (belt lines, reach
maps) share it without importing each other.
"""

from __future__ import annotations

import re

__all__ = ["NAME_RE", "SCENE_ROOT"]

#: The MeshCat folder (under ``/meshcat``) of everything a scene draws (:mod:`pinarms.viz.scene`).
SCENE_ROOT = "pinarms"

#: names of robots, trajectories, ...: 1-100 printable characters, no "/" (scene path separator),
#: no lone surrogates (they cannot be written as UTF-8)
NAME_RE = re.compile(r"^(?=.*\S)[^/\x00-\x1f\x7f\ud800-\udfff]{1,100}$")
