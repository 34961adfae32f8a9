"""Two bent arms (tests/robots/data/bent_arm.urdf) in a cell description, written into a test's folder.

Arm "b" stands before a table that its upper arm lies in at q = 0 (j2 = -1.2 rad lifts it
clear); ``b_keys`` adds lines to b's ``[[arm]]`` table (tcp, freeze, states, hold).
"""

from __future__ import annotations

import shutil
from pathlib import Path

DATA = Path(__file__).resolve().parents[1] / "data"

TEMPLATE = """\
name = "bent_pair"

[[arm]]
name = "a"
urdf = "bent_arm.urdf"
xyz = [0.0, {a_y!r}, 0.45]

[[arm]]
name = "b"
urdf = "bent_arm.urdf"
xyz = [0.0, -0.6, 0.45]
{b_keys}

[[fixture]]
name = "table"
box = [0.4, 0.4, 0.06]
xyz = [0.4, -0.6, 0.53]
"""


def bent_pair(folder: Path, b_keys: str = "", a_y: float = 0.6) -> Path:
    """Write ``pair.toml`` and the arm file into ``folder``; return the description's path."""
    shutil.copy(DATA / "bent_arm.urdf", folder / "bent_arm.urdf")
    path = folder / "pair.toml"
    path.write_text(TEMPLATE.format(b_keys=b_keys, a_y=a_y), encoding="utf-8")
    return path
