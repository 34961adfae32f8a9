"""The one-way flow of the packages: robots → planning → optim → viz → pinarms (CLI, studies).

Below them all sits the floor: the error classes (``pinarms.errors``), the execution layer
``pinarms.execution`` (serial loop or Dask), atomic file writing, units and the compiled-kernel
decorator. Every package may import it, and it imports nothing of ours but the floor (the error
classes import nothing of ours). The layers are stated once, in ``benchmarks/architecture.py``
(:data:`LAYERS`), which the figures test reads too.

The folders ``robots/``, ``planning/``, ``optim/``, ``viz/`` sit at the repository's top level
and install as ``pinarms.robots``, ``pinarms.planning``, ... Every module's imports (module
level and inside functions) are read with ``ast``; a package may import only the packages
below it, and nothing imports the folders as top-level packages (those names belong to
other projects on PyPI).
"""

from __future__ import annotations

import ast
import sys
from pathlib import Path

import pytest

from tests.architecture_script import architecture

ROOT = Path(__file__).resolve().parents[1]


#: benchmarks/architecture.py's layers: the one statement of them.
LAYERS = architecture().LAYERS
#: The packages in their one-way order (the layers above the floor).
ORDER = [name for name, _ in LAYERS[1:]]
#: The floor: modules of the ``pinarms`` folder that every package may import (the error
#: classes, the execution layer, atomic file writing, units, compiled kernels); they import
#: nothing of ours but each other (the compiled kernels' cache guard writes through the atomic writer).
BOTTOM = {prefix: prefix.split(".")[1] for prefix in LAYERS[0][1]}
ALLOWED = {pkg: set(ORDER[: i + 1]) | set(BOTTOM.values()) for i, pkg in enumerate(ORDER)}
SUBPACKAGES = set(ORDER[:-1]) | {"urdf"}


def _layer(module: str, names: list[str]) -> set[str]:
    """Layers that ``from module import names`` (or ``import module``) reaches."""
    parts = module.split(".")
    if parts[0] in SUBPACKAGES:
        return {"top-level " + parts[0]}
    if parts[0] != "pinarms":
        return set()
    if len(parts) > 1:
        if ".".join(parts[:2]) in BOTTOM:
            return {BOTTOM[".".join(parts[:2])]}
        return {parts[1]} if parts[1] in SUBPACKAGES else {"pinarms"}
    return {
        BOTTOM.get(f"pinarms.{n}") or (n if n in SUBPACKAGES else "pinarms") for n in names
    }


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


def _imported_modules(path: Path) -> set[str]:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    out: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out |= {alias.name for alias in node.names}
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            out.add(node.module)
    return out


def test_the_execution_layer_imports_only_numpy_dask_threadpoolctl_and_the_errors():

    modules = _imported_modules(ROOT / "pinarms" / "execution.py")
    ours = {m for m in modules if m.split(".")[0] in SUBPACKAGES | {"pinarms"}}
    assert ours == {"pinarms.errors", "pinarms.chunks", "pinarms.schedulers"}, ours  # chunks, schedulers: floor
    third_party = {
        m.split(".")[0] for m in modules - ours if m.split(".")[0] not in sys.stdlib_module_names
    }
    assert third_party <= {"numpy", "dask", "distributed", "threadpoolctl"}, third_party
    # and the errors module it reaches imports nothing of ours but the floor's lazy loading (the areas'
    # errors it offers load on first use)
    errors = _imported_modules(ROOT / "pinarms" / "errors.py")
    assert {m for m in errors if m.split(".")[0] in SUBPACKAGES | {"pinarms"}} == {"pinarms.lazy"}, errors
    assert _imported_modules(ROOT / "pinarms" / "lazy.py") <= sys.stdlib_module_names | {"__future__"}


@pytest.mark.parametrize("floor", sorted(set(BOTTOM.values()) - {"errors", "execution"}))
def test_the_floor_imports_nothing_of_ours_but_the_floor(floor):
    modules = _imported_modules(ROOT / "pinarms" / f"{floor}.py")
    ours = {m for m in modules if m.split(".")[0] in SUBPACKAGES | {"pinarms"}}
    assert ours <= set(BOTTOM) - {f"pinarms.{floor}"}, ours
    assert all(floor in ALLOWED[pkg] for pkg in ORDER)


def test_one_errors_module_offers_every_error():
    """``pinarms.errors`` offers every exception class of every area's ``errors`` module (the same class
    objects); no other module re-exports them (the old ``pinarms.errors`` is gone)."""
    import importlib

    import pinarms.errors as errors

    assert not (ROOT / "robots" / "errors.py").exists()
    defined = {}
    for path in sorted(ROOT.glob("**/errors.py")):
        if ".venv" in path.parts or "tests" in path.parts:
            continue
        tree = ast.parse(path.read_text(encoding="utf-8"))
        assert not [n for n in tree.body if isinstance(n, ast.ImportFrom) and any(a.name == "*" for a in n.names)], path
        for node in tree.body:
            if isinstance(node, ast.ClassDef) and not node.name.startswith("_"):
                defined[node.name] = path
    assert len(defined) >= 50
    for name, path in defined.items():
        assert name in errors.__all__, f"{name} ({path}) is missing from pinarms.errors"
        home = importlib.import_module(getattr(errors, name).__module__)
        assert getattr(home, name) is getattr(errors, name)


def test_robot_and_its_dynamics_are_no_circle():
    """robots/robot.py uses robots/dynamics.py; dynamics imports nothing of robot (not even for types)."""
    assert "robot" not in _sibling_imports(ROOT / "robots" / "dynamics.py")
    assert "pinarms.robots.robot" not in _imported_modules(ROOT / "robots" / "dynamics.py")


def test_every_package_may_import_the_execution_layer(tmp_path):
    module = tmp_path / "m.py"
    module.write_text("from pinarms import execution\nfrom pinarms.execution import map_chunks\n")
    assert _imported_packages(module) == {"execution"}
    assert all("execution" in ALLOWED[pkg] for pkg in ORDER)
    module.write_text("from pinarms import execution, demo\n")
    assert _imported_packages(module) == {"execution", "pinarms"}


def test_the_checker_sees_function_level_and_top_level_imports(tmp_path):
    module = tmp_path / "m.py"
    module.write_text(
        "def f():\n    from pinarms import viz\n    from pinarms.optim.ga.engine import run_ga\n"
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


def _sibling_imports(path: Path) -> set[str]:
    """Sibling modules a module of ``robots/`` imports (``from pinarms.robots.reach.x import``: ``x``)."""
    package = "pinarms." + ".".join(path.relative_to(ROOT).parent.parts)
    tree = ast.parse(path.read_text(encoding="utf-8"))
    return {
        node.module[len(package) + 1:].split(".")[0]
        for node in ast.walk(tree)
        if isinstance(node, ast.ImportFrom) and node.level == 0 and (node.module or "").startswith(package + ".")
    }


def test_workspace_analysis_modules_import_one_way():
    """voxels → workspace → workspace_stream, table_band, layout: nothing imports back down-up."""
    above = {
        "voxels": {"workspace", "workspace_stream", "table_band", "layout"},
        "workspace": {"workspace_stream", "table_band", "layout"},
        "workspace_stream": {"table_band", "layout"},
        "table_band": {"layout", "workspace_stream"},
    }
    wrong = {
        m: sorted(_sibling_imports(ROOT / "robots" / "reach" / f"{m}.py") & forbidden) for m, forbidden in above.items()
    }
    assert not any(wrong.values()), f"robots modules import modules above them: {wrong}"


def test_one_import_style_absolute():
    """Every import of our own code names the importable module (``from pinarms.robots.cell.cell import Cell``):
    the folders install under ``pinarms.`` (pyproject.toml's package-dir), so a relative import hides where a
    module lives; the lazy tables of the package ``__init__`` s name absolute modules too."""
    relative = []
    for folder in ("pinarms", *SUBPACKAGES):
        for path in sorted((ROOT / folder).rglob("*.py")):
            tree = ast.parse(path.read_text(encoding="utf-8"))
            relative += [f"{path.relative_to(ROOT)}:{n.lineno}" for n in ast.walk(tree)
                         if isinstance(n, ast.ImportFrom) and n.level > 0]
            relative += [f"{path.relative_to(ROOT)}:{n.lineno}" for n in ast.walk(tree) if isinstance(n, ast.Constant)
                         and isinstance(n.value, str) and path.name == "__init__.py" and n.value.startswith(".")
                         and n.value[1:2].isalpha()]
    assert relative == [], relative[:20]
