"""The line study's lines: maps shipped with the package, one run through the API."""

import pytest

from pinarms.optim.line import run_line
from pinarms.studies.line import gantry_line, maps_for, scara_line


def test_package_maps_match_the_study_lines():
    for spec in (scara_line(1, 60.0), scara_line(1, 60.0, paper_limit=True), gantry_line(60.0)):
        maps = maps_for(spec, build=False)  # raises if the package's map for this line is missing
        m = next(iter(maps.values()))[0]
        assert m.speed == spec.belt.speed and m.mass == spec.stream.types[0].mass


def test_scara_line_through_the_api():
    spec = scara_line(2, 20.0, seeds=(0, 1), duration=300.0)
    res = run_line(spec, maps=maps_for(spec, build=False))
    f = res.figures
    assert res.status in ("ok", "misses above target") and len(res.windows) == 2 and res.overlapping == ()
    assert 0.0 <= f.miss_rate <= f.miss_rate_ci[1] <= 1.0 and 0.0 < f.picks_per_minute <= f.arrivals_per_minute
    paper = run_line(scara_line(2, 20.0, seeds=(0, 1), duration=300.0, paper_limit=True),
                     maps=maps_for(scara_line(2, 20.0, paper_limit=True), build=False))
    assert paper.figures.picks_per_minute < f.picks_per_minute  # 55 deg/s on joint 1 is slower
    assert res.as_dict()["figures"]["utilisation"] == pytest.approx(list(f.utilisation))


def test_line_status_is_an_enum_with_a_reason_and_keeps_its_word():
    import dataclasses
    import json

    from pinarms.optim.line import LineStatus

    spec = scara_line(1, 60.0, seeds=(0,), duration=120.0)  # one arm cannot take 60 items/min
    res = run_line(spec, maps=maps_for(spec, build=False))
    assert res.status is LineStatus.MISSES_ABOVE_TARGET and res.figures.miss_rate > spec.target_miss_rate
    assert "above the target 1.00 %" in res.status_reason and "add an arm" in res.status_reason
    assert json.loads(json.dumps(res.as_dict()))["status"] == "misses above target"
    assert "  status            misses above target" in res.summary().splitlines()
    easy = run_line(dataclasses.replace(spec, target_miss_rate=0.99), maps=maps_for(spec, build=False))
    assert easy.status is LineStatus.OK and easy.status_reason == ""
