"""`pinarms layout-search`: ranked placements, JSON, plot, session, the Dask scheduler option."""

from __future__ import annotations

import json

import numpy as np
from click.testing import CliRunner

from pinarms import optim, robots, viz
from pinarms.cli import cli

SCARA = ["layout-search", "scara_mushroom", "--pick", "426", "96", "140", "--place", "228", "372", "140", "--mm",
         "--lift", "20", "--x", "-100:100:100", "--y", "0:100:100"]


def test_layout_search_json_plot_and_session(tmp_path):
    plot, session = tmp_path / "map.png", tmp_path / "best.pinarms"
    result = CliRunner().invoke(cli, [*SCARA, "--refine", "0", "--json", "--plot", str(plot), "--session", str(session)])
    assert result.exit_code == 0, (result.output, result.exception)
    data = json.loads(result.stdout)
    api = optim.search_layout(optim.LayoutRequest(robots.load("scara_mushroom"), [0.426, 0.096, 0.14], [0.228, 0.372, 0.14],
                              optim.grid_candidates(x=(-0.1, 0.1, 0.1), y=(0.0, 0.1, 0.1)), lift=0.02, refine=0))
    assert data["failures"] == api.failures() == {"unreachable": 2}
    assert [c["index"] for c in data["candidates"]] == api.order.tolist()
    best = data["candidates"][0]
    assert best["picks_per_minute"] == api.picks_per_minute[api.order[0]]
    assert data["best"]["placement"]["x_m"] == api.best_placement[0]
    assert data["ran_on"] == "serial (this process)"
    assert plot.stat().st_size > 10_000 and plot.read_bytes()[:4] == b"\x89PNG"
    s = viz.load_session(session)
    entry = next(iter(s.robots.values()))
    assert np.allclose(entry.base_to_world[:3, 3], api.best_placement[:3])
    assert "best_cycle" in s.trajectories and s.workspaces["candidates_picks_per_minute"].points.shape == (6, 3)


def test_layout_search_text_names_failures_and_refinement():
    result = CliRunner().invoke(cli, [*SCARA, "--refine", "1", "--refine-evaluations", "4"])
    assert result.exit_code == 0, (result.output, result.exception)
    out = result.stdout
    assert "6 placements, 4 planned, 2 unreachable" in out
    assert "unreachable: pick 1 (0.426, 0.096, 0.140) m: beyond the arm's reach" in out
    assert "refined over x, y from the best 1" in out and "best placement: base at" in out


def test_scheduler_from_the_standard_variable(monkeypatch):
    # DASK_SCHEDULER_ADDRESS is honoured when --scheduler is absent; nothing listens on port 9
    monkeypatch.setenv("DASK_SCHEDULER_ADDRESS", "tcp://127.0.0.1:9")
    monkeypatch.setenv("DASK_DISTRIBUTED__COMM__TIMEOUTS__CONNECT", "1s")
    import dask

    dask.config.refresh()
    try:
        result = CliRunner().invoke(cli, [*SCARA, "--refine", "0"])
    finally:
        monkeypatch.delenv("DASK_DISTRIBUTED__COMM__TIMEOUTS__CONNECT")
        dask.config.refresh()
    assert result.exit_code == 1
    assert "cannot reach the Dask scheduler at tcp://127.0.0.1:9" in result.output
    assert "dask scheduler" in result.output


def test_bad_ranges_are_usage_errors():
    result = CliRunner().invoke(cli, [*SCARA[:-4], "--x", "0:1", "--y", "0"])
    assert result.exit_code == 2 and "LO:HI:STEP" in result.output


def test_workspace_stream_option(tmp_path):
    from pinarms.robots.reach.workspace_stream import StreamGrid, stream_workspace

    out = tmp_path / "voxels.pinarms"
    result = CliRunner().invoke(cli, ["workspace", "aubo_i3", "-n", "60000", "--stream", "--voxel", "50",
                                      "--json", "--session", str(out)])
    assert result.exit_code == 0, (result.output, result.exception)
    data = json.loads(result.stdout)
    api = stream_workspace(robots.load("aubo_i3"), 60_000, seed=0, grid=StreamGrid(0.05))
    assert data["streamed"] and data["tasks"] == 1 and data["ran_on"] == "serial (this process)"
    assert data["summary"]["bbox_max"] == api.summary.bbox_max.tolist()
    assert data["voxels"]["reachable"] == int(api.voxels.reachable.sum())
    cloud = viz.load_session(out).workspaces["workspace_voxels"]
    assert cloud.points.shape == (int(api.voxels.reachable.sum()), 3)


def test_layout_search_bound_keeps_the_best_placement():
    args = ["layout-search", "scara_mushroom", "--pick", "-200", "0", "140", "--place", "200", "0", "140", "--mm",
            "--lift", "20", "--dwell", "0.05", "--x", "0:0:1", "--y", "50:400:50", "--yaw", "-90:-90:1", "--deg",
            "--refine", "0", "--json"]
    full = CliRunner().invoke(cli, args)
    bounded = CliRunner().invoke(cli, [*args, "--bound"])
    assert full.exit_code == 0 and bounded.exit_code == 0, (full.output, bounded.output)
    a, b = json.loads(full.stdout), json.loads(bounded.stdout)
    assert b["failures"].get("outranked", 0) >= 1 and "outranked" not in a["failures"]
    assert b["best"] == a["best"]
