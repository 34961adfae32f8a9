"""Sessions: ``view`` (live MeshCat viewer) and ``export-html`` (one standalone page)."""

from __future__ import annotations

import sys
from pathlib import Path

import click

from pinarms.cli._common import (
    cli,
    emit,
    json_option,
)


# --------------------------------------------------------------------------- sessions
@cli.command("view")
@click.argument("session", type=click.Path(exists=True, dir_okay=False))
@click.option("--package-dir", "package_dirs", multiple=True, type=click.Path(exists=True, file_okay=False),
              help="A folder meshes of embedded URDFs may come from, besides the session's own folder (repeatable).")
@click.option("--port", default=None, type=click.IntRange(1, 65535), help="HTTP port (default: a free one).")
@click.option("--open", "open_browser", is_flag=True, help="Open the page in the default web browser.")
@click.option("--no-wait", is_flag=True, help="Show, print the address and stop at once (for scripts/tests).")
@json_option
def view_cmd(session: str, package_dirs: tuple[str, ...], port: int | None, open_browser: bool, no_wait: bool,
             as_json: bool) -> None:
    """Open a saved SESSION in the MeshCat viewer (local server on 127.0.0.1; Ctrl+C stops it)."""
    from pinarms import viz

    loaded = viz.load_session(session, package_dirs=package_dirs)
    viewer = viz.show(loaded, port=port, open_browser=open_browser, wait=False)
    try:
        emit(as_json, {"session": session, "url": viewer.url, "title": loaded.title},
              [f"{loaded.title or session}: viewer at {viewer.url}"] + ([] if no_wait else ["press Ctrl+C to stop"]))
        if not no_wait:
            sys.stdout.flush()
            viewer.wait()
    finally:
        viewer.close()


@cli.command("export-html")
@click.argument("session", type=click.Path(exists=True))
@click.argument("out", type=click.Path(dir_okay=False))
@click.option("--package-dir", "package_dirs", multiple=True, type=click.Path(exists=True, file_okay=False),
              help="A folder meshes of embedded URDFs may come from, besides the session's own folder (repeatable).")
@json_option
def export_html_cmd(session: str, out: str, package_dirs: tuple[str, ...], as_json: bool) -> None:
    """Write SESSION as one self-contained HTML page OUT (opens offline in any browser)."""
    from pinarms import viz

    loaded = viz.load_session(session, package_dirs=package_dirs)
    path = viz.export_html(loaded, out)
    path = Path(path) if path else Path(out)
    size = path.stat().st_size
    emit(as_json, {"session": session, "html": str(path), "bytes": size}, [f"wrote {path} ({size / 1e6:.2f} MB)"])


