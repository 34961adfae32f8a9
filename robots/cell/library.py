"""The built-in cells and :func:`load_cell` (by name, or any xacro/URDF file of the user's).

Built-in cells are xacro files in ``robots/xacro/cells/<name>.urdf.xacro``; their URDFs are
generated and committed in ``urdf/cells/<name>.urdf`` like the arms' (``pinarms urdf
build``; :func:`stale_cells` lists those that differ from a fresh build). Every cell file,
built-in or not, is expanded behind the wall of :mod:`pinarms.robots.xacro_expand`.
Relative mesh paths of a built-in cell resolve against ``urdf/cells/`` (where its URDF is
committed: ``urdf/cells/meshes/``), so the committed URDF loads in other tools as it is.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any, Mapping

from pinarms.files import check_regular
from pinarms.robots._checks import check_path_name
from pinarms.errors import CellNotFound, InvalidInput, ModelError
from pinarms.robots.urdf_build import URDF_DIR, XACRO_DIR, write_atomic
from pinarms.robots.xacro_expand import XacroLimits, expand_xacro
from pinarms.robots.cell.cell import Cell
from pinarms.robots.cell.limits import MAX_CELL_FILE_BYTES, check_file_size, read_cell_file

__all__ = [
    "CELL_XACRO_DIR",
    "CELL_URDF_DIR",
    "cell_names",
    "cell_source_path",
    "cell_urdf_path",
    "build_cell",
    "build_cells",
    "stale_cells",
    "load_cell",
]

#: Folder of the built-in cells' xacro sources.
CELL_XACRO_DIR: Path = XACRO_DIR / "cells"
#: Folder of their generated URDFs.
CELL_URDF_DIR: Path = URDF_DIR / "cells"

_SUFFIX = ".urdf.xacro"


def cell_names() -> list[str]:
    """Names of the built-in cells, sorted (``["aubo_food_station", "mushroom_line"]``)."""
    return sorted(p.name[: -len(_SUFFIX)] for p in CELL_XACRO_DIR.glob("*" + _SUFFIX))


def cell_source_path(name: str) -> Path:
    """The xacro source of built-in cell ``name``; :class:`CellNotFound` lists the cells otherwise."""
    path = CELL_XACRO_DIR / f"{name}{_SUFFIX}"
    if not isinstance(name, str) or not path.is_file():
        raise CellNotFound(
            f"unknown cell {name!r}; built-in cells: {', '.join(cell_names())} (or give the path of a .xacro or .urdf file)"
        )
    return path


def cell_urdf_path(name: str, out_dir: str | os.PathLike | None = None) -> Path:
    """Where the generated URDF of built-in cell ``name`` lives (``urdf/cells/`` unless ``out_dir``)."""
    return Path(out_dir if out_dir is not None else CELL_URDF_DIR) / f"{name}.urdf"


def _header(name: str) -> tuple[str, ...]:
    return (
        f" Generated from robots/xacro/cells/{name}{_SUFFIX} by `pinarms urdf build` (pinarms). ",
        " Do not edit by hand: edit the xacro source and regenerate (`pinarms urdf build`). ",
    )


def build_cell(name: str, args: Mapping[str, Any] | None = None) -> str:
    """URDF text of built-in cell ``name`` (its xacro defaults, or ``args``)."""
    return expand_xacro(cell_source_path(name), args, header=_header(name)).urdf_text


def build_cells(out_dir: str | os.PathLike | None = None) -> list[Path]:
    """Generate every built-in cell's URDF (all built before any is written, each atomically)."""
    texts = {name: build_cell(name) for name in cell_names()}
    written = []
    for name, text in texts.items():
        target = cell_urdf_path(name, out_dir)
        write_atomic(target, text)
        written.append(target)
    return written


def stale_cells(out_dir: str | os.PathLike | None = None) -> list[str]:
    """Built-in cells whose URDF in ``out_dir`` (default ``urdf/cells/``) is missing or differs from a fresh build."""
    out = []
    for name in cell_names():
        target = cell_urdf_path(name, out_dir)
        if not target.is_file() or target.read_text(encoding="utf-8") != build_cell(name):
            out.append(name)
    return out


def load_cell(
    path_or_name: str | os.PathLike,
    *,
    packages: Mapping[str, str | os.PathLike] | None = None,
    limits: XacroLimits | None = None,
    seed: int = 0,
    xacro_args: Mapping[str, Any] | None = None,
    **args: Any,
) -> Cell:
    """Load a cell: a built-in name, a ``.xacro`` file (expanded behind the wall), a ``.urdf`` file
    or a ``.toml`` cell description (any URDF arms under prefixes: :mod:`.compose`).

    Args:
        path_or_name: ``"mushroom_line"``, ``"aubo_food_station"`` (see :func:`cell_names`),
            or a file path.
        packages: ``{name: folder}`` for ``$(find name)`` and ``package://name/`` meshes
            (``pinarms``, the built-in macros and meshes, is always there).
        limits: time/memory bounds of the xacro expansion.
        seed: seed of the random configurations of the "always touching" pair rule.
        xacro_args, **args: the file's ``xacro:arg`` values (``belt_top=0.85``); a
            built-in cell without arguments loads its committed URDF.

    Raises:
        CellNotFound: an unknown name (the message lists the built-in cells).
        XacroError (and its subclasses), MissingMesh: see :func:`~pinarms.robots.expand_xacro`.
        CellError: duplicate names, no arm, an arm that is not one subtree.
        CollisionGeometryError: a collision geometry that did not load or cannot be checked.
    """
    all_args = {**(xacro_args or {}), **args}
    text_or_path = str(path_or_name)
    is_file = text_or_path.endswith((".xacro", ".urdf", ".toml")) or os.sep in text_or_path or "/" in text_or_path
    if not is_file:
        source = cell_source_path(text_or_path)
        if all_args:
            result = expand_xacro(source, all_args, packages=packages, limits=limits, header=_header(text_or_path))
            return Cell(result.urdf_text, source=f"builtin:{text_or_path}", base_dir=CELL_URDF_DIR, packages=packages,
                        args=result.args, seed=seed)
        urdf = cell_urdf_path(text_or_path)
        if not urdf.is_file():
            raise ModelError(f"the URDF of cell {text_or_path!r} is missing ({urdf.name}); regenerate it with `pinarms urdf build`")
        declared = {}
        return Cell(urdf.read_text(encoding="utf-8"), source=f"builtin:{text_or_path}", base_dir=CELL_URDF_DIR,
                    packages=packages, args=declared, seed=seed)
    check_path_name(path_or_name, "cell file")
    path = Path(path_or_name)
    if not path.exists():
        raise CellNotFound(f"cell file {str(path)!r} does not exist; built-in cells: {', '.join(cell_names())}")
    check_regular(path, "cell file", error=ModelError, missing=CellNotFound)  # a FIFO or a device: refused unread
    if path.name.endswith(".toml"):  # a cell description: arms by URDF file under prefixes (compose.py)
        if all_args:
            raise InvalidInput(f"{str(path)!r} is a cell description: it takes no xacro arguments")
        from pinarms.robots.cell.compose import load_cell_description

        return load_cell_description(path, packages=packages, seed=seed)
    if path.name.endswith(".xacro"):
        check_file_size(path, MAX_CELL_FILE_BYTES, "cell file")  # by stat, before the expansion reads it
        result = expand_xacro(path, all_args, packages=packages, limits=limits,
                              header=(f" Generated from {path.name} by pinarms. ",))
        return Cell(result.urdf_text, source=str(path), base_dir=path.resolve().parent, packages=packages,
                    args=result.args, seed=seed)
    if all_args:
        raise InvalidInput(f"{str(path)!r} is a URDF: it takes no xacro arguments (got {', '.join(all_args)})")
    text = read_cell_file(path)  # sized by stat, read up to the cap only
    return Cell(text, source=str(path), base_dir=path.resolve().parent, packages=packages, seed=seed)
