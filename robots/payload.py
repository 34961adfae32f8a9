"""A payload: a rigid body fixed to a frame of an arm, and the robot that carries it.

A :class:`Payload` has a mass [kg], a centre of mass [m] in its frame (default the tcp) and
an inertia tensor [kg·m²] about the centre of mass in that frame's axes; checked as a rigid
body's (symmetric, positive semi-definite, triangle inequalities). :func:`with_payload` gives
a copy of the robot whose body holding the frame carries it (the torques of
:mod:`.dynamics` then include it).
"""

from __future__ import annotations

import copy
from dataclasses import dataclass
from typing import Any, Mapping

import numpy as np
from numpy.typing import ArrayLike
import pinocchio as pin

from pinarms.errors import InvalidInput
from pinarms.robots.robot_model import RobotModel

__all__ = ["Payload", "InvalidPayload", "as_payload", "with_payload"]

#: Relative tolerance of the inertia checks (symmetry, positive semi-definiteness, triangle inequalities).
_INERTIA_RTOL = 1e-9


class InvalidPayload(InvalidInput):
    """A payload has a negative mass, a non-finite entry or an inertia tensor no rigid body has."""


@dataclass(frozen=True, eq=False)
class Payload:
    """A rigid payload fixed to a frame of the arm (a gripped food pack, a tray, a koji block).

    Attributes:
        mass: mass [kg], ``>= 0``.
        com: centre of mass (3,) [m] in ``frame`` (default: at the frame's origin).
        inertia: inertia tensor (3, 3) [kg·m²] about the centre of mass, in ``frame``'s axes;
            symmetric, positive semi-definite and obeying the triangle inequalities
            (``Ixx + Iyy >= Izz`` and permutations) like every rigid body's. Default zero:
            a point mass.
        frame: the arm's frame the payload is fixed to (``"tcp"``: the robot's tcp frame).

    Raises:
        InvalidPayload: negative or non-finite mass, a ``com`` that is not 3 finite numbers,
            an inertia that is not (3, 3) / (3,) principal moments, not symmetric, not positive
            semi-definite or violating a triangle inequality, or an inertia without a mass.
    """

    mass: float
    com: Any = (0.0, 0.0, 0.0)
    inertia: Any = None
    frame: str = "tcp"

    def __post_init__(self) -> None:
        ok = isinstance(self.mass, (int, float, np.integer, np.floating)) and not isinstance(self.mass, bool)
        mass = float(self.mass) if ok else float("nan")
        if not np.isfinite(mass):
            raise InvalidPayload(f"payload mass must be a finite number of kg, got {self.mass!r}")
        if mass < 0.0:
            raise InvalidPayload(f"payload mass must be >= 0 kg, got {mass!r} kg: a negative mass is no payload")
        try:
            com = np.array(self.com, dtype=float)
        except (TypeError, ValueError) as exc:
            raise InvalidPayload(f"payload com must be 3 numbers (m), got {self.com!r}") from exc
        if com.shape != (3,) or not np.all(np.isfinite(com)):
            raise InvalidPayload(f"payload com must be 3 finite numbers (m) in frame {self.frame!r}, got {self.com!r}")
        inertia = _check_inertia(self.inertia, mass)
        if not isinstance(self.frame, str) or not self.frame:
            raise InvalidPayload(f"payload frame must be a frame name, got {self.frame!r}")
        com.setflags(write=False)
        inertia.setflags(write=False)
        object.__setattr__(self, "mass", mass)
        object.__setattr__(self, "com", com)
        object.__setattr__(self, "inertia", inertia)

    def spatial_inertia(self) -> pin.Inertia:
        """The payload as a Pinocchio spatial inertia in ``frame``."""
        return pin.Inertia(self.mass, self.com.copy(), self.inertia.copy())

    def as_dict(self) -> dict[str, Any]:
        """JSON-able form: ``mass_kg``, ``com_m``, ``inertia_kg_m2`` (3×3 rows), ``frame``."""
        return {
            "mass_kg": self.mass,
            "com_m": self.com.tolist(),
            "inertia_kg_m2": self.inertia.tolist(),
            "frame": self.frame,
        }

    @classmethod
    def from_dict(cls, data: object) -> "Payload":
        """Inverse of :meth:`as_dict` (checked like the constructor).

        Raises:
            InvalidPayload: not a mapping with ``mass_kg`` (and optionally ``com_m``,
                ``inertia_kg_m2``, ``frame``), or bad values.
        """
        if not isinstance(data, dict) or "mass_kg" not in data:
            raise InvalidPayload(f"a payload must be a mapping with mass_kg, com_m, inertia_kg_m2, frame; got {data!r}")
        unknown = sorted(set(data) - {"mass_kg", "com_m", "inertia_kg_m2", "frame"})
        if unknown:
            raise InvalidPayload(f"unknown payload field(s) {unknown}; expected mass_kg, com_m, inertia_kg_m2, frame")
        return cls(
            data["mass_kg"],
            com=data.get("com_m", (0.0, 0.0, 0.0)),
            inertia=data.get("inertia_kg_m2"),
            frame=data.get("frame", "tcp"),
        )

    def __repr__(self) -> str:
        return f"Payload(mass={self.mass:g} kg, com={self.com.tolist()} m, frame={self.frame!r})"


def _check_inertia(value: Any, mass: float) -> np.ndarray:
    """A physically consistent inertia tensor (3, 3) [kg·m²] about the centre of mass."""
    if value is None:
        return np.zeros((3, 3))
    try:
        arr = np.array(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InvalidPayload(f"payload inertia must be a (3, 3) tensor or (3,) principal moments in kg·m², got {value!r}") from exc
    if arr.shape == (3,):
        arr = np.diag(arr)
    if arr.shape != (3, 3):
        raise InvalidPayload(f"payload inertia must be a (3, 3) tensor or (3,) principal moments in kg·m², got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise InvalidPayload("payload inertia holds NaN or inf")
    scale = max(float(np.abs(arr).max()), 1e-300)
    asym = float(np.abs(arr - arr.T).max())
    if asym > _INERTIA_RTOL * scale:
        i, j = np.unravel_index(int(np.argmax(np.abs(arr - arr.T))), arr.shape)
        raise InvalidPayload(
            f"payload inertia is not symmetric: I[{i},{j}] = {arr[i, j]:.6g} but I[{j},{i}] = {arr[j, i]:.6g} kg·m²; "
            "an inertia tensor is symmetric (give the products of inertia once, on both sides)"
        )
    arr = 0.5 * (arr + arr.T)
    if not np.any(arr):
        return arr
    if mass == 0.0:
        raise InvalidPayload("payload inertia is non-zero but its mass is 0 kg: give the mass too")
    moments = np.linalg.eigvalsh(arr)
    if moments[0] < -_INERTIA_RTOL * scale:
        raise InvalidPayload(
            f"payload inertia is not positive semi-definite (principal moments {np.round(moments, 12).tolist()} kg·m²): "
            "no rigid body has a negative moment of inertia"
        )
    a, b, c = np.sort(moments)
    if a + b < c * (1.0 - _INERTIA_RTOL) - _INERTIA_RTOL * scale:
        raise InvalidPayload(
            f"payload inertia violates the triangle inequality: principal moments {a:.6g} + {b:.6g} < {c:.6g} kg·m² "
            "(for any rigid body each moment is at most the sum of the other two)"
        )
    return arr


def as_payload(payload: Payload | float | Mapping[str, object] | None, *, com: ArrayLike | None = None, inertia: ArrayLike | None = None, frame: str | None = None) -> Payload | None:
    """A :class:`Payload` from a mass [kg], a Payload, its dict form, or ``None`` (no payload).

    ``com``, ``inertia`` and ``frame`` apply when ``payload`` is a mass.
    """
    if payload is None:
        return None
    if isinstance(payload, Payload):
        if com is not None or inertia is not None or frame is not None:
            raise InvalidPayload("give com, inertia and frame in the Payload itself, not beside it")
        return payload
    if isinstance(payload, dict):
        return Payload.from_dict(payload)
    return Payload(
        payload,
        com=(0.0, 0.0, 0.0) if com is None else com,
        inertia=inertia,
        frame="tcp" if frame is None else frame,
    )



def with_payload(robot: RobotModel, mass: Payload | float, com: ArrayLike | None = None, inertia: ArrayLike | None = None, frame: str | None = None) -> Any:
    """A copy of ``robot`` carrying a payload; ``robot`` itself is unchanged.

    A payload replaces the one ``robot`` already carries (payloads do not stack); ``mass=0``
    with no inertia gives the bare arm back. The kinematics (frames, limits, IK) are the
    robot's own; only the inertia of the body holding ``frame`` changes.

    Args:
        mass: payload mass [kg] (or a :class:`Payload` / its dict form).
        com: centre of mass (3,) [m] in ``frame`` (default its origin).
        inertia: (3, 3) tensor or (3,) principal moments [kg·m²] about the centre of mass
            (default a point mass).
        frame: frame the payload is fixed to (default ``"tcp"``).

    Raises:
        InvalidPayload: see :class:`Payload`.
        InvalidInput: ``robot`` has no frame ``frame``.
    """
    load = as_payload(mass, com=com, inertia=inertia, frame=frame)
    base_model = getattr(robot, "_model_without_payload", None)
    if base_model is None:
        base_model = robot.model
    model = pin.Model(base_model)
    if load is not None and (load.mass > 0.0):
        fid = robot.frame_id(load.frame)
        f = base_model.frames[fid]
        jid = f.parentJoint
        if jid == 0:
            raise InvalidPayload(
                f"frame {load.frame!r} of robot '{robot.name}' is fixed to the base: a payload there moves no joint"
            )
        model.inertias[jid] = model.inertias[jid] + f.placement.act(load.spatial_inertia())
    else:
        load = None
    new = copy.copy(robot)
    new.model = model
    new._model_without_payload = base_model
    new.payload = load
    new.__dict__.pop("_numerical_ik_solver", None)
    return new
