"""The four-paper demo: ``demo``."""

from __future__ import annotations

from pathlib import Path
from typing import Callable

import click

from . import _common as common
from ._common import (
    cli,
    emit,
    json_option,
)


# --------------------------------------------------------------------------- demo
@cli.command("demo")
@click.option("--quick", is_flag=True, help="Smaller samples and GA runs: under a minute.")
@click.option("--out", "out_dir", default="demo-output", show_default=True, type=click.Path(file_okay=False))
@click.option("--only", multiple=True, type=click.Choice(["000", "001", "002", "004", "cell"]), help="Run only these studies.")
@click.option("--readme", "readme", default=None, type=click.Path(exists=True, dir_okay=False),
              help="Also write the table into this markdown file, between its table markers (full run only).")
@json_option
def demo_cmd(quick: bool, out_dir: str, only: tuple[str, ...], readme: str | None, as_json: bool) -> None:
    """Redo the four papers' studies, print the paper-vs-pinarms table and write sessions, HTML and plots."""
    from pinarms.demo import run_demo
    from pinarms.report import splice_table

    if readme and (quick or only):
        raise click.UsageError("--readme takes the table of the full run: drop --quick and --only")
    if readme:
        splice_table(Path(readme).read_text(encoding="utf-8"), [])  # markers checked before the long run
    progress: Callable[[str], None] | None = None
    if common.show_progress(as_json):
        progress = lambda label: click.echo(f"· {label}", err=True)  # noqa: E731
    result = run_demo(out_dir, quick=quick, only=only or None, progress=progress)
    lines = [result.table_text(), "", *(f"wrote {p}" for p in result.files)]
    data = result.as_dict()
    if readme:
        doc = Path(readme)
        doc.write_text(splice_table(doc.read_text(encoding="utf-8"), result.rows), encoding="utf-8")
        data["readme"] = readme
        lines.append(f"table written into {readme}")
    emit(as_json, data, lines)

