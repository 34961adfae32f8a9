"""Expand one xacro file inside a walled subprocess (run by :mod:`pinarms.robots.xacro_expand`).

This file runs as a script (``python -I _xacro_worker.py``) in a child process started
with resource limits (address space, CPU time, no file writes, no new processes), an
empty environment and a wall-clock timeout set by the parent. It imports only the
standard library and ``xacro``, never pinarms (nor Pinocchio).

Protocol: one JSON request on stdin::

    {"path": "/abs/file.xacro", "args": {"name": "value"}, "roots": ["/abs/dir", ...],
     "packages": {"pkg": "/abs/dir"}, "header": ["comment text", ...]}

and one JSON answer on stdout: ``{"ok": true, "urdf": "...", "files": [...],
"declared": {"arg": "default"}}`` or ``{"ok": false, "kind": "forbidden" | "xacro" |
"args", "message": "..."}``.

The wall, on top of xacro's own refusal of names starting with ``__``:

- every file xacro opens (the input, ``<xacro:include>`` files, ``load_yaml``) must lie,
  after resolving symbolic links, inside one of the allowed ``roots``;
- ``$(find PKG)`` resolves only the packages named in the request;
- ``$(env ...)``, ``$(optenv ...)``, ``$(eval ...)`` and ``$(cwd)`` are refused;
- each ``${...}`` expression is parsed and may hold only literals, names, arithmetic,
  comparisons, boolean and conditional expressions, calls, subscripts and attribute
  access to names that do not start with ``_``: no lambda, comprehension, generator,
  assignment expression, and no string literal holding ``__``.
"""

from __future__ import annotations

import ast
import json
import os
import sys


class Forbidden(Exception):
    """The file asks for something outside the wall."""


class ArgProblem(Exception):
    """A xacro argument given by the caller is not declared by the file."""


_ALLOWED_NODES = (
    ast.Expression, ast.Constant, ast.Name, ast.Load, ast.BinOp, ast.UnaryOp, ast.BoolOp,
    ast.Compare, ast.IfExp, ast.Call, ast.keyword, ast.Attribute, ast.Subscript, ast.Slice,
    ast.Tuple, ast.List, ast.Dict, ast.Set, ast.JoinedStr, ast.FormattedValue,
    ast.operator, ast.unaryop, ast.boolop, ast.cmpop,
)
# attributes that lead from an object to frames, code or globals (defence in depth: no
# construct allowed above creates a generator or a function, but refuse them by name too)
_DENIED_ATTRIBUTES = {"format", "format_map", "mro", "gi_frame", "gi_code", "cr_frame", "ag_frame",
                      "f_back", "f_globals", "f_locals", "f_builtins", "f_code", "tb_frame", "tb_next"}


def check_expression(expr: str) -> None:
    """Refuse a ``${...}`` expression outside the allowed subset (see the module doc)."""
    try:
        tree = ast.parse(expr.strip(), mode="eval")
    except SyntaxError:
        return  # xacro reports the syntax error itself
    for node in ast.walk(tree):
        if not isinstance(node, _ALLOWED_NODES):
            raise Forbidden(f"expression '{expr.strip()}' uses {type(node).__name__}, which pinarms does not allow in xacro")
        if isinstance(node, ast.Attribute) and (node.attr.startswith("_") or node.attr in _DENIED_ATTRIBUTES):
            raise Forbidden(f"expression '{expr.strip()}' accesses attribute '{node.attr}', which pinarms does not allow")
        if isinstance(node, ast.Name) and node.id.startswith("_"):
            raise Forbidden(f"expression '{expr.strip()}' uses name '{node.id}', which pinarms does not allow")
        if isinstance(node, ast.Constant) and isinstance(node.value, (str, bytes)) and (
            "__" in (node.value if isinstance(node.value, str) else node.value.decode("latin-1"))
        ):
            raise Forbidden(f"expression '{expr.strip()}' holds a string with '__', which pinarms does not allow")


class RecordingArgs(dict):
    """The caller's xacro arguments; records every ``<xacro:arg>`` the file declares."""

    def __init__(self, given: dict) -> None:
        super().__init__(given)
        self.declared: dict[str, str] = {}

    def __contains__(self, name) -> bool:  # xacro asks before storing a default
        self.declared.setdefault(name, None)
        return False  # so that xacro evaluates and hands us the default

    def __setitem__(self, name, value) -> None:
        if self.declared.get(name) is None:
            self.declared[name] = value
        if not dict.__contains__(self, name):
            dict.__setitem__(self, name, value)


def main() -> int:
    request = json.loads(sys.stdin.read())
    roots = [os.path.realpath(r) for r in request["roots"]]
    packages = {k: os.path.realpath(v) for k, v in request.get("packages", {}).items()}

    import xacro
    import xacro.substitution_args as subst

    def inside(path: str) -> bool:
        real = os.path.realpath(path)
        return any(real == r or real.startswith(r.rstrip(os.sep) + os.sep) for r in roots)

    def check_path(path: str, what: str) -> str:
        if not inside(path):
            raise Forbidden(
                f"{what} '{path}' is outside the folders this file may read "
                f"(its own folder and the packages given: {', '.join(sorted(packages)) or 'none'})"
            )
        return path

    original_parse = xacro.parse

    def parse(inp, filename=None):
        if inp is None and filename is not None:
            check_path(os.path.join(xacro.root_dir, filename), "file")
        return original_parse(inp, filename)

    original_load_yaml = xacro.load_yaml

    def load_yaml(filename):
        check_path(xacro.abs_filename_spec(filename), "yaml file")
        return original_load_yaml(filename)

    original_safe_eval = xacro.safe_eval

    def safe_eval(expr, globals, locals=None):
        check_expression(expr)
        return original_safe_eval(expr, globals, locals)

    def refuse(what):
        def fn(*args, **kwargs):
            raise Forbidden(f"$({what} ...) is not allowed in pinarms' xacro (files must not depend on the machine)")

        return fn

    def find(pkg):
        if pkg not in packages:
            raise Forbidden(
                f"$(find {pkg}): package '{pkg}' is not among the packages given "
                f"({', '.join(sorted(packages)) or 'none'}); pass it in packages={{'{pkg}': folder}}"
            )
        return packages[pkg]

    original_eval_extension = xacro.eval_extension

    def eval_extension(s):
        if s.strip() == "$(cwd)":
            raise Forbidden("$(cwd) is not allowed in pinarms' xacro (files must not depend on the machine)")
        return original_eval_extension(s)

    xacro.parse = parse
    xacro.load_yaml = load_yaml
    xacro.safe_eval = safe_eval
    xacro.eval_extension = eval_extension
    xacro._global_symbols = xacro.create_global_symbols()  # picks up the checked load_yaml
    subst._eval_env = refuse("env")
    subst._eval_optenv = refuse("optenv")
    subst._eval_find = find
    subst._eval = refuse("eval")
    subst._eval_dict.update(env=refuse("env"), optenv=refuse("optenv"), find=find)

    args = RecordingArgs({str(k): str(v) for k, v in request.get("args", {}).items()})
    path = request["path"]
    try:
        check_path(path, "file")
        doc = xacro.process_file(path, mappings=args)
    except Forbidden as exc:
        return _answer({"ok": False, "kind": "forbidden", "message": str(exc), "declared": args.declared})
    except MemoryError:
        return _answer({"ok": False, "kind": "memory", "message": "out of memory", "declared": args.declared})
    except RecursionError:
        return _answer({"ok": False, "kind": "xacro", "message": "macros or properties recurse without end", "declared": args.declared})
    except Exception as exc:  # XacroException, ExpatError, NameError, ...
        inner = getattr(exc, "exc", None)
        if isinstance(inner, Forbidden):
            return _answer({"ok": False, "kind": "forbidden", "message": str(inner), "declared": args.declared})
        if isinstance(inner, MemoryError):
            return _answer({"ok": False, "kind": "memory", "message": "out of memory", "declared": args.declared})
        message = " ".join(str(exc).split()) or type(exc).__name__
        return _answer({"ok": False, "kind": "xacro", "message": message, "declared": args.declared})
    unknown = sorted(set(dict.keys(args)) - set(args.declared))
    if unknown:
        declared = ", ".join(sorted(args.declared)) or "none"
        return _answer({"ok": False, "kind": "args", "message": f"unknown xacro argument(s) {', '.join(unknown)}; the file declares: {declared}", "declared": args.declared})
    root = doc.documentElement
    if root is None or root.tagName != "robot":
        tag = None if root is None else root.tagName
        return _answer({"ok": False, "kind": "xacro", "message": f"root element is <{tag}>, expected <robot>", "declared": args.declared})
    for node in list(doc.childNodes):  # xacro's banner holds the absolute path: replace it
        if node.nodeType == node.COMMENT_NODE and (
            "autogenerated by xacro" in node.data or "EDITING THIS FILE BY HAND" in node.data or set(node.data.strip()) == {"="}
        ):
            doc.removeChild(node)
    import xml.dom.minidom

    first = doc.firstChild
    for text in request.get("header", []):
        doc.insertBefore(xml.dom.minidom.Comment(text), first)
    files = sorted({os.path.realpath(f) for f in xacro.all_includes} | {os.path.realpath(path)})
    return _answer({"ok": True, "urdf": doc.toprettyxml(indent="  "), "files": files, "declared": args.declared})


def _answer(obj: dict) -> int:
    sys.stdout.write(json.dumps(obj))
    sys.stdout.flush()
    return 0


if __name__ == "__main__":
    sys.exit(main())
