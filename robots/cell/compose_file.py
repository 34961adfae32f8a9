"""Cell description files (TOML): arms by URDF file, name and base pose; fixtures as primitives.

The format and its rules are in :mod:`.compose` (and docs/cells.md "Any URDF arm in a
cell"); this module reads and checks a file without reading the arm files it names.
"""

from __future__ import annotations

import math
import os
import re
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from pinarms.files import read_bounded_text

from ..errors import CellError, CellNotFound

__all__ = [
    "ArmPlacement",
    "FixturePrimitive",
    "CellDescription",
    "read_cell_description",
    "MAX_DESCRIPTION_BYTES",
    "MAX_ARM_BYTES",
    "MAX_ARMS",
    "MAX_FIXTURES",
]

#: Largest cell description read [bytes].
MAX_DESCRIPTION_BYTES = 256 * 1024
#: Largest arm URDF read [bytes].
MAX_ARM_BYTES = 16 * 1024 * 1024
#: Most arms and fixtures in one description.
MAX_ARMS = 16
MAX_FIXTURES = 1000

_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]{0,63}\Z")
_SHAPES = {"box": 3, "cylinder": 2, "sphere": 1}


@dataclass(frozen=True)
class ArmPlacement:
    """One arm of a composed cell.

    Attributes:
        name: the arm's name in the cell (letters, digits, ``_``); its prefix is ``name + "_"``.
        urdf: the arm's URDF file: a path, or ``package://PKG/path`` in a package folder.
        xyz: position of the arm's root link in the world [m].
        rpy: its roll, pitch, yaw [rad] (URDF convention).
    """

    name: str
    urdf: str | os.PathLike
    xyz: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rpy: tuple[float, float, float] = (0.0, 0.0, 0.0)


@dataclass(frozen=True)
class FixturePrimitive:
    """A fixture of one primitive, fixed in the world.

    Attributes:
        name: the fixture's link name.
        kind: ``"box"`` (size x y z), ``"cylinder"`` (radius, length along local z) or
            ``"sphere"`` (radius) [m].
        size: the dimensions above.
        xyz, rpy: the primitive's centre in the world [m] and orientation [rad].
    """

    name: str
    kind: str
    size: tuple[float, ...]
    xyz: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rpy: tuple[float, float, float] = (0.0, 0.0, 0.0)


@dataclass(frozen=True)
class CellDescription:
    """A cell description read from a file: its name, arms, fixtures and folder."""

    name: str
    arms: tuple[ArmPlacement, ...]
    fixtures: tuple[FixturePrimitive, ...]
    base_dir: Path



# ----------------------------------------------------------------- reading files
def _read_bounded(path: Path, limit: int, what: str) -> str:
    return read_bounded_text(path, limit, what, error=CellError, missing=CellNotFound)


def _triple(value: Any, key: str, where: str) -> tuple[float, float, float]:
    nums = _numbers(value, key, where)
    if len(nums) != 3:
        raise CellError(f"{where}: {key} must be 3 numbers, got {len(nums)}")
    return nums  # type: ignore[return-value]


def _numbers(value: Any, key: str, where: str) -> tuple[float, ...]:
    items = value if isinstance(value, list) else [value]
    if not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in items):
        raise CellError(f"{where}: {key} must be numbers, got {value!r}")
    out = tuple(float(v) for v in items)
    if not all(math.isfinite(v) for v in out):
        raise CellError(f"{where}: {key} must be finite numbers, got {value!r}")
    return out


def _keys(table: Any, allowed: set[str], required: set[str], where: str) -> dict:
    if not isinstance(table, dict):
        raise CellError(f"{where} must be a table")
    unknown = sorted(set(table) - allowed)
    if unknown:
        raise CellError(f"{where}: unknown key(s) {', '.join(unknown)}; allowed: {', '.join(sorted(allowed))}")
    missing = sorted(required - set(table))
    if missing:
        raise CellError(f"{where}: missing key(s) {', '.join(missing)}")
    return table


def _name(value: Any, where: str) -> str:
    if not isinstance(value, str) or not _NAME.match(value):
        raise CellError(f"{where}: name {value!r} must start with a letter and hold only letters, digits and '_' "
                        "(at most 64 characters)")
    return value


def _fixture_of(table: dict, where: str) -> FixturePrimitive:
    _keys(table, {"name", "xyz", "rpy", *_SHAPES}, {"name"}, where)
    name = _name(table["name"], where)
    kinds = [k for k in _SHAPES if k in table]
    if len(kinds) != 1:
        raise CellError(f"{where} ({name!r}): give exactly one of {', '.join(_SHAPES)}")
    kind = kinds[0]
    size = _numbers(table[kind], kind, where)
    if len(size) != _SHAPES[kind] or min(size) <= 0.0:
        raise CellError(f"{where} ({name!r}): {kind} takes {_SHAPES[kind]} positive number(s) [m], got {table[kind]!r}")
    return FixturePrimitive(name, kind, size, _triple(table.get("xyz", [0, 0, 0]), "xyz", where),
                            _triple(table.get("rpy", [0, 0, 0]), "rpy", where))


def read_cell_description(path: str | os.PathLike) -> CellDescription:
    """Read and check a cell description file (TOML; see the module doc). Arm files are not read here.

    Raises:
        CellNotFound: the file does not exist.
        CellError: too large, not TOML, unknown or missing keys, bad names or numbers,
            too many arms or fixtures, duplicate names.
    """
    path = Path(path)
    text = _read_bounded(path, MAX_DESCRIPTION_BYTES, "cell description")
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise CellError(f"cell description {str(path)!r} is not valid TOML: {exc}") from exc
    except RecursionError:
        raise CellError(f"cell description {str(path)!r} nests arrays or tables too deeply") from None
    _keys(doc, {"name", "arm", "fixture"}, {"arm"}, f"cell description {str(path)!r}")
    default = re.sub(r"\W", "_", path.name.split(".")[0])
    name = _name(doc.get("name", default if _NAME.match(default) else "cell"), str(path))
    arm_tables, fixture_tables = doc["arm"], doc.get("fixture", [])
    if not isinstance(arm_tables, list) or not isinstance(fixture_tables, list):
        raise CellError(f"{path}: write arms as [[arm]] tables and fixtures as [[fixture]] tables")
    if not 1 <= len(arm_tables) <= MAX_ARMS or len(fixture_tables) > MAX_FIXTURES:
        raise CellError(f"{path}: {len(arm_tables)} arms and {len(fixture_tables)} fixtures; a description holds "
                        f"1 to {MAX_ARMS} arms and at most {MAX_FIXTURES} fixtures")
    arms = []
    for k, table in enumerate(arm_tables):
        where = f"{path} arm #{k + 1}"
        _keys(table, {"name", "urdf", "xyz", "rpy"}, {"name", "urdf"}, where)
        if not isinstance(table["urdf"], str):
            raise CellError(f"{where}: urdf must be a string (a path), got {table['urdf']!r}")
        arms.append(ArmPlacement(_name(table["name"], where), table["urdf"],
                                 _triple(table.get("xyz", [0, 0, 0]), "xyz", where),
                                 _triple(table.get("rpy", [0, 0, 0]), "rpy", where)))
    fixtures = [_fixture_of(t, f"{path} fixture #{k + 1}") for k, t in enumerate(fixture_tables)]
    return CellDescription(name, tuple(arms), tuple(fixtures), path.resolve().parent)


