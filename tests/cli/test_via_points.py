"""Via points of the trajectory commands: CSV and JSON files, options, and the errors that name the spot."""

from __future__ import annotations

import json

import click
import numpy as np
import pytest

from pinarms.cli import read_via_file
from pinarms.cli.via_points import TRAJECTORY_KINDS, via_input
from pinarms.errors import InvalidInput


def test_csv_file_gives_times_positions_and_joint_names(tmp_path):
    path = tmp_path / "via.csv"
    path.write_text("t,j1,j2\n0,0.1,0.2\n\n1.5,0.3,0.4\n", encoding="utf-8")
    doc = read_via_file(str(path))
    np.testing.assert_array_equal(doc["times"], [0.0, 1.5])
    np.testing.assert_array_equal(doc["positions"], [[0.1, 0.2], [0.3, 0.4]])
    assert doc["joint_names"] == ["j1", "j2"]
    path.write_text("t,j1\n0,0.1\n1,x\n", encoding="utf-8")
    with pytest.raises(InvalidInput, match=r"CSV row 3, column 2 \('j1'\): 'x' is not a finite number"):
        read_via_file(str(path))


def test_json_file_is_checked_key_by_key(tmp_path):
    path = tmp_path / "via.json"
    path.write_text(json.dumps({"positions": [0.0, 1.0, 2.0], "kind": "piecewise"}), encoding="utf-8")
    doc = read_via_file(str(path))
    assert doc["positions"].shape == (3, 1) and doc["kind"] == "piecewise" in TRAJECTORY_KINDS
    path.write_text(json.dumps({"positions": [[0.0], [1.0]], "kind": "spline"}), encoding="utf-8")
    with pytest.raises(InvalidInput, match="unknown 'kind' 'spline'"):
        read_via_file(str(path))


def test_options_give_the_via_points_or_say_what_is_missing():
    t, positions, extra = via_input(("0,1", "2,3"), "0,2", None)
    np.testing.assert_array_equal(t, [0.0, 2.0])
    np.testing.assert_array_equal(positions, [[0.0, 1.0], [2.0, 3.0]])
    assert extra == {}
    with pytest.raises(InvalidInput, match="same number of joint values"):
        via_input(("0,1", "2"), None, None)
    with pytest.raises(InvalidInput, match="at least two via points"):
        via_input(("0,1",), None, None)
    with pytest.raises(click.UsageError, match="--via .* or --file"):
        via_input((), None, None)
