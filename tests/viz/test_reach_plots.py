"""Plots of what an arm reaches: workspace projections."""

from __future__ import annotations

import os

import numpy as np
import pytest

from pinarms import viz
from pinarms.errors import InvalidInput


def test_workspace_views(tmp_path):
    rng = np.random.default_rng(0)
    pts = rng.normal(size=(500, 3)) * 0.3
    w = np.linalg.norm(pts, axis=1)
    out = viz.plot_workspace(tmp_path / "ws.svg", pts, w, mm=True)
    text = out.read_text()
    assert "top view" in text and "side view" in text and "manipulability" in text and "[mm]" in text
    with pytest.raises(InvalidInput, match=r"\(500,\)"):
        viz.plot_workspace(tmp_path / "bad.png", pts, w[:10])


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda p: viz.plot_workspace(p, np.full((3, 3), np.nan)), "NaN"),
        (lambda p: viz.plot_workspace(p, np.zeros((3, 3)), colormap="nope"), "colormap"),
    ],
)
def test_bad_workspace_data_raises_invalid_input_and_writes_nothing(call, match, tmp_path):
    with pytest.raises(InvalidInput, match=match):
        call(tmp_path / "bad.png")
    assert os.listdir(tmp_path) == []
