"""`pinarms demo --quick`: the table rows, the files, and the paper numbers that must agree.

The demo's quick studies 000, 001 and 004 come from the session's ``quick_study`` (tests/conftest.py), which
builds each once for every file that checks them: ``shared_studies`` hands them to ``run_demo`` (the same
``study_<key>(quick=True)`` call the demo makes), so that ``pinarms demo --quick`` builds only the others here.
"""

from __future__ import annotations

import dataclasses
import json

import pytest
from click.testing import CliRunner

from pinarms.cli import cli

SHARED = ("000", "001", "004")


@pytest.fixture
def shared_studies(monkeypatch, quick_study):
    """``run_demo`` takes studies 000, 001 and 004 from ``quick_study`` (each a copy: it sets their seconds)."""
    from pinarms import demo

    calls = []
    for key in SHARED:
        assert demo.STUDIES[key] is getattr(demo, f"study_{key}"), f"the demo no longer runs study_{key}"

        def shared(quick: bool, key: str = key):
            assert quick is True, "the demo tests run --quick"
            calls.append(key)
            return dataclasses.replace(quick_study(key))

        monkeypatch.setitem(demo.STUDIES, key, shared)
    return calls


@pytest.mark.slow
@pytest.mark.xdist_group("demo-studies")  # shares the quick studies (tests/conftest.py)
def test_demo_quick_writes_table_sessions_html_and_plots(tmp_path, shared_studies):
    out = tmp_path / "demo"
    result = CliRunner().invoke(cli, ["demo", "--quick", "--out", str(out), "--json"])
    assert result.exit_code == 0, (result.output, result.exception)
    data = json.loads(result.stdout)
    rows = data["rows"]
    assert {r["study"] for r in rows} == {"000", "001", "002", "004", "delta"}
    # the delta's standard pick cycle beside the datasheet it is compared with (not a paper: "n/a" or "differs")
    assert sum(r["study"] == "delta" for r in rows) >= 3
    for r in rows:
        assert r["status"] in ("agrees", "differs", "n/a")
        if r["status"] == "differs":
            assert r["note"], f"row {r['quantity']!r} differs without a reason"
    by = {(r["study"], r["quantity"]): r for r in rows}
    # numbers the papers and pinarms must share
    table3 = [r for r in rows if r["quantity"].startswith("Table 3 J1-J3")]
    assert len(table3) == 21 and all(r["status"] == "agrees" for r in table3)
    assert by[("004", "FK example 3 x")]["status"] == "agrees"  # the paper's third: (-90, 25, -30, 90) deg
    assert by[("004", "FK example 3 z")]["status"] == "agrees"
    assert by[("000", "initial total time")]["status"] == "agrees"
    assert by[("002", "jerk jump at interior knots / jerk limit")]["status"] == "agrees"
    assert by[("000", "GA peak |v| joint 1")]["pinarms"] <= 55.0 * (1 + 1e-6)
    # files
    for key in ("000", "001", "002", "004"):
        assert (out / "sessions" / f"seed{key}.pinarms").is_file()
        assert (out / "html" / f"seed{key}.html").stat().st_size > 100_000
        assert (out / "plots" / f"seed{key}_joints.png").is_file()
    assert (out / "plots" / "seed001_workspace.png").is_file()
    # the cell study: two SCARAs on one belt (rows filed under seed 000), the AUBO station (001)
    assert (out / "sessions" / "cell.pinarms").is_file() and (out / "plots" / "cell_schedule.png").is_file()
    line = by[("000", "mushroom_line, two SCARAs on one belt: line rate (every time offset checked continuously)")]
    alone = by[("000", "mushroom_line: one SCARA alone (its own cycle)")]
    assert line["pinarms"] > 1.8 * alone["pinarms"]
    assert by[("000", "mushroom_line: closest approach of the two arms over a period")]["pinarms"] > 0.0
    md = (out / "table.md").read_text()
    assert md.count("\n| ") == len(rows) + 1
    assert json.loads((out / "table.json").read_text()) == rows
    from pinarms import viz

    session = viz.load_session(out / "sessions" / "seed001.pinarms")
    assert session.trajectories and session.workspaces
    assert shared_studies == list(SHARED)


@pytest.mark.xdist_group("demo-studies")  # shares the quick studies (tests/conftest.py)
def test_demo_text_table_only_one_study(tmp_path, shared_studies):
    result = CliRunner().invoke(cli, ["demo", "--quick", "--only", "004", "--out", str(tmp_path)])
    assert result.exit_code == 0, (result.output, result.exception)
    assert "paper vs pinarms" in result.stdout
    assert "FK example 1 z" in result.stdout and "differs" in result.stdout
    assert (tmp_path / "table.md").is_file()
    # a pipe or a file gets one line per row; a terminal of 100 columns gets the table wrapped to it,
    # with a bar per study on stderr; table.md keeps every row on one line
    long_note = max(result.stdout.splitlines(), key=len)
    assert len(long_note) > 100
    narrow = CliRunner().invoke(cli, ["demo", "--quick", "--only", "004", "--out", str(tmp_path)], env={"COLUMNS": "100"})
    table = narrow.stdout.split("\n\nwrote ")[0]
    assert max(len(line) for line in table.splitlines()) <= 100
    assert sorted(table.replace(" ", "").replace("-", "").replace("\n", "")) == sorted(
        result.stdout.split("\n\nwrote ")[0].replace(" ", "").replace("-", "").replace("\n", ""))
    assert any(len(line) > 100 for line in (tmp_path / "table.md").read_text(encoding="utf-8").splitlines())
    assert shared_studies == ["004", "004"]


@pytest.mark.xdist_group("demo-studies")  # shares the quick studies (tests/conftest.py)
def test_demo_ik_rows_use_the_error_the_paper_states(quick_study):
    # seed 004 section 3: "the one-decimal position causes 0.1° of error in θ" (not a tolerance fitted to ours)
    from pinarms.papers import SEED004

    rows = [r for r in quick_study("004").rows if r.quantity.startswith("IK of")]
    assert len(rows) == 3
    for row, paper in zip(rows, (SEED004.ik_theta1_deg, SEED004.ik_theta2_deg, -SEED004.ik_theta3_down_deg)):
        assert row.paper == paper and row.tolerance == SEED004.ik_stated_error_deg == 0.1
        assert row.status == "agrees"
    # ours solve the printed target: θ2 within 0.002° of 25°, i.e. 0.026° from the paper's 25.0271°
    assert rows[1].pinarms == pytest.approx(25.0011, abs=1e-4)


@pytest.mark.xdist_group("demo-studies")  # shares the quick studies (tests/conftest.py)
def test_demo_joint_plots_in_degrees_for_seed000_only(tmp_path, monkeypatch, quick_study):
    # seed 000's paper draws joint 1 in degrees; the other studies keep SI (rad, m)
    from pinarms.viz import plots as vplots

    seen = {}
    real = vplots.plot_trajectory

    def spy(path, trajectory, **options):
        seen[path.name] = options.get("degrees", False)
        return real(path, trajectory, **options)

    monkeypatch.setattr(vplots, "plot_trajectory", spy)
    for key, study in (("000", quick_study("000")), ("004", quick_study("004"))):
        study.plots["joints"](tmp_path / f"seed{key}_joints.png")
    assert seen == {"seed000_joints.png": True, "seed004_joints.png": False}
    assert (tmp_path / "seed000_joints.png").stat().st_size > 10_000
