"""URDFs: ``urdf build`` (from the xacro sources) and ``urdf export`` (a folder other tools load)."""

from __future__ import annotations

import click

from ._common import (
    PinarmsGroup,
    cli,
    emit,
    json_option,
    load_robot,
)


# --------------------------------------------------------------------------- urdf
@cli.group("urdf", cls=PinarmsGroup)
def urdf_group() -> None:
    """Build the built-in URDFs from their xacro sources, or export a URDF for other tools."""


@urdf_group.command("build")
@click.option("--check", is_flag=True, help="Only check: exit 1 and list the URDFs that differ from their xacro.")
@click.option("--out", "out_dir", default=None, type=click.Path(file_okay=False),
              help="Write into this folder instead of the urdf/ package.")
@json_option
def urdf_build_cmd(check: bool, out_dir: str | None, as_json: bool) -> None:
    """Regenerate urdf/*.urdf from robots/xacro/*.urdf.xacro."""
    from pinarms.robots import urdf_build

    if check:
        stale = urdf_build.stale(out_dir)
        emit(as_json, {"stale": stale}, [f"stale: {name}" for name in stale] or ["all URDFs are up to date"])
        if stale:
            raise SystemExit(1)
        return
    written = urdf_build.build_all(out_dir)
    emit(as_json, {"written": [str(p) for p in written]}, [f"wrote {p}" for p in written])


@urdf_group.command("export")
@click.argument("robot")
@click.argument("out_dir", type=click.Path(file_okay=True))
@click.option("--overwrite", is_flag=True, help="Replace a non-empty folder.")
@click.option("--mjcf", is_flag=True,
              help="Write a MuJoCo model (MJCF) instead, with sites at the flange and tcp (needs: pip install mujoco).")
@json_option
def urdf_export_cmd(robot: str, out_dir: str, overwrite: bool, mjcf: bool, as_json: bool) -> None:
    """Write ROBOT as a self-contained folder (URDF with relative mesh paths + meshes) into OUT_DIR.

    With --mjcf the folder holds ROBOT.xml for MuJoCo: every link kept as a body, a site
    at the flange and at the tcp, mimic joints as equality constraints.
    """
    from pinarms.export import export_mjcf, export_urdf

    if mjcf:
        result = export_mjcf(load_robot(robot), out_dir, overwrite=overwrite)
        emit(
            as_json,
            {"folder": result.folder, "mjcf": result.mjcf, "sites": list(result.sites), "meshes": list(result.meshes)},
            [f"wrote {result.mjcf} (sites: {', '.join(result.sites)}) and {len(result.meshes)} mesh file(s)"],
        )
        return
    result = export_urdf(load_robot(robot), out_dir, overwrite=overwrite)
    emit(
        as_json,
        {"folder": result.folder, "urdf": result.urdf, "meshes": list(result.meshes)},
        [f"wrote {result.urdf} and {len(result.meshes)} mesh file(s)"],
    )
