"""The four-paper demo: ``demo``."""

from __future__ import annotations

from pathlib import Path
import click

from pinarms.cli import _common as common
from pinarms.cli._common import (
    cli,
    emit,
    json_option,
)


# --------------------------------------------------------------------------- demo
@cli.command("demo")
@click.option("--quick", is_flag=True,
              help="Smaller samples and GA runs: 3 to 5 minutes on two cores (measured 186 s and, on a loaded machine, "
                   "290 s), once `pinarms warm` has compiled the kernels (make install does; else minutes more, once).")
@click.option("--out", "out_dir", default="demo-output", show_default=True, type=click.Path(file_okay=False))
@click.option("--only", multiple=True, type=click.Choice(["000", "001", "002", "004", "cell", "line", "handoff", "delta"]), help="Run only these studies.")
@click.option("--readme", "readme", default=None, type=click.Path(exists=True, dir_okay=False),
              help="Also write the table into this markdown file, between its table markers (full run only).")
@json_option
def demo_cmd(quick: bool, out_dir: str, only: tuple[str, ...], readme: str | None, as_json: bool) -> None:
    """Redo the four papers' studies, the cell, line and hand-off studies; print the paper-vs-pinarms table and write
    sessions, HTML, plots and export files."""
    from pinarms.demo import STUDIES, run_demo
    from pinarms.report import splice_table

    if readme and (quick or only):
        raise click.UsageError("--readme takes the table of the full run: drop --quick and --only")
    if readme:
        splice_table(Path(readme).read_text(encoding="utf-8"), [])  # markers checked before the long run
    n_studies = len(only) if only else len(STUDIES)
    with common.progress_bar("demo studies", n_studies, as_json) as bar:
        def progress(label: str) -> None:
            bar.step(label)
            if label.endswith("done"):
                bar.advance()

        result = run_demo(out_dir, quick=quick, only=only or None, progress=progress)
    # the terminal gets the table wrapped to its width; table.md / table.json keep every row whole
    lines = [result.table_text(width=common.terminal_width()), "", *(f"wrote {p}" for p in result.files)]
    data = result.as_dict()
    if readme:
        doc = Path(readme)
        doc.write_text(splice_table(doc.read_text(encoding="utf-8"), result.rows), encoding="utf-8")
        data["readme"] = readme
        lines.append(f"table written into {readme}")
    emit(as_json, data, lines)

