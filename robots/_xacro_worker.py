"""Expand one xacro file inside a walled subprocess (run by :mod:`pinarms.robots.xacro_expand`).

This file runs as a script (``python -I -B _xacro_worker.py``) in a child process started
with resource limits (address space, CPU time, no file writes, no new processes), an
empty environment and a wall-clock timeout set by the parent. It imports only the
standard library, ``xacro`` and ``yaml``, and loads two sibling files by path:
``xacro_eval.py`` (the expression whitelist) and ``_sandbox.py`` (the Landlock wall, shared
with the map reader), never pinarms itself (nor Pinocchio).

Protocol: JSON lines. The request, one line on stdin::

    {"path": "/abs/file.xacro", "args": {"name": "value"}, "roots": ["/abs/dir", ...],
     "packages": {"pkg": "/abs/dir"}, "header": ["comment text", ...]}

then, for every file xacro opens, a question on stdout ``{"op": "read", "path", "what"}``
(or ``{"op": "glob", "pattern"}`` for an include pattern) and the parent's answer on stdin
(:mod:`pinarms.robots._xacro_child`: ``{"text"}``, ``{"names"}``, ``{"forbidden"}``,
``{"limit"}`` or ``{"errno", "message"}``); the child opens no file of the request itself.
Last, the answer on stdout: ``{"ok": true, "urdf": "...", "declared": {"arg": "default"},
"wall": "..."}`` or ``{"ok": false, "kind": "forbidden" | "limit" | "not_found" | "xacro" |
"args" | "memory", "message": "...", ...}``.

The walls, in order:

1. every ``${...}`` goes through :func:`xacro_eval.evaluate` (xacro's ``safe_eval`` is
   replaced; the name ``eval`` inside xacro's modules refuses), never Python's ``eval``;
2. every file xacro opens (the input, ``<xacro:include>`` files and patterns, ``load_yaml``)
   is served by the parent only if it lies, after resolving symbolic links, inside one of
   the allowed ``roots``; ``$(find PKG)`` resolves only the packages named; ``$(env)``,
   ``$(optenv)``, ``$(eval)``, ``$(cwd)`` refuse; a ``DOCTYPE`` in any file refuses;
3. before the first file is asked for, the process imports everything it uses and walls
   itself in (:func:`_sandbox.enter_wall`, with no folder to read): no write, no network,
   no capability, no other process, whatever code might run.
"""

from __future__ import annotations

import errno
import importlib.util
import json
import os
import stat
import sys
from pathlib import Path


class Forbidden(Exception):
    """The file asks for something outside the wall."""


class TooLarge(Exception):
    """An expression would build a value beyond the size bounds."""


def _load_sibling(name: str):
    spec = importlib.util.spec_from_file_location(f"pinarms_xacro_child_{name}", Path(__file__).with_name(f"{name}.py"))
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


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


def _location(xacro) -> str:
    """Where xacro is: the innermost file being read and the macro being expanded."""
    parts = []
    if xacro.macrostack:
        macro = xacro.macrostack[-1]
        defined = macro.history[-1][-1] if macro.history and macro.history[-1] else None
        parts.append(f"in macro '{macro.body.getAttribute('name')}'" + (f" (defined in '{defined}')" if defined else ""))
    if xacro.filestack and xacro.filestack[-1]:
        parts.append(f"in file '{xacro.filestack[-1]}'")
    return ", ".join(parts)


class _Parent:
    """The pipe to the parent: one JSON line each way; the parent serves every file of the request."""

    def ask(self, message: dict) -> dict:
        sys.stdout.write(json.dumps(message) + "\n")
        sys.stdout.flush()
        return json.loads(sys.stdin.readline())


class _Hooks:
    """xacro's file, expression and substitution entry points, walled."""

    def __init__(self, xacro, subst, whitelist, parent: _Parent, packages: dict[str, str]) -> None:
        self.xacro, self.subst, self.whitelist, self.parent = xacro, subst, whitelist, parent
        self.packages = packages
        self.original_parse = xacro.parse
        self.functions = {
            **whitelist.FUNCTIONS,
            "xacro.arg": self.arg, "xacro.tokenize": self.tokenize,
            "load_yaml": self.load_yaml, "xacro.load_yaml": self.load_yaml,
        }

    def _checked(self, reply: dict, path: str):
        if "forbidden" in reply:
            raise Forbidden(reply["forbidden"])
        if "limit" in reply:
            raise TooLarge(reply["limit"])
        if "errno" in reply:
            raise OSError(reply["errno"], reply["message"], path)
        return reply

    def read(self, path: str, what: str) -> str:
        """The text of ``path``, from the parent (which checks that it lies in the allowed folders)."""
        return self._checked(self.parent.ask({"op": "read", "path": path, "what": what}), path)["text"]

    def glob(self, pattern: str) -> list[str]:
        pattern = os.path.abspath(pattern)
        return self._checked(self.parent.ask({"op": "glob", "pattern": pattern}), pattern)["names"]

    def parse(self, inp, filename=None):
        if inp is None and filename is not None:
            full = os.path.join(self.xacro.root_dir, filename)
            try:
                inp = self.read(full, "file")
            except OSError as exc:  # as xacro reports it: not "in file" the missing one
                self.xacro.filestack.pop()
                raise self.xacro.XacroException(f"{exc.strerror}: {exc.filename}", exc=exc) from None
        doc = self.original_parse(inp, filename)
        if getattr(doc, "doctype", None) is not None:
            raise Forbidden(f"'{filename or 'the file'}' declares a DOCTYPE ('{doc.doctype.name}'); DOCTYPE "
                            "declarations and entities are not allowed in pinarms' xacro (remove the declaration)")
        return doc

    def load_yaml(self, filename):
        if not isinstance(filename, str):
            raise TypeError(f"load_yaml() takes a file name, got {type(filename).__name__}")
        import yaml

        full = self.xacro.abs_filename_spec(filename)
        text = self.read(full, "yaml file")
        self.xacro.filestack.append(full)
        try:
            return self.xacro.YamlListWrapper.wrap(yaml.safe_load(text))
        finally:
            self.xacro.filestack.pop()
            self.xacro.all_includes.append(full)

    def arg(self, name):
        return self.xacro.substitution_args_context["arg"][name]

    def tokenize(self, s, sep=",; ", skip_empty=True):
        if not isinstance(s, str) or not isinstance(sep, str) or set(sep) & set("[]\\^-"):
            raise ValueError("xacro.tokenize() takes a string and separator characters other than [ ] \\ ^ -")
        return self.xacro.tokenize(s, sep, bool(skip_empty))

    def safe_eval(self, expr, globals, locals=None):
        try:
            return self.whitelist.evaluate(expr, globals, functions=self.functions,
                                           namespaces=(self.xacro.NameSpace,), attr_dicts=(self.xacro.YamlDictWrapper,))
        except self.whitelist.ExpressionTooLarge as exc:
            raise TooLarge(f"{_location(self.xacro)}: {exc}") from None
        except self.whitelist.ExpressionRefused as exc:
            raise Forbidden(f"{_location(self.xacro)}: {exc}") from None

    def find(self, pkg):
        if pkg not in self.packages:
            raise Forbidden(
                f"$(find {pkg}): package '{pkg}' is not among the packages given "
                f"({', '.join(sorted(self.packages)) or 'none'}); pass it in packages={{'{pkg}': folder}} "
                f"(on the command line --package {pkg}=FOLDER)"
            )
        return self.packages[pkg]

    def eval_extension(self, s):
        if s.strip() == "$(cwd)":
            raise Forbidden("$(cwd) is not allowed in pinarms' xacro (files must not depend on the machine)")
        return self.original_eval_extension(s)

    def install(self) -> None:
        import types

        import yaml

        xacro, subst = self.xacro, self.subst

        def refuse(what):
            def fn(*args, **kwargs):
                raise Forbidden(f"{what} is not allowed in pinarms' xacro (files must not depend on the machine)")

            return fn

        for unit in xacro.ConstructUnits:  # xacro's !radians / !degrees yaml tags, registered once
            yaml.SafeLoader.add_constructor(unit.value.tag, unit.constructor)
        self.original_eval_extension = xacro.eval_extension
        xacro.parse, xacro.load_yaml, xacro.safe_eval = self.parse, self.load_yaml, self.safe_eval
        xacro.glob = types.SimpleNamespace(glob=self.glob)  # include patterns are listed by the parent
        xacro.eval_extension = self.eval_extension
        xacro._global_symbols = xacro.create_global_symbols()  # picks up the checked load_yaml
        xacro.eval = subst.eval = refuse("Python's eval")  # any path left to eval() inside xacro refuses
        subst._eval_env, subst._eval_optenv, subst._eval = refuse("$(env ...)"), refuse("$(optenv ...)"), refuse("$(eval ...)")
        subst._eval_find = self.find
        subst._eval_dict.update(env=subst._eval_env, optenv=subst._eval_optenv, find=self.find)


def _failure(exc: BaseException, xacro, declared: dict) -> dict:
    """The answer for an exception out of xacro: its kind and a message naming where it happened."""
    import xml.parsers.expat

    chain, inner = [exc], exc
    while getattr(inner, "exc", None) is not None and len(chain) < 20:  # XacroException wraps the cause
        inner = inner.exc
        chain.append(inner)
    where = _location(xacro)
    for item in chain:
        if isinstance(item, Forbidden):
            return {"ok": False, "kind": "forbidden", "message": str(item), "declared": declared}
        if isinstance(item, TooLarge):
            return {"ok": False, "kind": "limit", "message": str(item), "declared": declared}
        if isinstance(item, MemoryError):
            return {"ok": False, "kind": "memory", "message": "out of memory", "declared": declared}
        if isinstance(item, OSError) and item.errno == errno.ENOENT:
            message = f"file '{item.filename}' does not exist" + (f" (included {where})" if where else "")
            return {"ok": False, "kind": "not_found", "message": message, "declared": declared}
    if isinstance(exc, RecursionError):
        return {"ok": False, "kind": "xacro", "message": "macros or properties recurse without end", "declared": declared}
    if isinstance(exc, xml.parsers.expat.ExpatError):
        name = xacro.filestack[-1] if xacro.filestack and xacro.filestack[-1] else "the file"
        message = (f"'{name}' is not well-formed XML at line {exc.lineno}, column {exc.offset + 1}: "
                   f"{xml.parsers.expat.ErrorString(exc.code)}")
        return {"ok": False, "kind": "xacro", "message": message, "declared": declared}
    message = " ".join(str(exc).split()) or type(exc).__name__
    if where:
        message += f" ({where})"
    return {"ok": False, "kind": "xacro", "message": message, "declared": declared}


def prepare(request: dict):
    """Import everything, hook xacro and enter the wall; ``(xacro, hooks, wall)``.

    Everything the expansion imports is imported before the wall: a child that became
    ``nobody`` may not be able to read the standard library any more.
    """
    packages = {k: os.path.realpath(v) for k, v in request.get("packages", {}).items()}
    import types  # noqa: F401
    import xml.dom.expatbuilder  # noqa: F401 - minidom imports it at the first parse
    import xml.dom.minidom  # noqa: F401
    import xml.dom.xmlbuilder  # noqa: F401
    import xml.parsers.expat  # noqa: F401

    import xacro
    import xacro.substitution_args as subst
    import yaml  # noqa: F401

    whitelist = _load_sibling("xacro_eval")
    hooks = _Hooks(xacro, subst, whitelist, _Parent(), packages)
    hooks.install()
    wall = _load_sibling("_sandbox").enter_wall([])  # the parent serves the files: no folder to read
    return xacro, hooks, wall


def main() -> int:
    import xml.dom.minidom

    request = json.loads(sys.stdin.readline())
    xacro, _, wall = prepare(request)
    args = RecordingArgs({str(k): str(v) for k, v in request.get("args", {}).items()})
    path = request["path"]
    try:
        doc = xacro.process_file(path, mappings=args)
    except Forbidden as exc:
        return _answer({"ok": False, "kind": "forbidden", "message": str(exc), "declared": args.declared})
    except Exception as exc:  # XacroException, ExpatError, NameError, MemoryError, RecursionError ...
        return _answer(_failure(exc, xacro, args.declared))
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
    first = doc.firstChild
    for text in request.get("header", []):
        doc.insertBefore(xml.dom.minidom.Comment(text), first)
    return _answer({"ok": True, "urdf": doc.toprettyxml(indent="  "), "declared": args.declared, "wall": wall})


def _answer(obj: dict) -> int:
    sys.stdout.write(json.dumps(obj) + "\n")
    sys.stdout.flush()
    return 0


if __name__ == "__main__":
    sys.exit(main())
