"""``session.json`` parsed strictly: what plain ``json.loads`` would let through is refused, by name."""

from __future__ import annotations

import pytest

from pinarms.viz.session_json import JSON_MEMBER, parse_document


class Refused(Exception):
    pass


def parse(raw: bytes, max_depth: int = 64):
    return parse_document(raw, Refused, max_depth)


def test_a_plain_document_comes_back_unchanged():
    assert JSON_MEMBER == "session.json"
    assert parse(b'{"a": [1, 2.5, "x", null, true], "b": {"c": -1e300}}') == {
        "a": [1, 2.5, "x", None, True], "b": {"c": -1e300}}


@pytest.mark.parametrize(("raw", "fragment"), [
    (b'{"a": NaN}', "NaN is not allowed"),
    (b'{"a": -Infinity}', "-Infinity is not allowed"),
    (b'{"a": 1, "a": 2}', "duplicate key 'a'"),
    (b'{"a": 1e400}', "a number too large for float64"),
    (b'{"a": "\\ud800"}', "lone surrogate"),
    (b'{"\\udfff": 1}', "lone surrogate"),
    (b'\xff{}', "not valid UTF-8 JSON"),
    (b'{"a": [1, 2}', "not valid UTF-8 JSON"),
])
def test_what_json_loads_lets_through_is_refused(raw, fragment):
    with pytest.raises(Refused, match=fragment):
        parse(raw)


def test_depth_is_bounded_without_recursion():
    assert parse(b'{"a": {"b": [1]}}', max_depth=3) == {"a": {"b": [1]}}
    with pytest.raises(Refused, match="session.json nests deeper than 2 levels"):
        parse(b'{"a": {"b": [1]}}', max_depth=2)
    with pytest.raises(Refused, match="nests deeper than 64 levels"):
        parse(b"[" * 100_000 + b"]" * 100_000)
