"""The front door: ``import pinarms`` offers the names a user starts with, and every package loads lazily.

Each package ``__init__`` lists where its public names are defined (:func:`pinarms.lazy.lazy_exports`);
these tests import each name in a fresh interpreter (so that nothing another test loaded hides a
broken table) and check what ``import pinarms`` and ``import pinarms.optim.line`` load.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

PACKAGES = ("pinarms", "pinarms.robots", "pinarms.robots.cell", "pinarms.planning", "pinarms.optim",
            "pinarms.optim.cycle", "pinarms.optim.layout", "pinarms.optim.line", "pinarms.optim.motion",
            "pinarms.optim.timing", "pinarms.optim.topp", "pinarms.viz", "pinarms.export")


def _run(code: str) -> str:
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT)
    assert done.returncode == 0, done.stderr
    return done.stdout


def test_the_front_door_offers_the_names_a_user_starts_with():
    out = json.loads(_run(
        "import json, sys; import pinarms; before = sorted(m for m in sys.modules if m.startswith('pinarms'));"
        "print(json.dumps({'all': pinarms.__all__, 'loaded': before}))"))
    assert out["loaded"] == ["pinarms", "pinarms.lazy"]  # nothing else until a name is used
    assert {"load", "load_cell", "Robot", "Cell", "plan_motion", "plan_cycle", "run_line", "search_layout",
            "PinarmsError"} <= set(out["all"])
    assert len(out["all"]) <= 15


@pytest.mark.slow
def test_every_public_name_of_every_package_loads():
    """Every name in each package's ``__all__`` resolves (one fresh interpreter loads them all), to the
    object its table names, never to a submodule of the same name (``pinarms.planning.tool_path``)."""
    out = json.loads(_run(
        f"import json, types, importlib; out = {{}}\nfor package in {PACKAGES!r}:\n"
        "    p = importlib.import_module(package)\n"
        "    out[package] = [len(p.__all__), [n for n in p.__all__ if isinstance(getattr(p, n), types.ModuleType)],"
        " sorted(set(p.__all__) - set(dir(p)))]\n"
        "print(json.dumps(out))"))
    assert set(out) == set(PACKAGES)
    for package, (n, modules, hidden) in out.items():
        assert n > 0 and modules == [] and hidden == [], package


def test_an_unknown_name_is_an_attribute_error_naming_the_package():
    out = _run("import pinarms.optim as o\ntry:\n    o.no_such_name\nexcept AttributeError as e:\n    print(e)")
    assert "'pinarms.optim' has no attribute 'no_such_name'" in out


@pytest.mark.slow
def test_the_event_simulator_loads_no_planner():
    """``from pinarms.optim.line import run_line`` (the simulator's front door) loads neither the planner nor
    numba, coal or Pinocchio."""
    loaded = set(_run("import sys; from pinarms.optim.line import run_line, LineSpec, Belt;"
                      "print('\\n'.join(sys.modules))").split())
    assert not loaded & {"numba", "pinocchio", "coal", "pinarms.optim.motion", "pinarms.robots.cell"}
