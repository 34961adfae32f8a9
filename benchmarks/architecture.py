"""Architecture figures of the code: module and function sizes, import circles, upward imports.

Run ``python benchmarks/architecture.py`` from the repository (``--top N`` rows per table,
``--json`` for one JSON document). It reads every module of the installed packages'
folders (``[tool.setuptools.package-dir]`` of pyproject.toml: ``pinarms/``, ``robots/``,
``planning/``, ``optim/``, ``viz/``, ``urdf/``) with :mod:`ast`, nothing is imported, and prints

- the largest modules (lines) and the longest functions (lines from ``def`` to its last
  line; methods and nested functions count on their own);
- how many modules are over 400 and 500 lines, and functions over 80 and 100 lines;
- the import circles: strongly connected components of the module graph, built from every
  ``import`` and ``from … import`` statement, those inside functions included
  (``from package import submodule`` is an edge to the submodule; imports under
  ``if TYPE_CHECKING:`` never run and are left out);
- the same circles when the imports under ``if TYPE_CHECKING:`` count too (two modules that
  each need the other's types are one concept or need a third module for what they share);
- the upward imports: a module importing one of a layer above its own, in the one-way
  order of the architecture document (floor → robots → planning → optim → viz → the CLI,
  studies and export in ``pinarms``): :data:`LAYERS`;

then the walls between modules and the front door (:mod:`architecture_walls`: uses of another
module's private names, docstring references that cannot be imported, long signatures and the
share of parameters typed ``Any``, the import time of the event simulator); all
with the goals of the restructuring (no circle, no upward import, no module over 500
lines, no function over 100) and whether each is met. The analysis functions take the
folders and the layers as arguments, so they work on any package (the tests use a small
synthetic one).
"""

from __future__ import annotations

import argparse
import ast
import json
import sys
import tomllib
from dataclasses import asdict, dataclass, field
from pathlib import Path

__all__ = ["LAYERS", "Module", "Function", "Import", "Figures", "find_modules", "module_sizes", "function_sizes",
           "import_graph", "import_circles", "layer_of", "upward_imports", "figures", "main"]

ROOT = Path(__file__).resolve().parents[1]

#: The one-way order of the architecture document, lowest first: each layer names the module
#: prefixes it holds (a module belongs to the layer of its longest matching prefix). The
#: floor (errors, execution layer, atomic files, units) may be imported by every package and
#: imports none of them.
LAYERS: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("floor", ("pinarms.errors", "pinarms.lazy", "pinarms.execution", "pinarms.chunks", "pinarms.schedulers", "pinarms.files",
               "pinarms.units", "pinarms.compiled", "pinarms.compile_notice")),
    ("robots", ("pinarms.robots", "pinarms.urdf")),
    ("planning", ("pinarms.planning",)),
    ("optim", ("pinarms.optim",)),
    ("viz", ("pinarms.viz",)),
    ("pinarms", ("pinarms",)),
)

#: Thresholds counted (lines): modules and functions.
MODULE_LINES = (400, 500)
FUNCTION_LINES = (80, 100)


@dataclass(frozen=True)
class Module:
    """One module: dotted ``name``, its file ``path`` and its ``lines``."""

    name: str
    path: str
    lines: int


@dataclass(frozen=True)
class Function:
    """One function or method: ``module``, ``qualname`` (``Class.method``, ``outer.inner``), first line, lines."""

    module: str
    qualname: str
    lineno: int
    lines: int


@dataclass(frozen=True)
class Import:
    """One edge of the module graph: ``source`` imports ``target`` at ``lineno`` (``in_function``: inside a def)."""

    source: str
    target: str
    lineno: int
    in_function: bool


@dataclass
class Figures:
    """Every figure :func:`main` prints."""

    modules: list[Module]
    functions: list[Function]
    imports: list[Import]
    circles: list[tuple[str, ...]]
    upward: list[Import]
    layers: dict[str, str] = field(default_factory=dict)
    #: The circles when the imports for type checkers count too.
    typed_circles: list[tuple[str, ...]] = field(default_factory=list)

    @property
    def total_lines(self) -> int:
        return sum(m.lines for m in self.modules)

    def modules_over(self, lines: int) -> int:
        return sum(m.lines > lines for m in self.modules)

    def functions_over(self, lines: int) -> int:
        return sum(f.lines > lines for f in self.functions)

    def goals(self) -> list[tuple[str, int, bool]]:
        """``(goal, today's figure, met)`` for each goal of the restructuring."""
        return [
            ("no import circle", len(self.circles), not self.circles),
            ("no circle counting type-only imports", len(self.typed_circles), not self.typed_circles),
            ("no upward import", len(self.upward), not self.upward),
            ("no module over 500 lines", self.modules_over(500), self.modules_over(500) == 0),
            ("no function over 100 lines", self.functions_over(100), self.functions_over(100) == 0),
        ]


# ------------------------------------------------------------------------ reading the code
def package_dirs_of(root: Path) -> dict[str, Path]:
    """``{package prefix: folder}`` from pyproject.toml's ``[tool.setuptools.package-dir]``."""
    data = tomllib.loads((root / "pyproject.toml").read_text(encoding="utf-8"))
    dirs = data.get("tool", {}).get("setuptools", {}).get("package-dir", {})
    return {prefix: root / folder for prefix, folder in dirs.items() if prefix}


def find_modules(package_dirs: dict[str, Path]) -> dict[str, Path]:
    """``{dotted module name: file}`` of every ``.py`` file under the folders (``__init__`` is the package).

    A folder mapped to a longer prefix (``pinarms.robots`` → ``robots/``) is read under that
    prefix only, never again under a shorter one.
    """
    out: dict[str, Path] = {}
    folders = {Path(f).resolve(): p for p, f in package_dirs.items()}
    for prefix, folder in sorted(package_dirs.items(), key=lambda item: -len(item[0])):
        folder = Path(folder).resolve()
        for path in sorted(folder.rglob("*.py")):
            inner = [f for f in folders if f != folder and folder in f.parents and f in path.parents]
            if inner:  # belongs to a folder with its own prefix
                continue
            parts = list(path.relative_to(folder).with_suffix("").parts)
            if parts[-1] == "__init__":
                parts = parts[:-1]
            out.setdefault(".".join([prefix, *parts]), path)
    return out


def module_sizes(modules: dict[str, Path]) -> list[Module]:
    """Modules by size, largest first (lines of the file)."""
    rows = [Module(name, str(path), len(path.read_text(encoding="utf-8").splitlines()))
            for name, path in modules.items()]
    return sorted(rows, key=lambda m: (-m.lines, m.name))


def function_sizes(modules: dict[str, Path]) -> list[Function]:
    """Every function and method by length, longest first (``def`` line to last line)."""
    rows: list[Function] = []
    for name, path in modules.items():
        tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))

        def visit(node: ast.AST, scope: tuple[str, ...]) -> None:
            for child in ast.iter_child_nodes(node):
                if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef)):
                    q = (*scope, child.name)
                    rows.append(Function(name, ".".join(q), child.lineno, child.end_lineno - child.lineno + 1))
                    visit(child, q)
                elif isinstance(child, ast.ClassDef):
                    visit(child, (*scope, child.name))
                else:
                    visit(child, scope)

        visit(tree, ())
    return sorted(rows, key=lambda f: (-f.lines, f.module, f.qualname))


def _is_type_checking(node: ast.If) -> bool:
    test = node.test
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or \
        (isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING")


def _resolve(module: str, is_package: bool, node: ast.ImportFrom) -> str | None:
    """The absolute module a ``from`` statement names (relative levels resolved)."""
    if node.level == 0:
        return node.module
    parts = module.split(".") if is_package else module.split(".")[:-1]
    if node.level - 1 > len(parts):
        return None
    base = parts[: len(parts) - (node.level - 1)]
    return ".".join(base + ([node.module] if node.module else []))


def _target(name: str, known: set[str]) -> str | None:
    """The longest prefix of ``name`` that is a module of the code (``None``: outside it)."""
    parts = name.split(".")
    for k in range(len(parts), 0, -1):
        candidate = ".".join(parts[:k])
        if candidate in known:
            return candidate
    return None


def import_graph(modules: dict[str, Path], type_checking: bool = False) -> list[Import]:
    """Every import of one module of the code by another (module level and inside functions).

    ``type_checking``: also the imports under ``if TYPE_CHECKING:`` (they never run, but a circle
    through them is still two modules that each need the other to be understood).
    """
    known = set(modules)
    edges: list[Import] = []
    for name, path in modules.items():
        tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
        is_package = path.name == "__init__.py"

        def visit(node: ast.AST, in_function: bool) -> None:
            for child in ast.iter_child_nodes(node):
                if isinstance(child, ast.If) and _is_type_checking(child) and not type_checking:
                    for other in child.orelse:
                        visit(other, in_function)
                    continue
                inner = in_function or isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda))
                targets: list[str] = []
                if isinstance(child, ast.Import):
                    targets = [t for a in child.names if (t := _target(a.name, known))]
                elif isinstance(child, ast.ImportFrom):
                    base = _resolve(name, is_package, child)
                    if base is not None:
                        for alias in child.names:
                            t = _target(f"{base}.{alias.name}", known) if alias.name != "*" else None
                            t = t if t is not None and t != base else _target(base, known)
                            if t is not None:
                                targets.append(t)
                for t in dict.fromkeys(targets):
                    if t != name:
                        edges.append(Import(name, t, child.lineno, in_function))
                visit(child, inner)

        visit(tree, False)
    return edges


def import_circles(imports: list[Import]) -> list[tuple[str, ...]]:
    """Strongly connected components of two or more modules (each a circle of imports), largest first."""
    graph: dict[str, set[str]] = {}
    for e in imports:
        graph.setdefault(e.source, set()).add(e.target)
        graph.setdefault(e.target, set())
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    out: list[tuple[str, ...]] = []
    counter = 0
    for root in sorted(graph):  # Tarjan's algorithm, iterative
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = counter
        counter += 1
        stack.append(root)
        on_stack.add(root)
        while work:
            node, children = work[-1]
            child = next(children, None)
            if child is not None:
                if child not in index:
                    index[child] = low[child] = counter
                    counter += 1
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(graph[child]))))
                elif child in on_stack:
                    low[node] = min(low[node], index[child])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                component = []
                while True:
                    m = stack.pop()
                    on_stack.discard(m)
                    component.append(m)
                    if m == node:
                        break
                if len(component) > 1:
                    out.append(tuple(sorted(component)))
    return sorted(out, key=lambda c: (-len(c), c))


def layer_of(module: str, layers: tuple[tuple[str, tuple[str, ...]], ...] = LAYERS) -> tuple[int, str] | None:
    """``(rank, layer name)`` of ``module``: its longest matching prefix in ``layers`` (None: no layer)."""
    best: tuple[int, int, str] | None = None
    for rank, (layer, prefixes) in enumerate(layers):
        for p in prefixes:
            if (module == p or module.startswith(p + ".")) and (best is None or len(p) > best[0]):
                best = (len(p), rank, layer)
    return None if best is None else (best[1], best[2])


def upward_imports(imports: list[Import], layers: tuple[tuple[str, tuple[str, ...]], ...] = LAYERS) -> list[Import]:
    """The imports of a module of a layer above the importer's own."""
    out = []
    for e in imports:
        a, b = layer_of(e.source, layers), layer_of(e.target, layers)
        if a is not None and b is not None and b[0] > a[0]:
            out.append(e)
    return sorted(out, key=lambda e: (e.source, e.lineno, e.target))


def figures(package_dirs: dict[str, Path] | None = None,
            layers: tuple[tuple[str, tuple[str, ...]], ...] = LAYERS) -> Figures:
    """All the figures of the code under ``package_dirs`` (default: this repository's packages)."""
    modules = find_modules(package_dirs if package_dirs is not None else package_dirs_of(ROOT))
    imports = import_graph(modules)
    return Figures(
        modules=module_sizes(modules),
        functions=function_sizes(modules),
        imports=imports,
        circles=import_circles(imports),
        typed_circles=import_circles(import_graph(modules, type_checking=True)),
        upward=upward_imports(imports, layers),
        layers={m: (layer_of(m, layers) or (0, "?"))[1] for m in modules},
    )


# ------------------------------------------------------------------------ report
def _path(module: str, fig: Figures) -> str:
    for m in fig.modules:
        if m.name == module:
            try:
                return str(Path(m.path).relative_to(ROOT))
            except ValueError:
                return m.path
    return module


def report(fig: Figures, top: int = 10) -> list[str]:
    """The printed table, one line each."""
    lines = [f"{len(fig.modules)} modules, {fig.total_lines:,} lines, {len(fig.functions)} functions, "
             f"{len(fig.imports)} imports between modules"]
    lines += ["", f"largest modules (lines), top {top}:"]
    lines += [f"  {m.lines:6d}  {_path(m.name, fig)}" for m in fig.modules[:top]]
    lines += ["", f"longest functions (lines), top {top}:"]
    lines += [f"  {f.lines:6d}  {_path(f.module, fig)}:{f.qualname} (line {f.lineno})" for f in fig.functions[:top]]
    lines += [""]
    lines += [f"modules over {n} lines: {fig.modules_over(n)}" for n in MODULE_LINES]
    lines += [f"functions over {n} lines: {fig.functions_over(n)}" for n in FUNCTION_LINES]
    lines += ["", f"import circles: {len(fig.circles)}"]
    lines += [f"  {len(c)} modules: " + ", ".join(c) for c in fig.circles]
    lines += ["", f"import circles counting type-only imports: {len(fig.typed_circles)}"]
    lines += [f"  {len(c)} modules: " + ", ".join(c) for c in fig.typed_circles]
    lines += ["", f"upward imports: {len(fig.upward)}"]
    lines += [f"  {e.source} ({fig.layers.get(e.source)}) -> {e.target} ({fig.layers.get(e.target)}), "
              f"line {e.lineno}{' in a function' if e.in_function else ''}" for e in fig.upward]
    lines += ["", "goals:"]
    lines += [f"  {'met    ' if ok else 'not met'}  {goal} (today {n})" for goal, n, ok in fig.goals()]
    return lines


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--top", type=int, default=10, help="rows of the size tables")
    parser.add_argument("--json", action="store_true", help="print one JSON document")
    args = parser.parse_args(argv)
    fig = figures()
    if args.json:
        doc = {"modules": [asdict(m) for m in fig.modules], "functions": [asdict(f) for f in fig.functions],
               "circles": [list(c) for c in fig.circles], "upward": [asdict(e) for e in fig.upward],
               "counts": {**{f"modules_over_{n}": fig.modules_over(n) for n in MODULE_LINES},
                          **{f"functions_over_{n}": fig.functions_over(n) for n in FUNCTION_LINES}},
               "goals": [{"goal": g, "today": n, "met": ok} for g, n, ok in fig.goals()]}
        print(json.dumps(doc, indent=2))
    else:
        print("\n".join(report(fig, args.top)))
        sys.path.insert(0, str(Path(__file__).resolve().parent))
        import architecture_walls

        print("\n".join(["", *architecture_walls.report(find_modules(package_dirs_of(ROOT)), args.top)]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
