"""``benchmarks/architecture.py`` and ``architecture_walls.py`` loaded as modules for the architecture tests (scripts, not a package)."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path
from types import ModuleType

SCRIPT = Path(__file__).resolve().parents[1] / "benchmarks" / "architecture.py"
NAME = "architecture_figures"


def architecture() -> ModuleType:
    """The script's module (loaded once per process): its :data:`LAYERS` and analysis functions."""
    module = sys.modules.get(NAME)
    if module is None:
        spec = importlib.util.spec_from_file_location(NAME, SCRIPT)
        module = importlib.util.module_from_spec(spec)
        sys.modules[NAME] = module  # dataclasses look their module up by name
        spec.loader.exec_module(module)
    return module


WALLS = SCRIPT.with_name("architecture_walls.py")


def walls() -> ModuleType:
    """``benchmarks/architecture_walls.py`` (loaded once per process): private-name uses, references, signatures."""
    module = sys.modules.get("architecture_walls")
    if module is None:
        spec = importlib.util.spec_from_file_location("architecture_walls", WALLS)
        module = importlib.util.module_from_spec(spec)
        sys.modules["architecture_walls"] = module
        spec.loader.exec_module(module)
    return module
