"""The user's own arm on the belt: ``pinarms belt run|arms|size --robot URDF`` and its options.

``--robot URDF`` (with ``--package NAME=FOLDER`` for its ``package://`` files, repeatable) puts
copies of that arm along the belt (:func:`pinarms.studies.arm_line.arm_line`) instead of a
``--preset``. The tool point: ``--tcp LINK`` (default: the file's ``tcp`` link, else its last
link), ``--tcp-offset X,Y,Z`` [m] in that link's frame, and ``--tool-axis``: the link's axis
the tool points along (default ``z``). "Tool down" means the tool point's z axis along the
world's -z; an arm whose tool points along x (``--tool-axis x``) gets a tool point turned so
that its z axis is the link's x axis. Every bad value is one ``Error:`` line naming its flag.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar

import click
import numpy as np

from pinarms.errors import InvalidInput, PinarmsError

from pinarms.cli._common import floats, package_map
from pinarms.cli.option_groups import Flag, flag

__all__ = ["BeltRobotFlags", "load_belt_robot", "box_value", "grid_value", "TOOL_AXES", "TOOL_LINK"]

#: ``--tool-axis`` values: the tcp link's axis the tool points along -> roll, pitch, yaw [rad] of
#: a tool point whose z axis is that axis.
TOOL_AXES = {"z": (0.0, 0.0, 0.0), "x": (0.0, np.pi / 2, 0.0), "y": (-np.pi / 2, 0.0, 0.0),
             "-z": (np.pi, 0.0, 0.0), "-x": (0.0, -np.pi / 2, 0.0), "-y": (np.pi / 2, 0.0, 0.0)}
#: Name of the link added for a tool point with an offset or a turned axis.
TOOL_LINK = "belt_tool_point"


@dataclass(frozen=True)
class BeltRobotFlags:
    """The user's arm on the belt as typed (module doc): its URDF (``robot_urdf``; ``None``: a preset's
    arms) or a shipped delta's name, the files' packages, the tool point (``tcp``, ``tcp_offset``,
    ``tool_axis``) and the line's layout (``base_offset``, ``box``, ``base_height``, ``spacing`` [m],
    ``descend`` [s], ``map_grid``). Flags of the arm without ``--robot`` are refused, naming the flag."""

    robot_urdf: str | None = None
    packages: tuple[str, ...] = ()
    tcp: str | None = None
    tcp_offset: str | None = None
    tool_axis: str = "z"
    base_offset: float = 0.4
    box: str = "-0.1,0.25,0.15"
    base_height: float = 0.0
    spacing: float = 1.0
    descend: float = 0.5
    map_grid: str = "12,5"

    FLAGS: ClassVar[tuple[Flag, ...]] = (
        flag("--robot", "robot_urdf", type=click.Path(dir_okay=False), default=None, metavar="URDF",
             help="Your arm's URDF file: copies of it along the belt instead of --preset (maps built, minutes "
                  "for a 6-axis arm; a progress line shows); or a shipped delta's name (delta_flexpicker): "
                  "deltas above the belt's centre line, the layout of pinarms.studies.delta_line."),
        flag("--package", "packages", multiple=True, metavar="NAME=FOLDER",
             help="A folder for package://NAME/ in --robot's file (repeatable; the belt needs no meshes)."),
        flag("--tcp", "tcp", default=None, metavar="LINK",
             help="The link of --robot whose frame is the tool point (default: a link 'tcp', else the last link)."),
        flag("--tcp-offset", "tcp_offset", default=None, metavar="X,Y,Z",
             help="The tool point's offset from --tcp's link, in that link's frame [m]."),
        flag("--tool-axis", "tool_axis", type=click.Choice(list(TOOL_AXES)), default="z", show_default=True,
             help="The axis of the tool point's link the tool points along; the picks hold it vertical, "
                  "pointing down (tool down = the tcp z axis down)."),
        flag("--base-offset", type=float, default=0.4, show_default=True,
             help="--robot: the arms' bases from the belt's centre line, across [m]."),
        flag("--box", "box", default="-0.1,0.25,0.15", show_default=True, metavar="DX,DY,DZ",
             help="--robot: each arm's box from its base [m] (world x along the belt, y across, z up)."),
        flag("--base-height", type=float, default=0.0, show_default=True,
             help="--robot: the arms' bases above the belt's surface [m] (negative: below)."),
        flag("--spacing", type=float, default=1.0, show_default=True, help="--robot: distance between arms [m]."),
        flag("--descend", type=float, default=0.5, show_default=True,
             help="--robot: seconds of the tracking pick's descend (and lift); longer for a slow arm."),
        flag("--map-grid", default="12,5", show_default=True, metavar="NU,NW",
             help="--robot: task map nodes along the belt (over the arm's whole reach) and across it; a "
                  "cell is feasible where its four nodes are, so a coarse grid may leave none."),
    )

    def __post_init__(self) -> None:
        given = [f"--{k.replace('_', '-')}" for k in ("packages", "tcp", "tcp_offset") if getattr(self, k)]
        flag_name = (given or ["--tool-axis"])[0].replace("--packages", "--package")
        if self.robot_urdf is None and (given or self.tool_axis != "z"):
            raise InvalidInput(f"{flag_name} describes the arm of --robot URDF: give --robot, or drop {flag_name}")

    def resolve(self) -> dict | None:
        """``None`` without ``--robot``; a shipped delta: ``{"delta": name, "map_grid": ...}``; else the loaded arm
        (:func:`load_belt_robot`) with the layout's values checked (``box``, ``map_grid``)."""
        if self.robot_urdf is None:
            return None
        from pinarms.robots.delta import delta_names

        if self.robot_urdf in delta_names():  # a shipped delta, above the belt (pinarms.studies.delta_line)
            given = [f"--{k.replace('_', '-')}" for k in ("packages", "tcp", "tcp_offset") if getattr(self, k)]
            if given or self.tool_axis != "z":
                flag_name = (given or ["--tool-axis"])[0].replace("--packages", "--package")
                raise InvalidInput(f"{flag_name} describes a URDF arm; --robot {self.robot_urdf} is a shipped delta: "
                                   f"drop {flag_name}")
            return {"delta": self.robot_urdf, "map_grid": grid_value(self.map_grid)}
        robot = load_belt_robot(self.robot_urdf, self.packages, self.tcp, self.tcp_offset, self.tool_axis)
        return {"robot": robot, "base_offset": self.base_offset, "base_height": self.base_height,
                "box": box_value(self.box), "spacing": self.spacing, "descend": self.descend,
                "map_grid": grid_value(self.map_grid)}


def _tool_point_text(text: str, link: str, xyz: np.ndarray, rpy: tuple[float, float, float], source: str) -> str:
    """The URDF ``text`` with a link :data:`TOOL_LINK` fixed to ``link`` at ``xyz`` [m], ``rpy`` [rad]."""
    try:
        root = ET.fromstring(text)
    except ET.ParseError as exc:
        raise InvalidInput(f"--robot {source} is not well-formed XML: {exc}") from None
    links = [el.get("name") for el in root.findall("link")]
    if link not in links:
        raise InvalidInput(f"--tcp {link!r} is not a link of {source}; its links: {', '.join(map(str, links[:40]))}")
    if TOOL_LINK in links:
        raise InvalidInput(f"--robot {source} already has a link {TOOL_LINK!r}: rename it to use --tcp-offset or "
                           "--tool-axis")
    ET.SubElement(root, "link", {"name": TOOL_LINK})
    joint = ET.SubElement(root, "joint", {"name": TOOL_LINK + "_joint", "type": "fixed"})
    ET.SubElement(joint, "parent", {"link": link})
    ET.SubElement(joint, "child", {"link": TOOL_LINK})
    ET.SubElement(joint, "origin", {"xyz": " ".join(repr(float(v)) for v in xyz),
                                    "rpy": " ".join(repr(float(v)) for v in rpy)})
    return ET.tostring(root, encoding="unicode")


def load_belt_robot(urdf: str, packages: tuple[str, ...], tcp: str | None, tcp_offset: str | None,
                    tool_axis: str) -> Any:
    """The ``--robot`` arm with its tool point (module doc).

    Raises:
        InvalidInput: a flag's value that does not fit the file (names the flag).
    """
    from pinarms import robots
    from pinarms.files import read_bounded_text
    from pinarms.robots.registry import MAX_URDF_BYTES

    pkgs = package_map(packages)
    path = Path(urdf)
    dirs = (str(path.parent), *(str(Path(d).parent) for d in pkgs.values()), *pkgs.values())
    xyz = np.zeros(3) if tcp_offset is None else floats(tcp_offset, "--tcp-offset")
    if xyz.shape != (3,) or not np.all(np.isfinite(xyz)):
        raise InvalidInput(f"--tcp-offset must be three finite numbers X,Y,Z [m], got {tcp_offset!r}")
    turned = tcp_offset is not None or tool_axis != "z"
    try:
        if not turned:
            robot = robots.from_urdf(path, tcp=tcp, package_dirs=dirs)
        else:
            text = read_bounded_text(path, MAX_URDF_BYTES, "URDF file")
            base = tcp or robots.from_urdf_text(text, source=str(path)).tcp_frame  # the link the tcp would be
            robot = robots.from_urdf_text(_tool_point_text(text, base, xyz, TOOL_AXES[tool_axis], str(path)),
                                          tcp=TOOL_LINK, source=str(path), urdf_path=path, package_dirs=dirs)
        robot.tcp_frame  # a --tcp the file does not have: said here, not at the first pick
    except InvalidInput:
        raise
    except PinarmsError as exc:
        flag = "--tcp" if tcp and "tcp" in str(exc) else "--robot"
        raise InvalidInput(f"{flag}: {' '.join(str(exc).split())}") from None
    return robot


def box_value(text: str) -> tuple[float, float, float]:
    """``--box DX,DY,DZ`` as three finite numbers [m] (else InvalidInput naming the flag)."""
    try:
        values = tuple(float(p) for p in text.split(","))
    except ValueError:
        values = ()
    if len(values) != 3 or not all(np.isfinite(values)):
        raise InvalidInput(f"--box must be three finite numbers DX,DY,DZ [m], got {text!r}")
    return values  # type: ignore[return-value]


def grid_value(text: str) -> tuple[int, int]:
    """``--map-grid NU,NW`` as two integers >= 2 (else InvalidInput naming the flag)."""
    parts = [p.strip() for p in text.split(",")]
    try:
        nu, nw = (int(p) for p in parts)
    except ValueError:
        raise InvalidInput(f"--map-grid must be two integers NU,NW (>= 2), got {text!r}") from None
    if nu < 2 or nw < 2 or nu * nw > 10_000:
        raise InvalidInput(f"--map-grid must be two integers NU,NW, each >= 2, at most 10000 nodes, got {text!r}")
    return nu, nw
