"""A cell's URDF with one arm's base moved: what layout searches try among fixed fixtures.

:meth:`Cell.with_arm_base <pinarms.robots.cell.Cell.with_arm_base>` builds the new cell from
the URDF :func:`urdf_with_arm_base` writes.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from typing import Any

import numpy as np
from numpy.typing import ArrayLike
import pinocchio as pin

from pinarms.errors import CellError, InvalidInput

from pinarms.robots.cell.cell_model import CellModel

__all__ = ["urdf_with_arm_base"]


def urdf_with_arm_base(cell: "CellModel", name: str, base_to_world: ArrayLike, carry: tuple[str, ...] = ()) -> str:
    """The URDF of ``cell`` with arm ``name``'s base at ``base_to_world`` ``(4, 4)`` [m] in the world.

    The fixed joint that holds the arm's base link to its parent gets the origin that puts
    the base there; its parent stays where it is. Fixtures named in ``carry`` keep their
    pose relative to the arm's base instead of the world.

    Raises:
        InvalidInput: unknown arm or fixture, or not a rigid transform.
        CellError: the arm's base (or a carried fixture) is not held by a fixed joint.
    """
    arm = cell.arm(name)
    T = np.asarray(base_to_world, dtype=float)
    if T.shape != (4, 4) or not np.all(np.isfinite(T)) or np.abs(T[:3, :3] @ T[:3, :3].T - np.eye(3)).max() > 1e-9 \
            or np.linalg.det(T[:3, :3]) < 0 or np.abs(T[3] - [0, 0, 0, 1]).max() > 1e-12:
        raise InvalidInput(f"base_to_world of arm {name!r} must be a rigid transform (4, 4), got {base_to_world!r}")
    spec = next(a for a in cell.spec.arms if a.name == arm.name)
    for fixture in carry:
        cell.fixture(fixture)  # InvalidInput for an unknown name
    root = ET.fromstring(cell.urdf_text)
    data = cell.model.createData()
    pin.framesForwardKinematics(cell.model, data, pin.neutral(cell.model))

    def world(link: str) -> np.ndarray:
        return data.oMf[cell.model.getFrameId(link)].homogeneous

    def place(link: str, link_to_world: np.ndarray) -> None:
        holder = next((j for j in root.iter("joint")
                       if j.find("child") is not None and j.find("child").get("link") == link), None)
        if holder is None or holder.get("type") != "fixed":
            raise CellError(f"link {link!r} of cell {cell.name!r} is not held by a fixed joint: cannot move it")
        origin = np.linalg.inv(world(holder.find("parent").get("link"))) @ link_to_world
        element = holder.find("origin")
        if element is None:
            element = ET.SubElement(holder, "origin")
        element.set("xyz", " ".join(repr(float(v)) for v in origin[:3, 3]))
        element.set("rpy", " ".join(repr(float(v)) for v in pin.rpy.matrixToRpy(origin[:3, :3])))

    moved = T @ np.linalg.inv(arm.base_to_world)
    for fixture in carry:
        place(fixture, moved @ world(fixture))
    place(spec.base_link, T)
    return ET.tostring(root, encoding="unicode")
