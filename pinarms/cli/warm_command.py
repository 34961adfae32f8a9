"""Compile every numba kernel ahead of first use: ``warm`` (run by ``make install``)."""

from __future__ import annotations

import click

from pinarms.cli import _common as common
from pinarms.cli._common import cli, emit, json_option


@cli.command("warm")
@json_option
def warm_cmd(as_json: bool) -> None:
    """Compile every numba kernel once into numba's disk cache (a few minutes; one process per core), so that the first IK
    and the first motion plan of every later process load them in about a second. `make install` runs it; a
    second run only loads them. Run it again after changing pinarms' sources (their kernels compile again)."""
    from pinarms.warmup import STEPS, WarmStep, warm

    if not as_json:
        click.echo("compiling pinarms' numba kernels into numba's disk cache (minutes the first time; "
                   "then each is loaded in milliseconds)", err=True)
    with common.progress_bar("kernels", len(STEPS), as_json) as bar:
        running: list[str] = []  # the steps under way (in parallel processes)

        def progress(label: str) -> None:
            running.append(label)
            bar.step(", ".join(running))

        def done(step: WarmStep) -> None:
            running.remove(step.label)
            bar.advance(note=", ".join(running))

        result = warm(progress=progress, done=done)
    emit(as_json, result.as_dict(), result.lines())
