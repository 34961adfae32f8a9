"""Damaged cell files through robots.load_cell: a named PinarmsError, or a cell whose checks compute.

Starting from the shipped aubo_food_station cell URDF, each example damages it the way a
careless or hostile sender would: numbers of primitives and origins replaced (NaN, inf,
negative, zero, huge, not a number), links or joints dropped or duplicated, fixtures
multiplied past the caps, a DOCTYPE/entity, truncation, random byte flips. A cell that
loads must give a finite clearance with its pair, a boolean collision verdict and a
motion check at neutral; nothing may hang (bounded by ``outcome``'s clock) or raise
anything but a named PinarmsError.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from fuzz_support import EXPLORE, outcome
from pinarms.robots.cell import load_cell

CELLS = Path(__file__).resolve().parents[2] / "urdf" / "cells"
SOURCE = (CELLS / "aubo_food_station.urdf").read_text(encoding="utf-8")
_NUMBER = re.compile(r'(size|radius|length|xyz|rpy)="([^"]*)"')
_BAD = st.sampled_from(["nan", "inf", "-inf", "-0.2", "0", "1e308", "-1e-9", "abc", "", "1 2", "0.1 0.1", "1e-320"])
_DEFECTS = ["numbers", "numbers", "drop-link", "duplicate-link", "drop-joint", "many-fixtures", "doctype",
            "truncate", "bytes", "none"]


def _fixture_copies(text: str, n: int) -> str:
    block = re.search(r'  <link name="stand">.*?</link>\n  <joint name="[^"]*stand[^"]*".*?</joint>\n', text, re.S)
    if block is None:
        return text
    copies = "".join(block.group(0).replace('"stand', f'"stand{k}').replace("stand_", f"stand{k}_") for k in range(n))
    return text.replace("</robot>", copies + "</robot>")


@st.composite
def damaged(draw) -> bytes:
    text, defect = SOURCE, draw(st.sampled_from(_DEFECTS))
    if defect == "numbers":
        spots = list(_NUMBER.finditer(text))
        for m in sorted(draw(st.lists(st.sampled_from(spots), min_size=1, max_size=3, unique_by=lambda m: m.start())),
                        key=lambda m: -m.start()):
            text = text[: m.start(2)] + draw(_BAD) + text[m.end(2):]
    elif defect in ("drop-link", "duplicate-link", "drop-joint"):
        tag = "joint" if defect == "drop-joint" else "link"
        blocks = list(re.finditer(rf"  <{tag} name=.*?</{tag}>\n", text, re.S))
        m = draw(st.sampled_from(blocks))
        text = text[: m.start()] + (m.group(0) * 2 if defect == "duplicate-link" else "") + text[m.end():]
    elif defect == "many-fixtures":
        text = _fixture_copies(text, draw(st.sampled_from([3, 700])))
    elif defect == "doctype":
        text = text.replace("<robot", '<!DOCTYPE r [<!ENTITY a "aaaaaaaaaa">]>\n<robot', 1)
    elif defect == "truncate":
        text = text[: draw(st.integers(0, len(text) - 1))]
    raw = text.encode("utf-8")
    if defect == "bytes":
        raw = bytearray(raw)
        for pos in draw(st.lists(st.integers(0, len(raw) - 1), min_size=1, max_size=4)):
            raw[pos] = draw(st.integers(0, 255))
        raw = bytes(raw)
    return raw


def _load_and_check(path: Path):
    cell = load_cell(path)
    q = cell.neutral
    clearance = cell.clearance(q)
    verdict = cell.in_collision(q, margin=0.01)
    assert isinstance(bool(verdict), bool)
    assert np.isfinite(clearance.distance) and clearance.pair is not None
    return clearance.distance


@settings(max_examples=40 * EXPLORE, deadline=None, derandomize=True)
@given(raw=damaged())
def test_damaged_cell_files(tmp_path_factory, raw):
    folder = tmp_path_factory.mktemp("cell")
    (folder / "meshes").mkdir()
    for mesh in (CELLS / "meshes").iterdir():  # the cell's meshes beside it, as shipped
        (folder / "meshes" / mesh.name).write_bytes(mesh.read_bytes())
    path = folder / "cell.urdf"
    path.write_bytes(raw)
    outcome(_load_and_check, path, seconds=30.0)
