"""Every ``pinarms.x.y`` / ``x.y.name`` the docs name in their code spans and blocks, and every name
their code blocks import from pinarms, resolves: an import of the module and the attributes after
it (the "Modules that moved" tables name the old, removed paths and are skipped)."""

import importlib
import pkgutil
import re
from pathlib import Path

import pytest

import pinarms

ROOT = Path(__file__).resolve().parents[1]
DOCS = sorted((ROOT / "docs").glob("*.md")) + [ROOT / "README.md"]
PACKAGES = sorted({m.name for m in pkgutil.iter_modules(pinarms.__path__)} | {"robots", "planning", "optim", "viz", "urdf"})
#: a dotted name that starts at a pinarms package, not inside a path or a longer name
NAME = re.compile(r"(?<![\w./-])(?:pinarms\.)?((?:%s)(?:\.[A-Za-z_]\w*)+)" % "|".join(PACKAGES))
#: file suffixes: ``files.md``, ``line.pinarms`` are files, not names
SUFFIXES = {"md", "py", "png", "svg", "yaml", "yml", "json", "npz", "npy", "csv", "html", "urdf", "srdf", "xml",
            "xacro", "stl", "dae", "obj", "txt", "toml", "pinarms", "gz", "zip", "log", "sh", "cfg"}


def _code(text: str) -> list[str]:
    """Fenced blocks and inline code spans of a Markdown text, without the sections on moved modules."""
    text = re.sub(r"^(#+) [^\n]*moved[^\n]*\n.*?(?=^#{1,3} |\Z)", "", text, flags=re.S | re.M | re.I)
    blocks = re.findall(r"```[^\n]*\n(.*?)```", text, re.S)
    rest = re.sub(r"```.*?```", "", text, flags=re.S)
    return blocks + re.findall(r"`([^`\n]+)`", rest)


def _resolve(name: str) -> object:
    parts = name.split(".")
    for k in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module("pinarms." + ".".join(parts[:k]))
        except ModuleNotFoundError:
            continue
        for p in parts[k:]:
            obj = getattr(obj, p)
        return obj
    raise ModuleNotFoundError(name)


#: ``from pinarms.x import a, b`` (parenthesised over lines too): each name imported
IMPORT = re.compile(r"^\s*from pinarms\.([\w.]+) import (\([^)]*\)|[^\n]+)", re.M)


def _names(path: Path) -> list[str]:
    found = []
    for part in _code(path.read_text(encoding="utf-8")):
        found += [m.group(1) for m in NAME.finditer(part) if m.group(1).rsplit(".", 1)[-1] not in SUFFIXES]
        for m in IMPORT.finditer(part):
            imported = re.split(r"[\s,()]+", re.sub(r"\bas\s+\w+", "", m.group(2).split("#")[0]))
            found += [f"{m.group(1)}.{n}" for n in imported if n.isidentifier()]
    return sorted(set(found))


@pytest.mark.parametrize("path", DOCS, ids=lambda p: p.name)
def test_every_name_in_the_docs_code_resolves(path):
    missing = []
    for name in _names(path):
        try:
            _resolve(name)
        except (ImportError, AttributeError) as exc:
            missing.append(f"{name} ({type(exc).__name__}: {exc})")
    assert not missing, f"{path.name} names what does not exist: " + "; ".join(missing)


def test_the_check_sees_the_names():
    """The scan finds names (so the test above can fail): line.md names the line's API."""
    names = _names(ROOT / "docs" / "line.md")
    assert "optim.line.line_curve" in names and len(names) > 5
    assert "optim.line.Stream" in names  # from its code block's import line
    with pytest.raises(AttributeError):
        _resolve("viz.line_session.no_such_function")
