"""The page around a MeshCat scene: title, colour bar, framing, animation and cloud controls.

MeshCat's own page shows the 3-D scene and a collapsed control panel. pinarms adds, in
the standalone HTML export and in the live viewer alike, a small script
(``viz/page.js``) that reads what :func:`pinarms.viz.scene.build_scene` stored on the scene root
(property :data:`PAGE_PROPERTY`, a JSON object) and

- names the page and the study (``title``; ``lines``: one line per robot, trajectory and
  cloud),
- centres the orbit on the robots and their tcp paths (``target``, ``camera``; world
  frame, m),
- draws the colour bar of the workspace clouds (``colorbar``: ``label``, ``unit``, ``min``,
  ``max``, ``colors`` from low to high),
- offers play/pause, a time slider and a switch for the clouds (``clouds``,
  ``clouds_visible``, ``animation.duration`` in s).
- for reachability maps (``reachability``, present only when the scene has one: a list of
  ``name``, ``description``, ``label``, ``colors`` from index 0 to 1, and ``layers``, each a
  scene ``path`` and its height ``z_mm``, lowest first), a panel per map with its colour bar
  and a slice control: all layers, the layers up to a height, or that layer only.

The JSON keys above are the whole contract between the two sides.
"""

from __future__ import annotations

import html as _html
from pathlib import Path
from typing import Sequence

import matplotlib
import numpy as np

__all__ = ["PAGE_PROPERTY", "PAGE_SCRIPT", "colorbar_stops", "manipulability_unit", "with_page"]

#: Property of the scene node ``/meshcat/pinarms`` that holds the page's JSON.
PAGE_PROPERTY = "pinarms_page"
#: The page script (plain JavaScript, no dependency besides MeshCat's ``window.viewer``).
PAGE_SCRIPT = Path(__file__).with_name("page.js")


def colorbar_stops(colormap: str, n: int = 11) -> list[str]:
    """``n`` colours ``#rrggbb`` of ``colormap`` from its low end (0) to its high end (1)."""
    rgb = np.asarray(matplotlib.colormaps[colormap](np.linspace(0.0, 1.0, n)))[:, :3]
    return ["#%02x%02x%02x" % tuple(int(round(255 * c)) for c in row) for row in rgb]


def manipulability_unit(joint_units: Sequence[str]) -> str:
    """Unit of the position manipulability ``√det(J_v J_vᵀ)`` of an arm with these joint units.

    Each column of ``J_v`` is m/rad for a revolute joint and m/m for a prismatic one; the
    determinant sums products of three columns (Cauchy–Binet), so the measure has one unit
    only when every joint is of one kind: m³ (per rad³) for revolute arms, none for
    prismatic ones (shown as ``"1"``); ``""`` for mixed arms (SCARA: m² and m³ terms).
    """
    kinds = set(joint_units)
    if kinds == {"rad"}:
        return "m³" if len(joint_units) >= 3 else f"m{'²' if len(joint_units) == 2 else ''}"
    if kinds == {"m"}:
        return "1"
    return ""


def with_page(static_html: str, title: str) -> str:
    """MeshCat's static page with ``title`` and the page script added (see the module doc)."""
    script = PAGE_SCRIPT.read_text(encoding="utf-8")
    out = static_html.replace("<title>MeshCat</title>", f"<title>{_html.escape(title)}</title>", 1)
    head, body_end, tail = out.rpartition("</body>")  # the last one: MeshCat's inlined JS may hold the text
    if not body_end:
        return out + f"<script>\n{script}\n</script>\n"
    return f"{head}<script>\n{script}\n</script>\n{body_end}{tail}"
