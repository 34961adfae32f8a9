"""No merge leaves its conflict markers in a file of the repository (code, docs, models, cells)."""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
#: what a text file of the project may be (the rest is data or built)
SUFFIXES = {".py", ".md", ".toml", ".xacro", ".urdf", ".srdf", ".xml", ".yaml", ".yml", ".cfg", ".txt", ".json", ".sh"}
SKIP = {".git", ".venv", "demo-output", "build", "dist", ".hypothesis", "__pycache__", ".pytest_cache"}
MARKER = re.compile(r"^(<{7} |={7}$|>{7} )", re.MULTILINE)


def _text_files():
    for path in ROOT.rglob("*"):
        rel = path.relative_to(ROOT)
        if any(part in SKIP or part.endswith(".egg-info") for part in rel.parts):
            continue
        if path.is_file() and path.suffix in SUFFIXES:
            yield path


def test_no_file_holds_merge_conflict_markers():
    found = [f"{p.relative_to(ROOT)}:{p.read_text(encoding='utf-8', errors='replace')[:m.start()].count(chr(10)) + 1}"
             for p in _text_files() for m in MARKER.finditer(p.read_text(encoding="utf-8", errors="replace"))]
    assert not found, f"merge conflict markers left in: {', '.join(found)}"


def test_the_check_sees_a_marker(tmp_path):
    text = "a\n<<<<<<< HEAD\nb\n=======\nc\n>>>>>>> main\n"
    assert len(MARKER.findall(text)) == 3
    assert not MARKER.findall("a ======= b\n<<<<<<<x\n")
