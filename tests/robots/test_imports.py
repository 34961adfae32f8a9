"""Imports inside ``robots`` go one way: ``robot`` uses the solvers in ``ik``, never the reverse."""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def _imports(path: Path) -> set[str]:
    """The modules a file imports from (absolute: the package's one import style)."""
    names = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom):
            assert node.level == 0, f"{path.name}:{node.lineno}: a relative import"
            names.add(node.module or "")
    return names


def test_ik_solvers_do_not_import_the_robot_module():
    offenders = {
        f.name: sorted(m for m in _imports(f) if m in ("pinarms.robots", "pinarms.robots.robot"))
        for f in sorted((ROOT / "robots" / "ik").glob("*.py"))
    }
    offenders = {k: v for k, v in offenders.items() if v}
    assert not offenders, f"robots/ik modules import robots/robot.py (an import circle): {offenders}"


def test_robot_imports_the_solvers_at_module_level():
    # the IK methods of Robot live in robot_ik.py (a base class of Robot)
    assert "pinarms.robots.ik.numerical" in _imports(ROOT / "robots" / "robot_ik.py")
