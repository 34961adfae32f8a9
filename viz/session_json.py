"""``session.json``, the document of a session archive, parsed strictly from its bytes.

Strict where :func:`json.loads` is lenient: NaN and Infinity, duplicate keys in one object,
a number too large for float64, a string with a lone surrogate (not writable as UTF-8) and
nesting deeper than a bound are all refused, the depth checked without recursion. The
bytes come from :class:`pinarms.viz.session_archive.ArchiveReader`, which caps their size first.
"""

from __future__ import annotations

import json
import math
from typing import Any, Callable

__all__ = ["JSON_MEMBER", "parse_document"]

JSON_MEMBER = "session.json"


def parse_document(raw: bytes, fail: Callable[[str], Exception], max_depth: int) -> Any:
    """The JSON value of ``raw`` (UTF-8), checked as above; ``fail(what)`` is the error raised otherwise."""
    try:
        doc = json.loads(raw.decode("utf-8"), object_pairs_hook=_no_duplicate_keys, parse_constant=_bad_constant)
    except (UnicodeDecodeError, ValueError) as exc:  # JSONDecodeError and int digit limits are ValueErrors
        raise fail(f"{JSON_MEMBER} is not valid UTF-8 JSON ({str(exc)[:200]})") from None
    except RecursionError:
        raise fail(f"{JSON_MEMBER} nests deeper than {max_depth} levels") from None
    _check_json_values(doc, fail, max_depth)
    return doc


def _check_json_values(doc: Any, fail: Callable[[str], Exception], max_depth: int) -> None:
    """Depth, finite numbers and UTF-8-writable strings, without recursion."""
    stack = [(doc, 1)]
    while stack:
        obj, depth = stack.pop()
        if isinstance(obj, (dict, list)):
            if depth > max_depth:
                raise fail(f"{JSON_MEMBER} nests deeper than {max_depth} levels")
            values = obj.values() if isinstance(obj, dict) else obj
            stack.extend((v, depth + 1) for v in values)
            if isinstance(obj, dict):
                stack.extend((k, depth) for k in obj)
        elif isinstance(obj, float) and not math.isfinite(obj):
            raise fail(f"{JSON_MEMBER} holds a number too large for float64")
        elif isinstance(obj, str):
            try:
                obj.encode("utf-8")
            except UnicodeEncodeError:
                raise fail(f"{JSON_MEMBER} holds a string with a lone surrogate ({obj[:40]!r})") from None


def _no_duplicate_keys(pairs: list[tuple[str, Any]]) -> dict:
    out = dict(pairs)
    if len(out) != len(pairs):
        seen: set = set()
        dup = next(k for k, _ in pairs if k in seen or seen.add(k))
        raise ValueError(f"duplicate key {dup!r} in one object")
    return out


def _bad_constant(name: str) -> Any:
    raise ValueError(f"{name} is not allowed (JSON has no NaN or Infinity)")
