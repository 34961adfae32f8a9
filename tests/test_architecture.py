"""The one-way flow of the packages: robots → planning → optim → viz → pinarms (CLI, studies).

The folders ``robots/``, ``planning/``, ``optim/``, ``viz/`` sit at the repository's top level
and install as ``pinarms.robots``, ``pinarms.planning``, ... Every module's imports (module
level and inside functions) are read with ``ast``; a package may import only the packages
below it, and nothing imports the folders as top-level packages (those names belong to
other projects on PyPI).
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
ORDER = ["robots", "planning", "optim", "viz", "pinarms"]
ALLOWED = {pkg: set(ORDER[: i + 1]) for i, pkg in enumerate(ORDER)}
SUBPACKAGES = set(ORDER[:-1]) | {"urdf"}


def _layer(module: str, names: list[str]) -> set[str]:
    """Layers that ``from module import names`` (or ``import module``) reaches."""
    parts = module.split(".")
    if parts[0] in SUBPACKAGES:
        return {"top-level " + parts[0]}
    if parts[0] != "pinarms":
        return set()
    if len(parts) > 1:
        return {parts[1]} if parts[1] in SUBPACKAGES else {"pinarms"}
    return {n if n in SUBPACKAGES else "pinarms" for n in names}


def _imported_packages(path: Path) -> set[str]:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    names: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                names |= _layer(alias.name, [])
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            names |= _layer(node.module, [a.name for a in node.names])
    return names - {"urdf"}


@pytest.mark.parametrize("package", ORDER)
def test_imports_go_one_way(package):
    files = sorted((ROOT / package).rglob("*.py"))
    assert files, f"package {package} has no modules"
    wrong = {
        str(f.relative_to(ROOT)): sorted(_imported_packages(f) - ALLOWED[package])
        for f in files
        if _imported_packages(f) - ALLOWED[package]
    }
    assert not wrong, f"{package} imports packages above it (or as top-level names): {wrong}"


def test_the_checker_sees_function_level_and_top_level_imports(tmp_path):
    module = tmp_path / "m.py"
    module.write_text(
        "def f():\n    from pinarms import viz\n    from pinarms.optim.engine import run_ga\n"
        "    import pinarms.planning.trajectory\n    from pinarms.demo import run_demo\n    import robots\n"
    )
    assert _imported_packages(module) == {"viz", "optim", "planning", "pinarms", "top-level robots"}


def test_tests_and_benchmarks_import_the_namespace_only():
    offenders = sorted(
        str(f.relative_to(ROOT))
        for folder in ("tests", "benchmarks")
        for f in (ROOT / folder).rglob("*.py")
        if any(n.startswith("top-level") for n in _imported_packages(f))
    )
    assert not offenders, f"import pinarms.robots etc., not top-level robots: {offenders}"
