"""The deltas pinarms ships, by name, and loading a delta from a URDF and its closures file.

>>> from pinarms.robots.delta import load_delta
>>> delta = load_delta("delta_flexpicker")
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import pinocchio as pin

from pinarms.files import read_bounded_text

from pinarms.errors import ModelError, RobotNotFound
from pinarms.robots.registry import MAX_URDF_BYTES
from pinarms.robots.urdf_build import URDF_DIR
from pinarms.robots.urdf_checks import check_inertials, check_tree, refuse_dtd
from pinarms.robots.delta.closures import read_closures
from pinarms.robots.delta.errors import ClosuresFileError, DeltaInputError
from pinarms.robots.delta.model import DeltaRobot

__all__ = ["DeltaInfo", "delta_names", "delta_info", "load_delta", "delta_from_files", "XACRO_DIR"]

#: Folder of the family's xacro macro and the shipped deltas' sources.
XACRO_DIR = Path(__file__).resolve().parent / "xacro"


@dataclass(frozen=True)
class DeltaInfo:
    """A shipped delta: where its files are, where its numbers come from, what is assumed."""

    name: str
    description: str
    source: str            # the publication its geometry comes from
    assumed: str           # what is not published
    motor_acceleration: float  # arm-side limit of each motor [rad/s^2] (URDF has no field for it)

    @property
    def urdf_path(self) -> Path:
        return URDF_DIR / f"{self.name}.urdf"

    @property
    def closures_path(self) -> Path:
        return URDF_DIR / f"{self.name}.closures.xml"

    @property
    def xacro_path(self) -> Path:
        return XACRO_DIR / f"{self.name}.urdf.xacro"


_DELTAS = {d.name: d for d in (
    DeltaInfo(
        "delta_flexpicker",
        "three-legged delta with the ABB FlexPicker (IRB 360) geometry, fourth axis on the platform",
        "R. L. Williams II, 'The Delta Parallel Robot: Kinematics Solutions', Ohio University, 2015 "
        "(ABB FlexPicker IRB 360 example: sB = 567, sP = 76, L = 524, l = 1244, h = 131 mm)",
        "masses and inertias, motor range -40..80 deg, motor speed 10 rad/s, acceleration 150 rad/s^2, "
        "torque 120 N m (arm side), tool 0.2 kg at 0.05 m",
        150.0,
    ),
)}


def delta_names() -> list[str]:
    """Names :func:`load_delta` accepts."""
    return list(_DELTAS)


def delta_info(name: str) -> DeltaInfo:
    """Registry entry of a shipped delta; :class:`RobotNotFound` lists the known names."""
    if name not in _DELTAS:
        raise RobotNotFound(f"unknown delta {name!r}; shipped deltas: {', '.join(_DELTAS)} "
                            "(or robots.delta.delta_from_files(urdf, closures))")
    return _DELTAS[name]


def load_delta(name: str) -> DeltaRobot:
    """Load a shipped delta from its committed URDF and closures file (``urdf/<name>.urdf``, ``.closures.xml``)."""
    entry = delta_info(name)
    return delta_from_files(entry.urdf_path, entry.closures_path, acceleration=entry.motor_acceleration,
                            description=entry.description)


def delta_from_files(urdf: str | os.PathLike, closures: str | os.PathLike, *, acceleration: float,
                     description: str = "") -> DeltaRobot:
    """A :class:`DeltaRobot` from a URDF of the family's tree and its loop-closures file.

    Args:
        acceleration: arm-side acceleration limit of each motor [rad/s^2].

    Raises:
        ModelError: the URDF is missing, too large, not a URDF, or Pinocchio rejects it.
        ClosuresFileError: the closures file is bad, names another robot or frames the URDF lacks.
        NotADelta: the tree is not the family's.
    """
    if not (isinstance(acceleration, (int, float)) and acceleration > 0 and acceleration < float("inf")):
        raise DeltaInputError(f"acceleration must be a finite number > 0 rad/s^2, got {acceleration!r}")
    text = read_bounded_text(urdf, MAX_URDF_BYTES, "URDF file", error=ModelError)
    refuse_dtd(text, str(urdf))
    try:
        root = ET.fromstring(text)
    except ET.ParseError as exc:
        raise ModelError(f"{urdf} is not well-formed XML: {exc}") from None
    if root.tag != "robot":
        raise ModelError(f"{urdf} is not a URDF: its root element is <{root.tag}>, expected <robot>")
    check_tree(root, str(urdf))
    check_inertials(root, str(urdf))
    closure_set = read_closures(closures)
    if closure_set.robot != root.get("name"):
        raise ClosuresFileError(f"{closures} closes robot {closure_set.robot!r} but {urdf} is {root.get('name')!r}: "
                                "give the closures file of this URDF")
    try:
        model = pin.buildModelFromXML(text)
    except Exception as exc:  # Pinocchio raises RuntimeError/ValueError with its own message
        raise ModelError(f"Pinocchio cannot build a model from {urdf}: {exc}") from exc
    return DeltaRobot(model, closure_set, name=root.get("name"), acceleration=float(acceleration),
                      source=str(closures), description=description, urdf_text=text)
