"""The dimensions of a three-legged delta, read from its Pinocchio model (one source: the xacro).

Conventions (docs/delta.md): base frame at the plane of the motor axes, z up; leg ``i`` at
azimuth ``phi_i`` (0, 120, 240 degrees), its radial unit vector ``e_i`` and motor-axis
direction ``u_i = z x e_i``; motor angle 0 = upper arm horizontal pointing outward, positive =
arm down. Elbow ``E_i = R e_i + L (cos t_i e_i - sin t_i z)``; the platform centre ``p``
satisfies ``|p + r e_i - E_i| = l`` for each leg.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from pinarms.robots.delta.errors import NotADelta

__all__ = ["DeltaGeometry", "LEG_COUNT", "motor_joint", "leg_frames"]

#: Legs of the family.
LEG_COUNT = 3
_TOL = 1e-9


def motor_joint(i: int) -> str:
    """Name of leg ``i``'s motor joint (``i`` = 1, 2, 3)."""
    return f"leg{i}_motor"


def leg_frames(i: int) -> dict[str, str]:
    """The frames the family's xacro names for leg ``i``: elbow, forearm's ball, platform's ball, rod ends."""
    return {"ball": f"leg{i}_ball", "platform_ball": f"platform_ball{i}", "top_a": f"leg{i}_rod_top_a",
            "top_b": f"leg{i}_rod_top_b", "bottom_a": f"platform_ball{i}_a", "bottom_b": f"platform_ball{i}_b"}


@dataclass(frozen=True)
class DeltaGeometry:
    """Dimensions of a delta [m, rad]: ``base_radius`` R, ``platform_radius`` r, ``upper_arm`` L,
    ``forearm`` l, ``rod_spacing`` h (width of each parallelogram), ``azimuths`` of the legs."""

    base_radius: float
    platform_radius: float
    upper_arm: float
    forearm: float
    rod_spacing: float
    azimuths: tuple[float, float, float]

    @property
    def radial(self) -> np.ndarray:
        """Radial unit vectors ``e_i`` of the legs, shape (3, 3) (row i = leg i+1)."""
        a = np.asarray(self.azimuths)
        return np.stack([np.cos(a), np.sin(a), np.zeros(3)], axis=1)

    @property
    def tangential(self) -> np.ndarray:
        """Motor-axis directions ``u_i = z x e_i``, shape (3, 3)."""
        a = np.asarray(self.azimuths)
        return np.stack([-np.sin(a), np.cos(a), np.zeros(3)], axis=1)

    @classmethod
    def from_model(cls, model: pin.Model) -> "DeltaGeometry":
        """Read the dimensions off a model built from the family's xacro.

        Raises:
            NotADelta: a joint or frame of the family is missing, or the legs differ.
        """
        def frame(name: str) -> pin.Frame:
            if not model.existFrame(name):
                raise NotADelta(f"model {model.name!r} has no frame {name!r}: it was not built by the delta macro "
                                "(robots/delta/xacro/delta.xacro)")
            return model.frames[model.getFrameId(name)]

        legs = []
        for i in range(1, LEG_COUNT + 1):
            if not model.existJointName(motor_joint(i)) or not model.existJointName(f"leg{i}_elbow_fold"):
                raise NotADelta(f"model {model.name!r} has no joint {motor_joint(i)!r} / 'leg{i}_elbow_fold'")
            motor = model.jointPlacements[model.getJointId(motor_joint(i))].translation
            elbow = model.jointPlacements[model.getJointId(f"leg{i}_elbow_fold")].translation
            ball = frame(f"leg{i}_ball").placement.translation
            pball = frame(f"platform_ball{i}").placement.translation
            top = frame(f"leg{i}_rod_top_a").placement.translation
            legs.append((np.hypot(motor[0], motor[1]), np.arctan2(motor[1], motor[0]), elbow[0], ball[0],
                         np.hypot(pball[0], pball[1]), 2.0 * top[1]))
        arr = np.array(legs)
        if np.ptp(arr[:, [0, 2, 3, 4, 5]], axis=0).max() > _TOL:
            raise NotADelta(f"model {model.name!r}: the three legs' dimensions differ ({arr[:, [0, 2, 3, 4, 5]]}); "
                            "the closed form needs identical legs")
        return cls(float(arr[0, 0]), float(arr[0, 4]), float(arr[0, 2]), float(arr[0, 3]), float(arr[0, 5]),
                   tuple(float(a) for a in arr[:, 1]))
