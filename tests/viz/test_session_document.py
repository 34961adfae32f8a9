"""session.json checked: its format, version, fields and references."""

from __future__ import annotations

import json

import pytest

from pinarms import viz
from pinarms.viz import SessionFormatError

from session_files import document, rewrite


def test_bad_json(saved, tmp_path):
    cases = {
        b"{not json": "not valid UTF-8 JSON",
        b"[1, 2]": "must hold a JSON object",
        json.dumps({"format": "other", "version": 1}).encode(): "format 'other'",
        json.dumps({"format": "pinarms-session", "version": "1"}).encode(): "not a positive integer",
    }
    for i, (payload, message) in enumerate(cases.items()):
        bad = rewrite(saved, tmp_path / f"j{i}.pinarms", replace={"session.json": payload})
        with pytest.raises(SessionFormatError, match=message):
            viz.load_session(bad)
    doc = document(saved)
    del doc["workspaces"][0]["manipulability"]
    bad = rewrite(saved, tmp_path / "field.pinarms", replace={"session.json": json.dumps(doc).encode()})
    with pytest.raises(SessionFormatError, match=r"workspaces\[0\] lacks the field 'manipulability'"):
        viz.load_session(bad)
    doc = document(saved)
    doc["trajectories"][1]["robot"] = "nobody"
    bad = rewrite(saved, tmp_path / "robot.pinarms", replace={"session.json": json.dumps(doc).encode()})
    with pytest.raises(SessionFormatError, match="'nobody' is not one of the session's robots"):
        viz.load_session(bad)


def test_future_format_version(saved, tmp_path):
    doc = document(saved)
    doc["version"] = viz.FORMAT_VERSION + 1
    doc["something_new"] = {"x": 1}
    bad = rewrite(saved, tmp_path / "future.pinarms", replace={"session.json": json.dumps(doc).encode()})
    with pytest.raises(SessionFormatError, match=rf"version {viz.FORMAT_VERSION + 1}, newer .* upgrade pinarms"):
        viz.load_session(bad)
