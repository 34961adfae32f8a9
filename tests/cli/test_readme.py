"""The README: its two commands, its one quickstart, its paper-vs-pinarms table as the code prints it.

That the quickstart runs as written (and writes study.pinarms and study.html) is checked once, from the
installed wheel outside the repository: tests/test_packaging.py::test_wheel_beside_pypi_namesakes_runs_the_quickstart.
"""

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


def _cells(line: str) -> list[str]:
    return [c.strip() for c in re.split(r"(?<!\\)\|", line)[1:-1]]


@pytest.mark.slow
@pytest.mark.xdist_group("demo-studies")  # shares the quick studies (tests/conftest.py)
def test_readme_table_is_the_code_s_table(quick_study):
    """Every README row that does not depend on the run's budget (GA generations, samples) is
    exactly what the demo's studies print now; the summary line counts the README's rows."""
    from pinarms.report import TABLE_BEGIN, TABLE_END, markdown_table

    text = README.read_text(encoding="utf-8")
    block = text[text.index(TABLE_BEGIN) : text.index(TABLE_END)]
    lines = [line for line in block.splitlines() if line.startswith(("| 00", "| delta "))]
    budget = ("GA", "reduced by", "workspace sphere", "recommended")
    checked = 0
    # (the delta study's rows depend on its grid, coarser in quick mode: tests/robots/delta check its figures)
    for study in (quick_study("000"), quick_study("001"), quick_study("004")):
        for row in study.rows:
            if any(word in row.quantity for word in budget):
                continue
            expected = markdown_table([row]).splitlines()[2]
            assert expected in lines, f"README row out of date; run `make readme-table`:\n{expected}"
            checked += 1
    assert checked >= 40
    statuses = [_cells(line)[6] for line in lines]
    summary = (f"{len(lines)} rows: {statuses.count('agrees')} agree, {statuses.count('differs')} differ "
               f"(reason given), {statuses.count('n/a')} not comparable.")
    assert summary in block
    assert {_cells(line)[0] for line in lines} == {"000", "001", "002", "004", "delta"}


def test_splice_table_replaces_only_the_marked_block():
    from pinarms.report import TABLE_BEGIN, TABLE_END, Row, splice_table
    from pinarms.errors import InvalidInput

    doc = f"intro\n{TABLE_BEGIN}\nold table\n{TABLE_END}\noutro\n"
    rows = [Row("004", "x", 1.0, 1.0, "mm", 0.1), Row("004", "y", 1.0, 2.0, "mm", 0.1, "typo")]
    new = splice_table(doc, rows)
    assert "old table" not in new and new.startswith("intro\n") and new.endswith(f"{TABLE_END}\noutro\n")
    assert "| 004 | y | 1 | 2 | mm | 0.1 | differs | typo |" in new
    assert "2 rows: 1 agree, 1 differ (reason given), 0 not comparable." in new
    assert splice_table(new, rows) == new
    with pytest.raises(InvalidInput, match="markers|once each"):
        splice_table("no markers here", rows)
    with pytest.raises(InvalidInput):
        splice_table(f"{TABLE_END}\n{TABLE_BEGIN}\n", rows)


def test_demo_readme_option_checks_before_the_long_run(tmp_path):
    from click.testing import CliRunner

    from pinarms.cli import cli

    plain = tmp_path / "plain.md"
    plain.write_text("no markers\n")
    result = CliRunner().invoke(cli, ["demo", "--out", str(tmp_path / "out"), "--readme", str(plain)])
    assert result.exit_code == 1 and "once each" in result.stderr
    assert not (tmp_path / "out").exists()  # refused before any study ran
    result = CliRunner().invoke(cli, ["demo", "--quick", "--readme", str(plain)])
    assert result.exit_code == 2 and "--readme" in result.stderr


def test_readme_cell_example_loads(tmp_path):
    """'Your own cell': the xacro as written loads as a cell with one arm and its fixtures, collision-free."""
    from pinarms import robots

    text = README.read_text(encoding="utf-8")
    block = text[text.index('<robot name="my_line"') : text.index("</robot>", text.index('<robot name="my_line"')) + 8]
    path = tmp_path / "my_line.urdf.xacro"
    path.write_text(block, encoding="utf-8")
    cell = robots.load_cell(path)
    assert [a.name for a in cell.arms] == ["left"] and cell.arm("left").robot.nq == 4
    assert {"belt", "box", "box_wall_xpos"} <= {f.name for f in cell.fixtures}
    assert not cell.in_collision(cell.neutral)
