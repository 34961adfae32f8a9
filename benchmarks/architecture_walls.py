"""Walls between modules and the front door, measured: what ``benchmarks/architecture.py`` prints below its tables.

Each function takes ``{dotted module name: file}`` (:func:`architecture.find_modules`) and reads the
files with :mod:`ast`; nothing of the package is imported, except by :func:`import_seconds`, which
imports one module in a fresh interpreter.

- :func:`private_uses`: a module using another module's private names (one leading underscore):
  ``from m import _name`` of a function, class or constant; ``from m._private import x`` or
  ``import m._private`` of a private module from outside the package that holds it; and
  ``obj._name`` (or ``getattr(obj, "_name")``) read or written on an object other than ``self``/``cls``
  when another module of the code defines that ``_name`` and this one does not (so ``other._name`` of a
  class of the same module is its own business, and a library's private names are left to the library);
- :func:`docstring_references`: every dotted Sphinx reference (``:mod:`x.y```, ``:func:`x.y.f```,
  ``:class:``, ``:meth:``, ``:attr:``, ``:data:``, ``:exc:``, a leading ``~`` dropped) whose first part
  names a package of the code (``pinarms``, or a folder's own name such as ``optim``), with whether it
  can be imported: its longest module prefix is a module of the code and the rest is defined there;
- :func:`parameter_figures`: the public functions and methods (names without a leading underscore, in
  modules and classes without one) with their parameters (``self``/``cls`` left out), how many take
  ten or more, and the share of parameters whose annotation mentions ``Any``;
- :func:`import_seconds`: the wall time of ``import <module>`` in a fresh interpreter, the best of a few.
"""

from __future__ import annotations

import ast
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

__all__ = ["report", "LIGHT_MODULE", "LIGHT_SECONDS", "PrivateUse", "Reference", "Signature", "private_uses", "docstring_references", "parameter_figures",
           "import_seconds", "MANY_PARAMETERS"]

#: A public function with this many parameters or more counts as a long signature.
MANY_PARAMETERS = 10

#: The module a user of the event simulator imports, and the most it may cost [s] warm: no planner,
#: no numba, coal or Pinocchio behind it.
LIGHT_MODULE = "pinarms.optim.line"
LIGHT_SECONDS = 0.3

_ROLES = ("mod", "func", "class", "meth", "attr", "data", "exc", "obj")


def _private(name: str) -> bool:
    return name.startswith("_") and not name.startswith("__")


def _parse(path: Path) -> ast.Module:
    return ast.parse(path.read_text(encoding="utf-8"), filename=str(path))


@dataclass(frozen=True)
class PrivateUse:
    """``module`` uses ``name`` (a private name of another module, or ``target``'s private module) at ``lineno``."""

    module: str
    lineno: int
    kind: str  # "import" | "private module" | "attribute"
    name: str
    target: str = ""

    @property
    def across_folders(self) -> bool:
        """Whether the other module lies in another package folder (``optim.motion`` using ``robots.cell``)."""
        return bool(self.target) and self.target.rsplit(".", 1)[0] != self.module.rsplit(".", 1)[0] \
            and not self.target.startswith(self.module.rsplit(".", 1)[0] + ".")


def _resolve(module: str, is_package: bool, node: ast.ImportFrom) -> str:
    if node.level == 0:
        return node.module or ""
    parts = module.split(".") if is_package else module.split(".")[:-1]
    base = parts[: max(0, len(parts) - (node.level - 1))]
    return ".".join(base + ([node.module] if node.module else []))


def _own_private_names(tree: ast.Module) -> set[str]:
    """Private names a module defines anywhere: defs, classes, assignments, ``self._x = ...``, imports."""
    out: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            out.add(node.name)
        elif isinstance(node, ast.Name) and isinstance(node.ctx, ast.Store):
            out.add(node.id)
        elif isinstance(node, ast.Attribute) and isinstance(node.ctx, ast.Store) and \
                isinstance(node.value, ast.Name) and node.value.id in ("self", "cls"):
            out.add(node.attr)
        elif isinstance(node, ast.alias):
            out.add(node.asname or node.name.split(".")[0])
        elif isinstance(node, ast.arg):
            out.add(node.arg)
    return {n for n in out if _private(n)}


def _private_module_outside(importer: str, target: str, known: set[str]) -> str | None:
    """The private module of ``target`` (a dotted name) that ``importer`` may not reach, or None."""
    parts = target.split(".")
    for k in range(1, len(parts)):
        if _private(parts[k]) and ".".join(parts[: k + 1]) in known:
            owner = ".".join(parts[:k])
            if importer != owner and not importer.startswith(owner + "."):
                return ".".join(parts[: k + 1])
            return None
    return None


def private_uses(modules: dict[str, Path]) -> list[PrivateUse]:
    """Every use of another module's private name (see the module's docstring), by module and line."""
    known = set(modules)
    trees = {name: _parse(path) for name, path in modules.items()}
    owns = {name: _own_private_names(tree) for name, tree in trees.items()}
    out: list[PrivateUse] = []
    for name, path in modules.items():
        tree = trees[name]
        own = owns[name]
        others = {n for m, names in owns.items() if m != name for n in names} - own
        is_package = path.name == "__init__.py"
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom):
                base = _resolve(name, is_package, node)
                hidden = _private_module_outside(name, base, known)
                if hidden:
                    out.append(PrivateUse(name, node.lineno, "private module", hidden, hidden))
                for alias in node.names:
                    full = f"{base}.{alias.name}"
                    if full in known:
                        hidden = _private_module_outside(name, full, known)
                        if hidden and hidden == full:
                            out.append(PrivateUse(name, node.lineno, "private module", hidden, hidden))
                    elif _private(alias.name) and base in known and base != name:
                        out.append(PrivateUse(name, node.lineno, "import", alias.name, base))
            elif isinstance(node, ast.Import):
                for alias in node.names:
                    hidden = _private_module_outside(name, alias.name, known)
                    if hidden:
                        out.append(PrivateUse(name, node.lineno, "private module", hidden, hidden))
            elif isinstance(node, ast.Attribute) and node.attr in others:
                if not (isinstance(node.value, ast.Name) and node.value.id in ("self", "cls")):
                    out.append(PrivateUse(name, node.lineno, "attribute", node.attr))
            elif isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and \
                    node.func.id in ("getattr", "setattr", "hasattr", "delattr") and len(node.args) >= 2 and \
                    isinstance(node.args[1], ast.Constant) and isinstance(node.args[1].value, str) and \
                    node.args[1].value in others:
                out.append(PrivateUse(name, node.lineno, "attribute", node.args[1].value))
    return sorted(out, key=lambda u: (u.module, u.lineno, u.name))


# ------------------------------------------------------------------ docstring references
@dataclass(frozen=True)
class Reference:
    """A dotted reference ``text`` in a docstring of ``module`` at ``lineno``; ``importable``: it resolves."""

    module: str
    lineno: int
    text: str
    importable: bool


def _defined_names(tree: ast.Module) -> dict[str, set[str]]:
    """``{"": top-level names, "Class": its attributes and methods}`` of a module (names a lazy
    ``_EXPORTS`` table offers count as top-level names)."""
    out: dict[str, set[str]] = {"": set()}
    for node in tree.body:
        if isinstance(node, ast.ClassDef):
            members = out.setdefault(node.name, set())
            out.setdefault(" bases " + node.name, set()).update(b.id for b in node.bases if isinstance(b, ast.Name))
            for item in ast.walk(node):
                if isinstance(item, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                    members.add(item.name)
                elif isinstance(item, ast.AnnAssign) and isinstance(item.target, ast.Name):
                    members.add(item.target.id)
                elif isinstance(item, ast.Assign):
                    members.update(t.id for t in item.targets if isinstance(t, ast.Name))
                elif isinstance(item, ast.Attribute) and isinstance(item.ctx, ast.Store):
                    members.add(item.attr)
        if isinstance(node, ast.Assign):  # Class.method = function, at module level; names listed in __all__
            for t in node.targets:
                if isinstance(t, ast.Attribute) and isinstance(t.value, ast.Name):
                    out.setdefault(t.value.id, set()).add(t.attr)
                elif isinstance(t, ast.Name) and t.id == "__all__" and isinstance(node.value, (ast.List, ast.Tuple)):
                    out[""].update(e.value for e in node.value.elts if isinstance(e, ast.Constant))
        if isinstance(node, ast.Assign) and any(isinstance(t, ast.Name) and t.id == "_EXPORTS" for t in node.targets) \
                and isinstance(node.value, ast.Dict):
            out[""].update(k.value for k in node.value.keys if isinstance(k, ast.Constant))
        for sub in ast.walk(node) if not isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)) \
                else [node]:
            if isinstance(sub, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                out[""].add(sub.name)
            elif isinstance(sub, (ast.Import, ast.ImportFrom)):
                out[""].update((a.asname or a.name).split(".")[0] for a in sub.names)
            elif isinstance(sub, ast.Name) and isinstance(sub.ctx, ast.Store):
                out[""].add(sub.id)
    return out


def _homes(modules: dict[str, Path], trees: dict[str, ast.Module]) -> dict[tuple[str, str], str]:
    """``{(module, name): module it comes from}`` for names a module imports or offers lazily."""
    out: dict[tuple[str, str], str] = {}
    for name, tree in trees.items():
        is_package = modules[name].name == "__init__.py"
        for node in tree.body:
            if isinstance(node, ast.ImportFrom):
                base = _resolve(name, is_package, node)
                for a in node.names:
                    out[(name, a.asname or a.name)] = base
            elif isinstance(node, ast.Assign) and any(isinstance(t, ast.Name) and t.id == "_EXPORTS"
                                                      for t in node.targets) and isinstance(node.value, ast.Dict):
                for k, v in zip(node.value.keys, node.value.values):
                    if isinstance(k, ast.Constant) and isinstance(v, ast.Constant):
                        where = v.value.partition(":")[0]
                        if where.startswith("."):
                            level = len(where) - len(where.lstrip("."))
                            parts = name.split(".") if is_package else name.split(".")[:-1]
                            where = ".".join(parts[: len(parts) - (level - 1)] + [where.lstrip(".")])
                        out[(name, k.value)] = where
    return out


def _resolves(text: str, known: set[str], names: dict[str, dict[str, set[str]]],
              homes: dict[tuple[str, str], str] | None = None, depth: int = 0) -> bool:
    parts = text.split(".")
    for k in range(len(parts), 0, -1):
        module = ".".join(parts[:k])
        if module in known:
            rest = parts[k:]
            if not rest:
                return True
            defined = names[module]
            if rest[0] not in defined[""] and ".".join([module, rest[0]]) not in known:
                return False
            if len(rest) == 1 or rest[1] in defined.get(rest[0], set()):
                return True
            for base in defined.get(" bases " + rest[0], ()):  # a member inherited from a base class
                where = (homes or {}).get((module, base), module)
                if depth < 5 and _resolves(".".join([where, base, *rest[1:]]), known, names, homes, depth + 1):
                    return True
            home = (homes or {}).get((module, rest[0]))
            if home and depth < 5:
                return _resolves(".".join([home, *rest]), known, names, homes, depth + 1)
            return len(rest) > 2
    return False


def docstring_references(modules: dict[str, Path], roots: tuple[str, ...] | None = None) -> list[Reference]:
    """Every dotted reference in the docstrings whose first part is a package root (default: the code's roots and the
    last part of each top-level package: ``pinarms``, ``robots``, ``planning``, ``optim``, ``viz``, ``urdf``)."""
    import re

    known = set(modules)
    if roots is None:
        tops = {m.split(".")[0] for m in known}
        roots = tuple(sorted(tops | {m.split(".")[1] for m in known if m.count(".") >= 1 and m.split(".")[0] in tops}))
    pattern = re.compile(r":(?:py:)?(?:%s):`~?([A-Za-z_][\w.]*)`" % "|".join(_ROLES))
    trees = {name: _parse(path) for name, path in modules.items()}
    names = {name: _defined_names(tree) for name, tree in trees.items()}
    homes = _homes(modules, trees)
    out: list[Reference] = []
    for name, tree in trees.items():
        for node in ast.walk(tree):
            if not isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)):
                continue
            doc = ast.get_docstring(node, clean=False)
            if not doc or not node.body:
                continue
            first = node.body[0].lineno
            for match in pattern.finditer(doc):
                text = match.group(1)
                if "." in text and text.split(".")[0] in roots:
                    line = first + doc[: match.start()].count("\n")
                    out.append(Reference(name, line, text, _resolves(text, known, names, homes)))
            # comments with #: above constants are not docstrings; they are left out
    return sorted(out, key=lambda r: (r.module, r.lineno, r.text))


# ------------------------------------------------------------------ signatures
@dataclass(frozen=True)
class Signature:
    """A public function or method ``qualname`` of ``module``: its parameters and how many are typed with ``Any``."""

    module: str
    qualname: str
    lineno: int
    parameters: int
    any_typed: int


def _mentions_any(annotation: ast.AST | None) -> bool:
    if annotation is None:
        return False
    if isinstance(annotation, ast.Constant) and isinstance(annotation.value, str):
        try:
            annotation = ast.parse(annotation.value, mode="eval").body
        except SyntaxError:
            return "Any" in annotation.value
    return any((isinstance(n, ast.Name) and n.id == "Any") or (isinstance(n, ast.Attribute) and n.attr == "Any")
               for n in ast.walk(annotation))


def parameter_figures(modules: dict[str, Path]) -> list[Signature]:
    """The public functions and methods of the public modules, with their parameter counts."""
    out: list[Signature] = []
    for name, path in modules.items():
        if any(_private(part) for part in name.split(".")):
            continue
        tree = _parse(path)

        def visit(body: list[ast.stmt], scope: tuple[str, ...], in_class: bool) -> None:
            for node in body:
                if isinstance(node, ast.ClassDef) and not _private(node.name):
                    visit(node.body, (*scope, node.name), True)
                elif isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) and \
                        (not _private(node.name) or node.name == "__init__"):
                    a = node.args
                    params = [*a.posonlyargs, *a.args, *a.kwonlyargs]
                    if in_class and params and params[0].arg in ("self", "cls") and not any(
                            isinstance(d, ast.Name) and d.id == "staticmethod" for d in node.decorator_list):
                        params = params[1:]
                    params += [p for p in (a.vararg, a.kwarg) if p is not None]
                    out.append(Signature(name, ".".join((*scope, node.name)), node.lineno, len(params),
                                         sum(_mentions_any(p.annotation) for p in params)))

        visit(tree.body, (), False)
    return sorted(out, key=lambda s: (-s.parameters, s.module, s.qualname))


def import_seconds(module: str, runs: int = 3, python: str = sys.executable, cwd: Path | None = None) -> float:
    """The best wall time [s] of ``import module`` over ``runs`` fresh interpreters (each measured inside itself)."""
    code = f"import time; t = time.perf_counter(); import {module}; print(time.perf_counter() - t)"
    best = float("inf")
    for _ in range(runs):
        done = subprocess.run([python, "-c", code], capture_output=True, text=True, check=True, cwd=cwd)
        best = min(best, float(done.stdout.strip().splitlines()[-1]))
    return best


def imported_modules(module: str, python: str = sys.executable, cwd: Path | None = None) -> list[str]:
    """The modules a fresh interpreter holds after ``import module`` (beyond those it starts with)."""
    code = (f"import sys; before = set(sys.modules); import {module}; "
            f"print('\\n'.join(sorted(set(sys.modules) - before)))")
    done = subprocess.run([python, "-c", code], capture_output=True, text=True, check=True, cwd=cwd)
    return done.stdout.split()


def report(modules: dict[str, Path], top: int = 10) -> list[str]:
    """The printed lines: private-name uses, docstring references, signatures, the light import."""
    from collections import Counter

    uses = private_uses(modules)
    kinds = Counter(u.kind for u in uses)
    lines = [f"uses of another module's private names: {len(uses)}" + (
        f" ({', '.join(f'{n} {k}' for k, n in sorted(kinds.items()))}; "
        f"{sum(u.across_folders for u in uses)} across package folders)" if uses else "")]
    by_name = Counter(u.name for u in uses)
    lines += [f"  {n:4d}  {name}" for name, n in by_name.most_common(top)]
    refs = docstring_references(modules)
    bad = [r for r in refs if not r.importable]
    lines += ["", f"docstring references naming a package: {len(refs)}, not importable: {len(bad)}"]
    lines += [f"  {r.module}:{r.lineno}  {r.text}" for r in bad[:top]]
    sigs = parameter_figures(modules)
    n_params = sum(s.parameters for s in sigs)
    n_any = sum(s.any_typed for s in sigs)
    long = [s for s in sigs if s.parameters >= MANY_PARAMETERS]
    lines += ["", f"public functions and methods: {len(sigs)}, with >= {MANY_PARAMETERS} parameters: {len(long)}; "
              f"parameters typed Any: {n_any} of {n_params} ({100 * n_any / max(n_params, 1):.1f} %)"]
    lines += [f"  {s.parameters:4d}  {s.module}:{s.qualname}" for s in long[:top]]
    root = Path(__file__).resolve().parents[1]
    seconds = import_seconds(LIGHT_MODULE, cwd=root)
    loaded = imported_modules(LIGHT_MODULE, cwd=root)
    heavy = [m for m in ("numba", "pinocchio", "coal", "pinarms.optim.motion") if m in loaded]
    lines += ["", f"import {LIGHT_MODULE}: {seconds:.2f} s (best of 3; goal <= {LIGHT_SECONDS} s), "
              f"{sum(m.startswith('pinarms') for m in loaded)} pinarms modules, heavy: {', '.join(heavy) or 'none'}"]
    return lines
