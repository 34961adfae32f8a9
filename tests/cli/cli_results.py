"""What the command-line tests read from a result: its ``--json`` document, and a user error's one line."""

from __future__ import annotations

import json


def as_json(result) -> dict:
    return json.loads(result.stdout)


def assert_user_error(result, code: int, *fragments: str) -> None:
    """Non-zero exit, one 'Error:' line on stderr, no traceback."""
    assert result.exit_code == code, (result.output, result.exception)
    assert "Traceback" not in result.output
    assert not isinstance(result.exception, Exception) or isinstance(result.exception, SystemExit)
    err = result.stderr
    assert "Error:" in err
    for fragment in fragments:
        assert fragment in err, err
