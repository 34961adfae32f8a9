"""Every command-line fault is one ``Error:`` line on stderr, exit status 1, no traceback, no Dask logging.

Settings past their caps are refused before any work; a cell file that is not UTF-8, a
malformed ``--scheduler`` address, an address where nothing listens and a Dask scheduler
lost in the middle of a run each get a message that fits the fault.
"""

from __future__ import annotations

import os
import socket
import subprocess
import sys
import time

import click
import pytest
from click.testing import CliRunner

from pinarms.cli import cli
from pinarms.cli._common import DEBUG_VARIABLE, PinarmsGroup

TASKS = ["--task", "left", "-50", "-30", "840", "220", "680", "840", "--task", "right", "50", "30", "840", "220",
         "-680", "840", "--mm"]


def one_error_line(result_or_text, *fragments: str, exit_code: int = 1) -> str:
    if isinstance(result_or_text, str):
        text = result_or_text
    else:
        assert result_or_text.exit_code == exit_code, (result_or_text.output, result_or_text.exception)
        text = result_or_text.stderr
    lines = [line for line in text.splitlines() if line.strip()]
    assert len(lines) == 1, f"{len(lines)} lines on stderr:\n{text}"
    assert lines[0].startswith("Error: "), lines[0]
    assert "Traceback" not in text
    for f in fragments:
        assert f in lines[0], f"{f!r} not in {lines[0]!r}"
    return lines[0]


@pytest.fixture
def run():
    runner = CliRunner()
    return lambda *args: runner.invoke(cli, list(args))


def test_a_billion_offsets_is_refused_at_once_naming_the_cap(run):
    t0 = time.perf_counter()
    result = run("cell", "cycle", "mushroom_line", *TASKS, "--offsets", "1000000000")
    assert time.perf_counter() - t0 < 5.0  # before the cell loads or a cycle is planned
    one_error_line(result, "--offsets", "1,000,000,000", "2 to 1,000")


@pytest.mark.parametrize("option, value, word", [("--dwell", "nan", "--dwell"), ("--dwell", "-1", "--dwell"),
                                                 ("--margin", "0", "--margin"), ("--clearance", "inf", "--clearance"),
                                                 ("--lift", "0", "--lift")])
def test_cell_cycle_settings_are_checked_first(run, option, value, word):
    one_error_line(run("cell", "cycle", "mushroom_line", *TASKS, option, value), word)


def test_a_cell_file_that_is_not_utf8_is_one_line(run, tmp_path):
    path = tmp_path / "latin1_cell.urdf"
    path.write_bytes('<?xml version="1.0"?>\n<robot name="caf\xe9">\n</robot>\n'.encode("latin-1"))
    one_error_line(run("cell", "show", str(path)), "not UTF-8", "latin1_cell.urdf")


@pytest.mark.parametrize("address", ["tcp://nohost:abc", "tcp://", "foo://host:8786", "tcp://host:0",
                                     "tcp://host:70000", "processes:-1", "processes:x", "nonsense"])
def test_a_malformed_scheduler_address_is_one_line(run, address):
    t0 = time.perf_counter()
    result = run("workspace", "ur5", "--stream", "-n", "1000", "--scheduler", address)
    assert time.perf_counter() - t0 < 5.0
    one_error_line(result, repr(address))


def test_reach_checks_its_scheduler_address_too(run):
    one_error_line(run("reach", "scara_mushroom", "--scheduler", "tcp://host:port"), "tcp://host:port")


def test_a_line_tolerance_below_a_nanometre_is_refused_at_once(run):
    t0 = time.perf_counter()
    result = run("line", "aubo_i3", "--from", "350", "200", "0", "--to", "350", "200", "300", "--mm",
                 "--tolerance", "1e-300")
    assert time.perf_counter() - t0 < 5.0
    one_error_line(result, "tolerance", "1e-09 m (1 nm)")


def test_a_voxel_too_fine_for_memory_is_refused_before_the_sweep(run):
    # 1e-9 mm voxels once reached a chunk and came back as numpy's "array is too big"
    one_error_line(run("workspace", "ur5", "--stream", "--voxel", "1e-9", "-n", "1000"), "voxel_size", "1e+08")


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_an_address_where_nothing_listens_is_one_line(run):
    import dask
    import distributed  # noqa: F401  (its defaults in dask's config before the override, which removes what it added)

    with dask.config.set({"distributed.comm.timeouts.connect": "1s"}):
        result = run("workspace", "ur5", "--stream", "-n", "1000", "--scheduler", f"tcp://127.0.0.1:{_free_port()}")
    one_error_line(result, "cannot reach the Dask scheduler")


@pytest.mark.slow
def test_a_scheduler_lost_mid_run_is_one_line_that_says_so(tmp_path):
    from distributed import LocalCluster

    cluster = LocalCluster(n_workers=1, threads_per_worker=1, processes=True, host="127.0.0.1",
                           dashboard_address=None)
    env = dict(os.environ, DASK_DISTRIBUTED__COMM__TIMEOUTS__CONNECT="3s")
    env.pop("DASK_LOGGING__DISTRIBUTED", None)
    proc = subprocess.Popen([sys.executable, "-m", "pinarms.cli", "workspace", "ur5", "--stream", "-n", "100000000",
                             "--scheduler", cluster.scheduler_address], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env=env, cwd=tmp_path)
    try:
        deadline = time.monotonic() + 120
        while not cluster.scheduler.tasks and time.monotonic() < deadline and proc.poll() is None:
            time.sleep(0.2)
        assert cluster.scheduler.tasks, "the command never sent its tasks"
        time.sleep(0.5)
        cluster.close()
        _, err = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
        cluster.close()
    assert proc.returncode == 1
    line = one_error_line(err, "lost the connection to the Dask scheduler", "nothing was returned")
    assert "re-run" not in line


def test_an_unexpected_exception_is_one_line_and_the_traceback_is_on_request(monkeypatch):
    @click.group(cls=PinarmsGroup)
    def group() -> None:
        pass

    @group.command("divide")
    def divide() -> None:
        print(1 / 0)

    monkeypatch.delenv(DEBUG_VARIABLE, raising=False)
    one_error_line(CliRunner().invoke(group, ["divide"]), "unexpected ZeroDivisionError", DEBUG_VARIABLE)
    monkeypatch.setenv(DEBUG_VARIABLE, "1")
    result = CliRunner().invoke(group, ["divide"])
    assert isinstance(result.exception, ZeroDivisionError)


def _pinarms(*args: str, cwd=None) -> subprocess.CompletedProcess:
    """The installed command in a child process (pytest's own warning capture does not hide anything there)."""
    env = {k: v for k, v in os.environ.items() if k not in (DEBUG_VARIABLE, "PYTHONWARNINGS")}
    return subprocess.run([sys.executable, "-m", "pinarms.cli", *args], capture_output=True, text=True, timeout=120,
                          cwd=cwd, env=env)


def test_numpy_warnings_do_not_precede_the_error_line():
    result = _pinarms("plan", "--kind", "multi-quintic", "--times", "0,1e-320", "--via", "0", "--via", "1")
    assert result.returncode == 1
    one_error_line(result.stderr, "finite")


def test_a_cell_file_named_with_a_leading_dash_loads_after_double_dash_or_by_path(tmp_path):
    source = (os.path.dirname(__file__) + "/../robots/data/user_scara.urdf")
    (tmp_path / "user_scara.urdf").write_text(open(source, encoding="utf-8").read(), encoding="utf-8")
    (tmp_path / "--c.toml").write_text('name = "c"\n[[arm]]\nname = "left"\nurdf = "user_scara.urdf"\n'
                                       'xyz = [0.0, 0.0, 0.0]\nrpy = [0.0, 0.0, 0.0]\n')
    runner = CliRunner()
    with runner.isolated_filesystem(temp_dir=tmp_path) as here:
        os.replace(tmp_path / "--c.toml", os.path.join(here, "--c.toml"))
        os.replace(tmp_path / "user_scara.urdf", os.path.join(here, "user_scara.urdf"))
        for args in (["cell", "show", "--", "--c.toml"], ["cell", "show", "./--c.toml"]):
            result = runner.invoke(cli, args)
            assert result.exit_code == 0, (args, result.output)
            assert "left: arm" in result.output
        result = runner.invoke(cli, ["cell", "show", "--c.toml"])
        assert result.exit_code == 2
        assert "./--c.toml" in result.stderr and "put -- before it" in result.stderr


def test_a_library_error_names_the_flag_not_the_python_parameter():
    """The library says ``time_limit must be ...``; on the command line that is ``--time-limit``."""
    from click.testing import CliRunner

    from pinarms.cli import cli

    result = CliRunner().invoke(cli, ["motion", "aubo_crate_guard", "--from", "0.41", "0.10", "0.79", "--to", "0",
                                      "-0.465", "0.78", "--time-limit", "-1"])
    assert result.exit_code == 1 and result.stderr.startswith("Error: --time-limit must be a positive number")
    assert result.stderr.count("\n") == 1


def test_name_the_flag_replaces_only_a_leading_option_name():
    import click

    from pinarms.cli._common import name_the_flag

    params = [click.Option(["--time-limit", "-t"]), click.Option(["--amax"]), click.Argument(["cell"])]
    assert name_the_flag("time_limit must be positive", params) == "--time-limit must be positive"
    assert name_the_flag("cell must exist", params) == "cell must exist"  # an argument has no flag
    assert name_the_flag("the amax is too large", params) == "the amax is too large"
