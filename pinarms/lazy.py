"""Packages whose public names load on first use (PEP 562 ``__getattr__``): ``import pinarms.optim.line`` stays light.

A package ``__init__`` lists where each of its public names is defined and hands the table to
:func:`lazy_exports`; the defining module is imported the first time the name is used
(``pinarms.optim.plan_motion``, ``from pinarms.optim import plan_motion``), never when the package
or one of its other subpackages is imported. Part of the floor: it imports no package of pinarms.
"""

from __future__ import annotations

import importlib
import sys
import types
from typing import Any, Callable, Mapping

__all__ = ["lazy_exports"]


def lazy_exports(package: str, exports: Mapping[str, str]) -> tuple[Callable[[str], Any], Callable[[], list[str]]]:
    """``(__getattr__, __dir__)`` for ``package`` whose names ``exports`` maps to their modules.

    ``exports``: ``{name: module}``, the module relative to ``package`` (``".cell"``) or absolute;
    ``"module:other"`` when the package offers the module's ``other`` under ``name``. A name
    loaded once is kept in the package's namespace, so later uses cost nothing. A name that is also
    a submodule's (``pinarms.planning.tool_path``, the function, in the module of that name) stays the
    name's object when the submodule loads: the import system's binding of the submodule is skipped.
    """

    class Package(types.ModuleType):
        def __setattr__(self, name: str, value: Any) -> None:
            if name in exports and isinstance(value, types.ModuleType) and value.__name__ == f"{package}.{name}":
                return
            super().__setattr__(name, value)

    sys.modules[package].__class__ = Package

    def __getattr__(name: str) -> Any:
        where = exports.get(name)
        if where is None:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        module, _, attr = where.partition(":")
        value = getattr(importlib.import_module(module, package), attr or name)
        setattr(sys.modules[package], name, value)
        return value

    def __dir__() -> list[str]:
        return sorted(set(vars(sys.modules[package])) | set(exports))

    return __getattr__, __dir__
