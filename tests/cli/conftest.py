"""The command line's shared test fixture: ``run(*args, ok=True)`` invokes ``pinarms`` through click's CliRunner
and, with ``ok``, asserts exit code 0 (a file may define its own ``run`` to see every exit)."""

from __future__ import annotations

import pytest
from click.testing import CliRunner

from pinarms.cli import cli


@pytest.fixture
def run():
    runner = CliRunner()

    def invoke(*args: str, ok: bool = True):
        result = runner.invoke(cli, list(args))
        if ok:
            assert result.exit_code == 0, (result.output, result.stderr, result.exception)
        return result

    return invoke
