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
from typing import Any, Mapping, Sequence

from pinarms.files import read_bounded_text

from pinarms.errors import CellError, CellNotFound

__all__ = [
    "FIXTURE_SIZES",
    "check_name",
    "read_cell_file",
    "ArmPlacement",
    "ToolPoint",
    "FixturePrimitive",
    "CellDescription",
    "read_cell_description",
    "MAX_DESCRIPTION_BYTES",
    "MAX_ARM_BYTES",
    "MAX_ARMS",
    "MAX_FIXTURES",
    "MAX_DECLARED",
]

#: Largest cell description read [bytes].
MAX_DESCRIPTION_BYTES = 256 * 1024
#: Largest arm URDF read [bytes].
MAX_ARM_BYTES = 16 * 1024 * 1024
#: Most arms and fixtures in one description.
MAX_ARMS = 16
MAX_FIXTURES = 1000
#: Most ``[[disable_collisions]]`` entries in one description.
MAX_DECLARED = 10_000

_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]{0,63}\Z")
#: How many size numbers [m] each fixture kind takes in a cell description.
FIXTURE_SIZES = {"box": 3, "cylinder": 2, "sphere": 1, "crate": 3}
_ARM_KEYS = {"name", "urdf", "delta", "xyz", "rpy", "tcp", "freeze", "states", "hold"}


@dataclass(frozen=True)
class ToolPoint:
    """Where an arm's tool point (tcp) is: a link of the arm file and an offset from it.

    Attributes:
        link: the link's name in the arm file (without the cell's prefix).
        xyz: position of the tcp in that link's frame [m].
        rpy: its roll, pitch, yaw in that frame [rad]; the tcp's z axis is the tool axis
            (a "tool down" pose points it along the world's -z, docs/workspace.md).
    """

    link: str
    xyz: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rpy: tuple[float, float, float] = (0.0, 0.0, 0.0)


@dataclass(frozen=True)
class ArmPlacement:
    """One arm of a composed cell.

    Attributes:
        name: the arm's name in the cell (letters, digits, ``_``); its prefix is ``name + "_"``.
        urdf: the arm's URDF file: a path, or ``package://PKG/path`` in a package folder.
        xyz: position of the arm's root link in the world [m].
        rpy: its roll, pitch, yaw [rad] (URDF convention).
        tcp: the arm's tool point (:class:`ToolPoint`); ``None``: the file's ``tcp`` link if it
            has one, else its last link (deepest in the tree), as :attr:`CellArm.tcp_choice` says.
        freeze: ``{joint: value}`` [rad or m] of joints held fixed (gripper fingers): they leave
            the arm's joint vector; each value within the joint's limits.
        states: ``{name: joint values}`` [rad or m], in the arm's joint order after freezing
            (``cell.arm(name).robot.joint_names``); each within the limits. No state is implied:
            a ``home`` exists only when given.
        hold: the arm's configuration whenever it does not move (planning, checks, cycles,
            sessions): a state's name or joint values; ``None``: the neutral configuration.
        delta: the name of a shipped delta robot (``"delta_flexpicker"``) placed instead of a
            URDF arm (``urdf`` then empty): its joint vector is its three motor angles (and its
            tool axis), its bodies are posed from the closed form (:mod:`.delta_arm`); no ``tcp``
            or ``freeze``.
    """

    name: str
    urdf: str | os.PathLike
    xyz: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rpy: tuple[float, float, float] = (0.0, 0.0, 0.0)
    tcp: ToolPoint | None = None
    freeze: Mapping[str, float] | tuple[tuple[str, float], ...] = ()
    states: Mapping[str, Sequence[float]] | tuple[tuple[str, tuple[float, ...]], ...] = ()
    hold: str | Sequence[float] | None = None
    delta: str | None = None

    def __post_init__(self) -> None:  # mappings kept as tuples of pairs: the placement stays hashable
        where = f"arm {self.name!r}"
        if self.delta is not None and (not isinstance(self.delta, str) or self.urdf or self.tcp is not None
                                       or dict(self.freeze)):
            raise CellError(f"{where}: a delta is placed by its name alone (delta = \"delta_flexpicker\"): no urdf, "
                            f"tcp or freeze; got delta={self.delta!r}, urdf={self.urdf!r}")
        if self.tcp is not None and not isinstance(self.tcp, ToolPoint):
            raise CellError(f"{where}: tcp must be a ToolPoint(link, xyz, rpy), got {self.tcp!r}")
        freeze = dict(self.freeze)
        for k, v in freeze.items():
            if isinstance(v, (list, tuple)):
                raise CellError(f"{where}: freeze {k} takes one value [rad or m], got {v!r}")
        object.__setattr__(self, "freeze", tuple((str(k), _numbers(v, f"freeze {k}", where)[0])
                                                 for k, v in freeze.items()))
        states = dict(self.states)
        for state in states:
            check_name(state, f"{where} state")
        object.__setattr__(self, "states", tuple((k, _numbers(list(v), f"state {k!r}", where))
                                                 for k, v in states.items()))
        if self.hold is not None and not isinstance(self.hold, str):
            object.__setattr__(self, "hold", _numbers(list(self.hold), "hold", where))


@dataclass(frozen=True)
class FixturePrimitive:
    """A fixture of one primitive, fixed in the world.

    Attributes:
        name: the fixture's link name.
        kind: ``"box"`` (size x y z), ``"cylinder"`` (radius, length along local z),
            ``"sphere"`` (radius) or ``"crate"`` (outer x y and height: a floor slab and four
            walls, like the ``fixture_crate`` macro) [m].
        size: the dimensions above.
        xyz, rpy: the primitive's centre (a crate: the centre of its floor slab) in the world
            [m] and orientation [rad].
        wall, floor: a crate's wall and floor thickness [m]; its links are ``name`` (the floor)
            and ``name_wall_xpos``, ``_xneg``, ``_ypos``, ``_yneg``, so a contact names the wall.
    """

    name: str
    kind: str
    size: tuple[float, ...]
    xyz: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rpy: tuple[float, float, float] = (0.0, 0.0, 0.0)
    wall: float = 0.01
    floor: float = 0.01


@dataclass(frozen=True)
class CellDescription:
    """A cell description read from a file: its name, arms, fixtures and folder."""

    name: str
    arms: tuple[ArmPlacement, ...]
    fixtures: tuple[FixturePrimitive, ...]
    base_dir: Path
    declared: tuple[tuple[str, str, str], ...] = ()



# ----------------------------------------------------------------- reading files
def read_cell_file(path: Path, limit: int, what: str) -> str:
    """The text of a cell's file ``path`` (at most ``limit`` bytes; ``what`` names it in the error).

    Raises:
        CellNotFound: no such file. CellError: too large, or not UTF-8 text.
    """
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


def check_name(value: object, where: str) -> str:
    """``value`` checked as a cell, arm, fixture or state name (a letter, then letters, digits, ``_``; at most 64).

    Raises:
        CellError: not such a name (``where`` says where it was read).
    """
    if not isinstance(value, str) or not _NAME.match(value):
        raise CellError(f"{where}: name {value!r} must start with a letter and hold only letters, digits and '_' "
                        "(at most 64 characters)")
    return value


def _fixture_of(table: dict, where: str) -> FixturePrimitive:
    _keys(table, {"name", "xyz", "rpy", "wall", "floor", *FIXTURE_SIZES}, {"name"}, where)
    name = check_name(table["name"], where)
    kinds = [k for k in FIXTURE_SIZES if k in table]
    if len(kinds) != 1:
        raise CellError(f"{where} ({name!r}): give exactly one of {', '.join(FIXTURE_SIZES)}")
    kind = kinds[0]
    size = _numbers(table[kind], kind, where)
    if len(size) != FIXTURE_SIZES[kind] or min(size) <= 0.0:
        raise CellError(f"{where} ({name!r}): {kind} takes {FIXTURE_SIZES[kind]} positive number(s) [m], got {table[kind]!r}")
    extra = [k for k in ("wall", "floor") if k in table]
    if extra and kind != "crate":
        raise CellError(f"{where} ({name!r}): {' and '.join(extra)} belong to a crate, not a {kind}")
    if any(isinstance(table.get(k), list) for k in ("wall", "floor")):
        raise CellError(f"{where} ({name!r}): wall and floor take one number each [m]")
    wall, floor = (_numbers(table.get(k, 0.01), k, where)[0] for k in ("wall", "floor"))
    fixture = FixturePrimitive(name, kind, size, _triple(table.get("xyz", [0, 0, 0]), "xyz", where),
                               _triple(table.get("rpy", [0, 0, 0]), "rpy", where), wall, floor)
    check_crate(fixture, f"{where} ({name!r})")
    return fixture


def check_crate(fixture: FixturePrimitive, where: str) -> None:
    """A crate's walls and floor must be thinner than it: ``0 < 2 wall < min(x, y)``, ``0 < floor < height``."""
    if fixture.kind != "crate":
        return
    sx, sy, h = fixture.size
    if not (0.0 < 2.0 * fixture.wall < min(sx, sy) and 0.0 < fixture.floor < h):
        raise CellError(f"{where}: a crate's wall {fixture.wall:g} m and floor {fixture.floor:g} m must be > 0, two "
                        f"walls thinner than its width {min(sx, sy):g} m and the floor thinner than its height {h:g} m")


def _tool_point(value: Any, where: str) -> ToolPoint:
    if isinstance(value, str):
        value = {"link": value}
    _keys(value, {"link", "xyz", "rpy"}, {"link"}, f"{where} tcp")
    if not isinstance(value["link"], str) or not value["link"]:
        raise CellError(f"{where}: tcp link must be a link name, got {value['link']!r}")
    return ToolPoint(value["link"], _triple(value.get("xyz", [0, 0, 0]), "tcp xyz", where),
                     _triple(value.get("rpy", [0, 0, 0]), "tcp rpy", where))


def _arm_of(table: Any, where: str) -> ArmPlacement:
    """One ``[[arm]]`` table: name, urdf, pose, and the optional tcp, freeze, states and hold."""
    _keys(table, _ARM_KEYS, {"name"}, where)
    if "urdf" not in table and "delta" not in table:
        raise CellError(f"{where}: missing key(s) urdf (a serial arm's file), or delta (a shipped delta's name)")
    if "urdf" in table and "delta" in table:
        raise CellError(f"{where}: give exactly one of urdf (a serial arm's file) or delta (a shipped delta's name)")
    if "delta" in table:
        extra = sorted({"tcp", "freeze"} & set(table))
        if extra or not isinstance(table["delta"], str):
            raise CellError(f"{where}: a delta takes its name (delta = \"delta_flexpicker\"), pose, states and hold; "
                            f"not {', '.join(extra) or repr(table['delta'])}")
    elif not isinstance(table["urdf"], str):
        raise CellError(f"{where}: urdf must be a string (a path), got {table['urdf']!r}")
    freeze, states = table.get("freeze", {}), table.get("states", {})
    for key, value in (("freeze", freeze), ("states", states)):
        if not isinstance(value, dict):
            raise CellError(f"{where}: write {key} as a table ({key} = {{ name = ... }}), got {value!r}")
    hold = table.get("hold")
    if hold is not None and not isinstance(hold, (str, list)):
        raise CellError(f"{where}: hold must be a state's name or a list of joint values, got {hold!r}")
    tcp = _tool_point(table["tcp"], where) if "tcp" in table else None
    for key, value in states.items():
        if not isinstance(value, list):
            raise CellError(f"{where}: state {key!r} must be a list of joint values, got {value!r}")
    return ArmPlacement(check_name(table["name"], where), table.get("urdf", ""),
                        _triple(table.get("xyz", [0, 0, 0]), "xyz", where),
                        _triple(table.get("rpy", [0, 0, 0]), "rpy", where),
                        tcp=tcp, freeze=freeze, states=states, hold=hold, delta=table.get("delta"))


def read_cell_description(path: str | os.PathLike) -> CellDescription:
    """Read and check a cell description file (TOML; see the module doc). Arm files are not read here.

    Raises:
        CellNotFound: the file does not exist.
        CellError: too large, not TOML, unknown or missing keys, bad names or numbers,
            too many arms or fixtures, duplicate names.
    """
    path = Path(path)
    text = read_cell_file(path, MAX_DESCRIPTION_BYTES, "cell description")
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise CellError(f"cell description {str(path)!r} is not valid TOML: {exc}") from exc
    except RecursionError:
        raise CellError(f"cell description {str(path)!r} nests arrays or tables too deeply") from None
    _keys(doc, {"name", "arm", "fixture", "disable_collisions"}, {"arm"}, f"cell description {str(path)!r}")
    default = re.sub(r"\W", "_", path.name.split(".")[0])
    name = check_name(doc.get("name", default if _NAME.match(default) else "cell"), str(path))
    arm_tables, fixture_tables = doc["arm"], doc.get("fixture", [])
    if not isinstance(arm_tables, list) or not isinstance(fixture_tables, list):
        raise CellError(f"{path}: write arms as [[arm]] tables and fixtures as [[fixture]] tables")
    if not 1 <= len(arm_tables) <= MAX_ARMS or len(fixture_tables) > MAX_FIXTURES:
        raise CellError(f"{path}: {len(arm_tables)} arms and {len(fixture_tables)} fixtures; a description holds "
                        f"1 to {MAX_ARMS} arms and at most {MAX_FIXTURES} fixtures")
    arms = [_arm_of(table, f"{path} arm #{k + 1}") for k, table in enumerate(arm_tables)]
    fixtures = [_fixture_of(t, f"{path} fixture #{k + 1}") for k, t in enumerate(fixture_tables)]
    declared = _declared_of(doc.get("disable_collisions", []), path)
    return CellDescription(name, tuple(arms), tuple(fixtures), path.resolve().parent, declared)


def _declared_of(tables: Any, path: Path) -> tuple[tuple[str, str, str], ...]:
    """The ``[[disable_collisions]]`` tables (``link1``, ``link2`` the cell's link names, ``reason`` optional)."""
    if not isinstance(tables, list) or len(tables) > MAX_DECLARED:
        raise CellError(f"{path}: write declared contacts as [[disable_collisions]] tables (at most {MAX_DECLARED})")
    out = []
    for k, table in enumerate(tables):
        where = f"{path} disable_collisions #{k + 1}"
        _keys(table, {"link1", "link2", "reason"}, {"link1", "link2"}, where)
        a, b, note = table["link1"], table["link2"], table.get("reason", "")
        if not all(isinstance(v, str) for v in (a, b, note)) or not a or not b or a == b:
            raise CellError(f"{where}: link1 and link2 must be two different link names of the cell (strings), "
                            f"reason a string; got {a!r}, {b!r}, {note!r}")
        out.append((a, b, note))
    return tuple(out)


