"""URDFs: ``urdf build`` (from the xacro sources) and ``urdf export`` (a folder other tools load)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import ClassVar

import click
import numpy as np

from pinarms.errors import InvalidInput

from pinarms.cli._common import (
    PinarmsGroup,
    cli,
    emit,
    floats,
    json_option,
    load_robot,
)
from pinarms.cli._common import package_map
from pinarms.cli.option_groups import Flag, flag, option_group


# --------------------------------------------------------------------------- urdf
@cli.group("urdf", cls=PinarmsGroup)
def urdf_group() -> None:
    """Build the built-in URDFs from their xacro sources, or export a URDF for other tools."""


@urdf_group.command("build")
@click.argument("source", required=False, type=click.Path(dir_okay=False))
@click.option("--arg", "xacro_args", multiple=True, metavar="NAME=VALUE",
              help="A xacro:arg value of SOURCE (repeatable).")
@click.option("--package", "packages", multiple=True, metavar="NAME=FOLDER",
              help="A folder for $(find NAME) and package://NAME/ in SOURCE (repeatable).")
@click.option("-o", "--output", default=None, type=click.Path(dir_okay=False),
              help="Write SOURCE's URDF to this file (default: print it).")
@click.option("--check", is_flag=True, help="Only check: exit 1 and list the URDFs that differ from their xacro.")
@click.option("--out", "out_dir", default=None, type=click.Path(file_okay=False),
              help="Write into this folder instead of the urdf/ package.")
@json_option
def urdf_build_cmd(source: str | None, xacro_args: tuple[str, ...], packages: tuple[str, ...], output: str | None,
                   check: bool, out_dir: str | None, as_json: bool) -> None:
    """Regenerate urdf/*.urdf and urdf/cells/*.urdf from robots/xacro/, or expand a user's SOURCE.xacro.

    SOURCE is expanded behind a wall (docs/cells.md): it may read only its own folder and
    the --package folders, within a time and memory bound.
    """
    from pinarms.robots import urdf_build

    if source is not None:
        if check or out_dir:
            raise click.UsageError("--check and --out apply to the built-in arms; with SOURCE use -o OUT.urdf")
        _build_user_xacro(source, xacro_args, packages, output, as_json)
        return
    if xacro_args or packages or output:
        raise click.UsageError("--arg, --package and -o need a SOURCE.xacro file")
    from pinarms.robots.cell import library

    cells_dir = None if out_dir is None else str(Path(out_dir) / "cells")
    if check:
        stale = urdf_build.stale(out_dir) + [f"cells/{name}" for name in library.stale_cells(cells_dir)]
        emit(as_json, {"stale": stale}, [f"stale: {name}" for name in stale] or ["all URDFs are up to date"])
        if stale:
            raise SystemExit(1)
        return
    written = urdf_build.build_all(out_dir) + library.build_cells(cells_dir)
    emit(as_json, {"written": [str(p) for p in written]}, [f"wrote {p}" for p in written])


def _parse_states(items: tuple[str, ...]) -> dict[str, dict[str | None, np.ndarray]]:
    """``--state NAME=[ARM:]V1,V2,...`` values as ``{NAME: {ARM or None: values}}``."""
    out: dict[str, dict[str | None, np.ndarray]] = {}
    for item in items:
        name, sep, rest = item.partition("=")
        arm, colon, values = rest.partition(":")
        if not sep or not name.strip() or not rest.strip():
            raise InvalidInput(f"--state must be NAME=V1,V2,... or NAME=ARM:V1,V2,..., got {item!r}")
        arm_name = arm.strip() if colon else None
        out.setdefault(name.strip(), {})[arm_name] = floats(values if colon else rest, f"--state {name.strip()}")
    return out


def _cell_states(items: tuple[str, ...], cell) -> dict[str, dict[str, np.ndarray]]:
    """``--state`` values of a cell, each arm named (the only arm when none is given)."""
    arms = [a.name for a in cell.arms]
    out: dict[str, dict[str, np.ndarray]] = {}
    for name, per_arm in _parse_states(items).items():
        for arm, q in per_arm.items():
            if arm is None and len(arms) != 1:
                raise InvalidInput(f"--state {name}: cell {cell.name!r} has arms {', '.join(arms)}: "
                                   f"give {name}=ARM:V1,V2,...")
            arm = arms[0] if arm is None else arm
            if arm not in arms:
                raise InvalidInput(f"--state {name}: cell {cell.name!r} has no arm {arm!r}; arms: {', '.join(arms)}")
            out.setdefault(name, {})[arm] = q
    return out


def _build_user_xacro(source: str, xacro_args: tuple[str, ...], packages: tuple[str, ...], output: str | None,
                      as_json: bool) -> None:
    from pinarms.robots.urdf_build import write_atomic
    from pinarms.robots.xacro_expand import check_mesh_files, expand_xacro, parse_xacro_args

    args = parse_xacro_args(xacro_args)
    pkgs = package_map(packages)
    header = (f" Generated from {Path(source).name} by `pinarms urdf build` (pinarms). ",)
    result = expand_xacro(source, args, packages=pkgs, header=header)
    check_mesh_files(result.urdf_text, source, pkgs)
    if output is None and not as_json:
        click.echo(result.urdf_text, nl=False)
        return
    if output is not None:
        write_atomic(Path(output), result.urdf_text)
    emit(
        as_json,
        {"written": output, "args": dict(result.args), "files": list(result.files),
         **({} if output is not None else {"urdf": result.urdf_text})},
        [f"wrote {output} (args: {', '.join(f'{k}={v}' for k, v in result.args.items()) or 'none'})"],
    )


@dataclass(frozen=True)
class SrdfFlags:
    """The SRDF written beside the URDF (``srdf``) and its named states: the demo's poses (``study_poses``,
    a built-in cell) and the ``--state`` items as typed. States without ``--srdf`` are refused."""

    srdf: bool = False
    study_poses: bool = False
    state_items: tuple[str, ...] = ()

    FLAGS: ClassVar[tuple[Flag, ...]] = (
        flag("--srdf", is_flag=True,
             help="Also write the SRDF (MoveIt: groups, end effector, home, disable_collisions from pinarms' pairs)."),
        flag("--study-poses", is_flag=True,
             help="With --srdf, a built-in cell: also the demo's pick/place poses as named states (plans its cycles)."),
        flag("--state", "state_items", multiple=True, metavar="NAME=[ARM:]V1,V2,...",
             help="With --srdf, a named state (repeatable): joint values [rad or m]; in a cell of several arms "
                  "NAME=ARM:V1,... (repeat NAME for each arm of a whole-cell state). 'home' is the arm's home."),
    )

    def __post_init__(self) -> None:
        if self.study_poses and not self.srdf:
            raise click.UsageError("--study-poses are SRDF states: add --srdf")
        if self.state_items and not self.srdf:
            raise InvalidInput("--state gives SRDF states: add --srdf")


@urdf_group.command("export")
@click.argument("robot")
@click.argument("out_dir", type=click.Path(file_okay=True))
@click.option("--overwrite", is_flag=True, help="Replace a non-empty folder.")
@click.option("--mjcf", is_flag=True,
              help="Write a MuJoCo model (MJCF) instead (a cell: beside its URDF), with sites at the flange and tcp "
                   "(needs: pip install mujoco).")
@option_group(SrdfFlags, "srdf_flags")
@click.option("--cell", "is_cell", is_flag=True,
              help="ROBOT is a cell file (a built-in cell name is recognised without it).")
@click.option("--package", "packages", multiple=True, metavar="NAME=FOLDER",
              help="A folder for package://NAME/ meshes (repeatable). Meshes are copied only from ROBOT's own "
                   "folder and these.")
@json_option
def urdf_export_cmd(robot: str, out_dir: str, overwrite: bool, mjcf: bool, srdf_flags: SrdfFlags, is_cell: bool,
                    packages: tuple[str, ...], as_json: bool) -> None:
    """Write ROBOT (an arm or a whole cell) as a self-contained folder (URDF with relative mesh paths + meshes) into OUT_DIR.

    With --mjcf the folder holds ROBOT.xml for MuJoCo: every link kept as a body, a site
    at the flange and at the tcp, mimic joints as equality constraints. With --srdf it also
    holds ROBOT.srdf; the URDF then gives each collision element its own link. A cell
    (a built-in cell name, or --cell FILE) is written as URDF, plus SRDF and MJCF when asked.

    Files are named after the robot or cell, made a plain file name; meshes and COLLADA
    textures are copied only from ROBOT's folder and the --package folders (docs/files.md).
    An OUT_DIR that is a link to a folder is written through.
    """
    from pinarms.export import export_cell, export_mjcf, export_urdf
    from pinarms.robots.cell import cell_names, load_cell

    srdf, study_poses, state_items = srdf_flags.srdf, srdf_flags.study_poses, srdf_flags.state_items
    pkgs = package_map(packages)
    if is_cell or robot in cell_names():
        cell = load_cell(robot, packages=pkgs)
        states = None
        if study_poses:
            from pinarms.export.shipped import study_states

            states = study_states(cell)
        if state_items:
            states = {**(states or {}), **_cell_states(state_items, cell)}
        result = export_cell(cell, out_dir, srdf=srdf, mjcf=mjcf, overwrite=overwrite, states=states, packages=pkgs)
        files = [p for p in (result.urdf, result.srdf, result.mjcf) if p is not None]
        emit(
            as_json,
            {"folder": result.folder, "urdf": result.urdf, "srdf": result.srdf, "mjcf": result.mjcf,
             "sites": list(result.sites), "meshes": list(result.meshes), "notes": list(result.notes)},
            [f"wrote {', '.join(str(p) for p in files)} and {len(result.meshes)} mesh file(s)",
             *(f"note: {n}" for n in result.notes)],
        )
        return
    if study_poses:
        raise click.UsageError("--study-poses apply to the built-in cells")
    if mjcf:
        if srdf or state_items:
            raise click.UsageError("--srdf goes with the URDF export (run it once without --mjcf)")
        result = export_mjcf(load_robot(robot), out_dir, overwrite=overwrite, packages=pkgs)
        emit(
            as_json,
            {"folder": result.folder, "mjcf": result.mjcf, "sites": list(result.sites), "meshes": list(result.meshes)},
            [f"wrote {result.mjcf} (sites: {', '.join(result.sites)}) and {len(result.meshes)} mesh file(s)"],
        )
        return
    parsed = _parse_states(state_items)
    for name, per_arm in parsed.items():
        if set(per_arm) != {None}:
            raise InvalidInput(f"--state {name}: {robot} is one arm, not a cell: give {name}=V1,V2,... (no ARM:)")
    states = {name: per_arm[None] for name, per_arm in parsed.items()} or None
    result = export_urdf(load_robot(robot), out_dir, overwrite=overwrite, srdf=srdf, packages=pkgs, states=states)
    emit(
        as_json,
        {"folder": result.folder, "urdf": result.urdf, "srdf": result.srdf, "meshes": list(result.meshes),
         "notes": list(result.notes)},
        [f"wrote {result.urdf}{'' if result.srdf is None else f' and {result.srdf}'} and "
         f"{len(result.meshes)} mesh file(s)", *(f"note: {n}" for n in result.notes)],
    )
