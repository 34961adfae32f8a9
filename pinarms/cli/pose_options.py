"""Pose options of the commands that take tcp poses (``line``, ``motion``): ``--from X Y Z [R P Y]``."""

from __future__ import annotations

import click
import numpy as np

from pinarms.errors import InvalidInput
from pinarms.units import angle_scale, length_scale

from pinarms.cli._common import PinarmsCommand, floats

__all__ = ["POSE_OPTIONS", "PoseCommand", "parse_pose"]

#: Options that take a pose: X Y Z, optionally followed by ROLL PITCH YAW.
POSE_OPTIONS = ("--from", "--to", "--via")


class PoseCommand(PinarmsCommand):
    """A command whose pose options take 3 or 6 numbers (``--from X Y Z [R P Y]``).

    Before click parses, the numbers following a pose option are joined into one value
    (as many as parse as numbers, up to six), so negative numbers and an optional
    orientation both work.
    """

    def parse_args(self, ctx: click.Context, args: list[str]) -> list[str]:
        out: list[str] = []
        i = 0
        while i < len(args):
            token = args[i]
            out.append(token)
            i += 1
            if token in POSE_OPTIONS:
                numbers = []
                while i < len(args) and len(numbers) < 6 and _is_number(args[i]):
                    numbers.append(args[i])
                    i += 1
                out.append(" ".join(numbers))
        return super().parse_args(ctx, out)


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def parse_pose(text: str, what: str, mm: bool, deg: bool, orientation: np.ndarray) -> np.ndarray:
    """'X Y Z [R P Y]' in user units → a tcp → base pose (4, 4) [m]; no R P Y: ``orientation``."""
    import pinocchio as pin

    values = floats(text.replace(" ", ","), what) if text.strip() else np.zeros(0)
    if values.size not in (3, 6):
        raise InvalidInput(f"{what} takes X Y Z or X Y Z ROLL PITCH YAW (3 or 6 numbers), got {values.size}")
    T = np.eye(4)
    T[:3, 3] = values[:3] * length_scale(mm)
    T[:3, :3] = pin.rpy.rpyToMatrix(*(values[3:] * angle_scale(deg))) if values.size == 6 else orientation
    return T
