"""Units: SI inside, degrees and millimetres at the edges; the one units module.

pinarms works in SI (m, rad, s) everywhere. The CLI accepts ``--deg`` (revolute joint
values and roll/pitch/yaw in degrees) and ``--mm`` (prismatic joint values and Cartesian
positions in millimetres), the papers print mm and degrees: this module is the one place
that converts. Part of the floor every package may import (with :mod:`pinarms.execution`
and :mod:`pinarms.files`): it imports nothing of pinarms but the error classes (a robot is
read through its ``nq`` and ``model`` only).
"""

from __future__ import annotations

from typing import Any, Protocol

import numpy as np
from numpy.typing import ArrayLike

from pinarms.errors import InvalidInput

__all__ = ["JointModel", "as_float_array", "deg_to_rad", "rad_to_deg", "mm_to_m", "m_to_mm", "wrap_angle", "prismatic_mask", "joints_to_si",
           "joints_from_si", "length_scale", "angle_scale", "mass_kg", "parse_length", "parse_angle"]


class JointModel(Protocol):
    """What the joint-unit helpers read of a robot: its number of independent joints and its Pinocchio model
    (a :class:`pinarms.robots.Robot` has both)."""

    @property
    def nq(self) -> int: ...

    @property
    def model(self) -> Any: ...


def as_float_array(x: ArrayLike, what: str) -> np.ndarray:
    """``x`` as a float64 array; ``what`` names it in the error.

    Raises:
        InvalidInput: ``x`` is not numeric.
    """
    try:
        return np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InvalidInput(f"{what} must be numeric (a number or an array of numbers), got {x!r}") from exc


def deg_to_rad(angle_deg) -> np.ndarray:
    """Degrees → radians, element-wise (any shape)."""
    return np.deg2rad(as_float_array(angle_deg, "angle_deg"))


def rad_to_deg(angle_rad) -> np.ndarray:
    """Radians → degrees, element-wise (any shape)."""
    return np.rad2deg(as_float_array(angle_rad, "angle_rad"))


def mm_to_m(length_mm) -> np.ndarray:
    """Millimetres → metres, element-wise (any shape)."""
    return as_float_array(length_mm, "length_mm") * 1e-3


def m_to_mm(length_m) -> np.ndarray:
    """Metres → millimetres, element-wise (any shape)."""
    return as_float_array(length_m, "length_m") * 1e3


def wrap_angle(angle_rad) -> np.ndarray:
    """Wrap angles (rad) to [−π, π), element-wise."""
    a = as_float_array(angle_rad, "angle_rad")
    return (a + np.pi) % (2.0 * np.pi) - np.pi


def prismatic_mask(robot: JointModel) -> np.ndarray:
    """``(nq,)`` bool: True where the independent joint is prismatic (metres), else revolute (rad)."""
    mask = np.zeros(robot.nq, dtype=bool)
    model = robot.model
    for i in range(1, model.njoints):
        joint = model.joints[i]
        short = joint.shortname()
        if "Mimic" in short or joint.nv == 0:
            continue
        if short.startswith("JointModelP") and not short.startswith("JointModelPlanar"):
            mask[joint.idx_v] = True
    return mask


def length_scale(mm: bool) -> float:
    """Metres per user length unit."""
    return 1e-3 if mm else 1.0


def angle_scale(deg: bool) -> float:
    """Radians per user angle unit."""
    return np.pi / 180.0 if deg else 1.0


def joints_to_si(robot: JointModel, values: np.ndarray, *, deg: bool, mm: bool) -> np.ndarray:
    """User joint values (deg/rad for revolute, mm/m for prismatic) → SI, shape kept."""
    scale = np.where(prismatic_mask(robot), length_scale(mm), angle_scale(deg))
    return np.asarray(values, dtype=float) * scale


def joints_from_si(robot: JointModel, values: np.ndarray, *, deg: bool, mm: bool) -> np.ndarray:
    """SI joint values → user units (inverse of :func:`joints_to_si`)."""
    scale = np.where(prismatic_mask(robot), length_scale(mm), angle_scale(deg))
    return np.asarray(values, dtype=float) / scale


_MASS_UNITS = {"kg": 1.0, "g": 1e-3}


def mass_kg(text: str) -> float:
    """A mass given at the command line (``"3kg"``, ``"1.5 kg"``, ``"800g"``, or a bare number of kg) → kg.

    Raises:
        pinarms.errors.InvalidInput: not a finite number with an optional ``kg``/``g`` unit, or negative.
    """
    raw = str(text).strip().lower()
    factor = 1.0
    for unit in ("kg", "g"):
        if raw.endswith(unit):
            raw, factor = raw[: -len(unit)].strip(), _MASS_UNITS[unit]
            break
    try:
        value = float(raw) * factor
    except ValueError:
        raise InvalidInput(f"a mass must be a number of kg with an optional unit (3kg, 1.5 kg, 800g), got {text!r}") from None
    if not np.isfinite(value) or value < 0.0:
        raise InvalidInput(f"a mass must be finite and >= 0 kg, got {text!r}")
    return value


_LENGTH_UNITS = {"m": 1.0, "cm": 1e-2, "mm": 1e-3}
_ANGLE_UNITS = {"rad": 1.0, "deg": np.pi / 180.0, "°": np.pi / 180.0}


def _quantity(text: str, units: dict, default_unit: str, what: str) -> float:
    import re

    match = re.fullmatch(r"\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*([a-z°]*)\s*", str(text))
    if not match or (match.group(2) and match.group(2) not in units):
        raise InvalidInput(f"{what} must be a number with an optional unit ({', '.join(units)}), got {text!r}")
    return float(match.group(1)) * units[match.group(2) or default_unit]


def parse_length(text: str, what: str = "length") -> float:
    """``"0.025"``, ``"25mm"``, ``"2.5cm"`` → metres (a bare number is in metres)."""
    return _quantity(text, _LENGTH_UNITS, "m", what)


def parse_angle(text: str, what: str = "angle") -> float:
    """``"15deg"``, ``"15°"``, ``"0.26rad"`` → radians (a bare number is in degrees)."""
    return _quantity(text, _ANGLE_UNITS, "deg", what)
