"""The README's quickstart runs as written."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

README = Path(__file__).resolve().parents[2] / "README.md"


def _python_blocks() -> list[str]:
    return re.findall(r"```python\n(.*?)```", README.read_text(encoding="utf-8"), flags=re.DOTALL)


def test_readme_has_the_two_commands_and_a_quickstart():
    text = README.read_text(encoding="utf-8")
    assert "make demo" in text and "make test" in text
    assert len(_python_blocks()) == 1
    assert text.count("| 00") >= 40  # the paper-vs-pinarms table


@pytest.mark.slow
def test_readme_quickstart_runs(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code = _python_blocks()[0]
    exec(compile(code, str(README), "exec"), {"__name__": "readme"})
    assert (tmp_path / "study.pinarms").is_file()
    assert (tmp_path / "study.html").stat().st_size > 100_000
