"""Plots of searches: a GA's convergence."""

from __future__ import annotations

import os

import pytest
from PIL import Image

from pinarms import viz
from pinarms.errors import InvalidInput


def test_ga_convergence(tmp_path):
    hist = {"best": [6.0, 4.1, 3.7, 3.61], "mean": [9.0, 6.0, 4.5, 3.9], "feasible_share": [0.1, 0.5, 0.9, 1.0]}
    out = viz.plot_ga_convergence(tmp_path / "ga.svg", hist)
    text = out.read_text()
    assert "generation" in text and "feasible share" in text and "population mean" in text
    assert "can lie below the best" in text  # a mean of all individuals says what it counts
    hist["feasible_mean"] = [7.0, 5.0, 4.0, 3.7]
    text = viz.plot_ga_convergence(tmp_path / "ga2.svg", hist).read_text()
    assert "mean of the feasible individuals" in text and "population mean" not in text
    s = viz.Session()
    rec = s.add_history("ga", hist)
    assert Image.open(viz.plot_ga_convergence(tmp_path / "ga.png", rec)).format == "PNG"
    with pytest.raises(InvalidInput, match="best"):
        viz.plot_ga_convergence(tmp_path / "x.png", {"mean": [1.0]})


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda p: viz.plot_ga_convergence(p, {"best": []}), "G >= 1"),
        (lambda p: viz.plot_ga_convergence(p, {"best": [[1.0, 2.0], [3.0, 4.0]]}), "one objective per generation"),
        (lambda p: viz.plot_ga_convergence(p, {"best": [1.0, 2.0], "mean": [1.0, 2.0, 3.0]}), "mean must have one value"),
        (lambda p: viz.plot_ga_convergence(p, {"best": [1.0, float("nan")]}), "NaN"),
    ],
)
def test_bad_ga_data_raises_invalid_input_and_writes_nothing(call, match, tmp_path):
    with pytest.raises(InvalidInput, match=match):
        call(tmp_path / "bad.png")
    assert os.listdir(tmp_path) == []
