"""Every example in a command's help is a valid command line of that command (running them all takes minutes:
the motion example is run in test_motion_cli.py, the others by the commands' own tests)."""

from __future__ import annotations

import re
import shlex

import click
import pytest

from pinarms.cli import cli


def _commands(group: click.Group, path: tuple[str, ...] = ()):
    for name, command in group.commands.items():
        if isinstance(command, click.Group):
            yield from _commands(command, path + (name,))
        else:
            yield path + (name,), command


def _examples() -> dict[str, list[str]]:
    found = {}
    for path, command in _commands(cli):
        for paragraph in re.split(r"\n\s*\n", command.help or ""):
            text = " ".join(paragraph.split())
            match = re.match(r"Example[^:]*: (pinarms .*)", text)
            if match:
                found[" ".join(path)] = shlex.split(match.group(1))[1:]
    return found


EXAMPLES = _examples()


def test_the_help_examples_are_found():
    assert {"motion", "plan", "optimize", "cycle", "line", "layout-search", "cell cycle"} <= set(EXAMPLES)


@pytest.mark.parametrize("name", sorted(EXAMPLES))
def test_every_help_example_parses(name):
    """Each example names its own command, and click parses it (options exist, values convert)."""
    args = EXAMPLES[name]
    assert args[: len(name.split())] == name.split(), f"the example of {name!r} runs another command: {args}"
    ctx = click.Context(cli, info_name="pinarms")
    command: click.Command = cli
    for part in name.split():
        command = command.get_command(ctx, part)
        parent, ctx = ctx, click.Context(command, info_name=part, parent=ctx)
    command.make_context(name.split()[-1], args[len(name.split()):], parent=parent)
    assert command.name == name.split()[-1]
