"""Imports inside ``robots`` go one way: ``robot`` uses the solvers in ``ik``, never the reverse."""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def _relative_imports(path: Path) -> set[str]:
    names = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom) and node.level > 0:
            names.add("." * node.level + (node.module or ""))
    return names


def test_ik_solvers_do_not_import_the_robot_module():
    offenders = {
        f.name: sorted(m for m in _relative_imports(f) if m.endswith("robot") or m in ("..", "..robot"))
        for f in sorted((ROOT / "robots" / "ik").glob("*.py"))
    }
    offenders = {k: v for k, v in offenders.items() if v}
    assert not offenders, f"robots/ik modules import robots/robot.py (an import circle): {offenders}"


def test_robot_imports_the_solvers_at_module_level():
    # the IK methods of Robot live in robot_ik.py (a base class of Robot)
    assert ".ik.numerical" in _relative_imports(ROOT / "robots" / "robot_ik.py")
