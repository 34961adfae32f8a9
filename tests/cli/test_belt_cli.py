"""`pinarms belt ...`: a line simulated from the command line; bad input is one error line."""

import json

from click.testing import CliRunner

from pinarms.cli import cli


def test_belt_run_json_figures():
    r = CliRunner().invoke(cli, ["belt", "run", "--arms", "2", "--rate", "20", "--seeds", "2", "--duration", "120",
                                 "--json"])
    assert r.exit_code == 0, (r.output, r.exception)
    data = json.loads(r.stdout)
    f = data["figures"]
    assert data["status"] in ("ok", "misses above target") and data["belt_speed_m_s"] == 0.2
    assert len(f["arms"]) == 2 and 0.0 <= f["miss_rate"] <= 1.0
    assert 0.0 < f["picks_per_minute"] <= f["arrivals_per_minute"]
    assert f["miss_rate_ci"][0] <= f["miss_rate"] <= f["miss_rate_ci"][1]


def test_belt_run_arrivals_file_and_errors(tmp_path):
    p = tmp_path / "arrivals.csv"
    p.write_text("time,across,type\n0.5,0.0,enoki bunch\n1.0,x,enoki bunch\n")
    r = CliRunner().invoke(cli, ["belt", "run", "--arms", "1", "--arrivals", str(p)])
    assert r.exit_code == 1 and "row 2" in r.output and "'across'" in r.output and "Traceback" not in r.output
    p.write_text("time,across,type\n0.5,0.0,enoki bunch\n4.0,0.05,enoki bunch\n")
    r = CliRunner().invoke(cli, ["belt", "run", "--arms", "1", "--arrivals", str(p), "--duration", "30", "--json"])
    assert r.exit_code == 0, r.output
    assert json.loads(r.stdout)["figures"]["picks_per_minute"] == 4.0  # both picked in 30 s
    r = CliRunner().invoke(cli, ["belt", "run", "--speed", "0"])
    assert r.exit_code == 1 and "belt speed" in r.output


def test_belt_run_trays_bad_input():
    for text, words in (("0.4,0,2", "speed"), ("0.4,0.1,0", "capacity"), ("0.4,0.1", "PITCH,SPEED,SLOTS"),
                        ("0.4,fast,2", "speed [m/s]"), ("0,0.1,2", "pitch")):
        r = CliRunner().invoke(cli, ["belt", "run", "--arms", "1", "--trays", text])
        assert r.exit_code == 1 and words in r.output and "Traceback" not in r.output, (text, r.output)


def test_belt_counts_and_rates_are_capped_before_any_work():
    """`--arms 1000000`, `--seeds 1000000` and `--rate 1e8` (7.45 GiB asked for) once ran away;
    each is one error line naming the flag, at once."""
    import time

    for args, flag in ((["--arms", "1000000"], "--arms"), (["--seeds", "1000000"], "--seeds"),
                       (["--rate", "1e8"], "--rate"), (["--arms", "0"], "--arms"), (["--seeds", "0"], "--seeds")):
        t0 = time.perf_counter()
        r = CliRunner().invoke(cli, ["belt", "run", *args])
        assert time.perf_counter() - t0 < 5.0
        assert r.exit_code == 1 and r.output.startswith("Error: ") and r.output.count("\n") == 1, r.output
        assert flag in r.output and "Traceback" not in r.output
    r = CliRunner().invoke(cli, ["belt", "arms", "--max-arms", "1000000"])
    assert r.exit_code == 1 and "--max-arms" in r.output


def test_belt_run_prints_the_results_summary():
    """The CLI prints LineResult.summary(): the Python figures and the printed ones cannot drift."""
    from pinarms.optim.line import run_line
    from pinarms.studies.line import maps_for, scara_line

    args = ["belt", "run", "--arms", "2", "--rate", "20", "--seeds", "1", "--duration", "60"]
    r = CliRunner().invoke(cli, args)
    assert r.exit_code == 0, (r.output, r.exception)
    spec = scara_line(2, 20.0, seeds=(0,), duration=60.0)
    res = run_line(spec, maps=maps_for(spec))
    text = res.summary("belt run: scara, 2 arm(s), rule first")
    assert r.stdout.strip() == text
    f = res.figures
    for part in (f"picks             {f.picks_per_minute:.1f} /min", f"miss rate         {100 * f.miss_rate:.2f} %",
                 f"{f.arms[0]}: {100 * f.utilisation[0]:.0f} %", f"{f.arms[1]}: {100 * f.utilisation[1]:.0f} %",
                 "belt speed        0.200 m/s", "status"):
        assert part in text, (part, text)


def test_belt_arms_with_a_shipped_delta():
    """`--robot delta_flexpicker`: deltas above the belt; at 60 bunches/min one misses, two do not."""
    r = CliRunner().invoke(cli, ["belt", "arms", "--robot", "delta_flexpicker", "--rate", "60", "--seeds", "2",
                                 "--duration", "120", "--map-grid", "5,3", "--max-arms", "3", "--json"])
    assert r.exit_code == 0, (r.output, r.exception)
    data = json.loads(r.stdout)
    assert data["arms_needed"] == 2 and data["belt_speed_m_s"] == 0.2
    assert data["figures"]["arms"] == ["delta 1", "delta 2"]
    assert data["figures"]["miss_rate"] <= 0.01


def test_belt_delta_bad_flags_are_one_error_line():
    for extra, flag in ((["--tcp", "tool"], "--tcp"), (["--paper-limit"], "--paper-limit")):
        r = CliRunner().invoke(cli, ["belt", "run", "--robot", "delta_flexpicker", "--arms", "1", *extra])
        assert r.exit_code == 1 and flag in r.output and "Traceback" not in r.output, r.output
        assert r.output.startswith("Error:") and len(r.output.strip().splitlines()) == 1, r.output
