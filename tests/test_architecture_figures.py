"""benchmarks/architecture.py measures what it says: sizes, circles and upward imports of a known package.

A tiny package is written in a temporary folder with a known circle (``a → b → c → a``,
one edge inside a function), a known upward import (``low`` importing ``high`` inside a
function), a relative import, an import only for type checkers and functions of known
lengths; the analysis must find exactly those. On the real code the goals of the
restructuring are asserted: no import circle, no upward import, no module over 500 lines, no
function over 100 lines (``python benchmarks/architecture.py`` prints the figures).
"""

from __future__ import annotations

import textwrap
from pathlib import Path

import pytest

from tests.architecture_script import architecture

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def arch():
    return architecture()


def _write(folder: Path, name: str, text: str) -> None:
    path = folder / name
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(textwrap.dedent(text).lstrip("\n"), encoding="utf-8")


@pytest.fixture
def package(tmp_path):
    src = tmp_path / "src"
    _write(src, "__init__.py", '"""pkg."""\n')
    _write(src, "low/__init__.py", "")
    _write(src, "low/a.py", """
        from pkg.low import b


        def long_one():
            x = 1
            x += 1
            x += 1
            x += 1
            return x
        """)  # long_one: 6 lines
    _write(src, "low/b.py", """
        from . import c
        """)
    _write(src, "low/c.py", """
        from typing import TYPE_CHECKING

        if TYPE_CHECKING:
            from pkg.high import view  # never runs: not an edge


        def late():
            import pkg.low.a  # the edge that closes the circle a -> b -> c -> a
            return pkg.low.a


        class Box:
            def method(self):
                return 1
        """)
    _write(src, "low/alone.py", """
        import os


        def up():
            from pkg.high.view import show  # an upward import, inside a function
            return show, os
        """)
    _write(src, "high/__init__.py", "")
    _write(src, "high/view.py", """
        from pkg.low.alone import up


        def show():
            return up
        """)
    layers = (("low", ("pkg.low",)), ("high", ("pkg.high",)))
    return {"pkg": src}, layers


def test_modules_and_their_sizes(arch, package):
    dirs, _ = package
    modules = arch.find_modules(dirs)
    assert set(modules) == {"pkg", "pkg.low", "pkg.low.a", "pkg.low.b", "pkg.low.c", "pkg.low.alone", "pkg.high",
                            "pkg.high.view"}
    sizes = {m.name: m.lines for m in arch.module_sizes(modules)}
    assert sizes["pkg.low.a"] == 9 and sizes["pkg.low.b"] == 1 and sizes["pkg.low"] == 0
    assert arch.module_sizes(modules)[0].name == "pkg.low.c"  # the largest first


def test_function_lengths_count_methods_and_nested_functions(arch, package):
    dirs, _ = package
    functions = arch.function_sizes(arch.find_modules(dirs))
    by_name = {(f.module, f.qualname): f.lines for f in functions}
    assert by_name[("pkg.low.a", "long_one")] == 6
    assert by_name[("pkg.low.c", "Box.method")] == 2
    assert by_name[("pkg.low.c", "late")] == 3
    assert functions[0].qualname == "long_one"


def test_the_known_circles_are_found_and_nothing_else(arch, package):
    dirs, _ = package
    imports = arch.import_graph(arch.find_modules(dirs))
    edges = {(e.source, e.target, e.in_function) for e in imports}
    assert ("pkg.low.a", "pkg.low.b", False) in edges          # from package import submodule
    assert ("pkg.low.b", "pkg.low.c", False) in edges          # relative import
    assert ("pkg.low.c", "pkg.low.a", True) in edges           # inside a function
    assert not any(e.target == "pkg.high.view" and e.source == "pkg.low.c" for e in imports)  # TYPE_CHECKING
    # a -> b -> c -> a, and view -> alone (module level) with alone -> view (inside a function)
    assert arch.import_circles(imports) == [("pkg.low.a", "pkg.low.b", "pkg.low.c"),
                                            ("pkg.high.view", "pkg.low.alone")]


def test_the_known_upward_import_is_reported(arch, package):
    dirs, layers = package
    fig = arch.figures(dirs, layers)
    assert [(e.source, e.target, e.in_function) for e in fig.upward] == [("pkg.low.alone", "pkg.high.view", True)]
    assert arch.layer_of("pkg.high.view", layers) == (1, "high")
    assert arch.layer_of("pkg", layers) is None
    goals = {g: (n, ok) for g, n, ok in fig.goals()}
    assert goals["no import circle"] == (2, False) and goals["no upward import"] == (1, False)
    assert goals["no module over 500 lines"] == (0, True)
    text = "\n".join(arch.report(fig))
    assert "pkg.low.alone (low) -> pkg.high.view (high), line 5 in a function" in text


def test_the_project_meets_the_goals_of_the_restructuring(arch):
    """Measured on this repository's own code, function-level imports included: no circle, no
    upward import, no module over 500 lines, no function over 100 lines
    (``python benchmarks/architecture.py`` prints the whole table)."""
    fig = arch.figures()
    assert len(fig.modules) > 100  # the repository itself was read
    assert fig.circles == [], "\n".join(" -> ".join(c) for c in fig.circles)
    assert fig.upward == [], "\n".join(f"{e.source} -> {e.target} (line {e.lineno})" for e in fig.upward)
    too_big = [f"{m.path}: {m.lines} lines" for m in fig.modules if m.lines > 500]
    assert too_big == [], "modules over 500 lines: " + ", ".join(too_big)
    too_long = [f"{f.module}:{f.qualname} (line {f.lineno}): {f.lines} lines" for f in fig.functions if f.lines > 100]
    assert too_long == [], "functions over 100 lines: " + ", ".join(too_long)
