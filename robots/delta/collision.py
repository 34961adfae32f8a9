"""Collision geometry of a delta: upper arms, the six rods, the platform and the tool, and the clearance to a fixture.

The mid-line forearm of the tree (``leg{i}_forearm``, docs/delta.md) is not a physical body: two
rods ``rod_spacing`` apart run on either side of it, and an object between them touches neither.
The bodies here are therefore the real parts, placed from the closed form at motor angles
``theta``: each upper arm a capsule from its motor axis to its elbow
(:func:`~.kinematics.elbow_positions`), each rod a capsule between its ball centres
(:func:`~.rods.rod_endpoints`), the platform a disk at the closed-form position
(:func:`~.kinematics.forward_position`), the tool a capsule from the platform centre to the tcp.
Radii and thickness are :data:`PART_RADII` (assumed: a 50 mm carbon upper arm, 16 mm rods, a
20 mm platform plate). Distances by coal (Pinocchio's collision library).
"""

from __future__ import annotations

from dataclasses import dataclass

import coal
import numpy as np

from pinarms.robots.delta.errors import DeltaInputError
from pinarms.robots.delta.kinematics import elbow_positions, forward_position
from pinarms.robots.delta.model import DeltaRobot
from pinarms.robots.delta.rods import rod_endpoints

__all__ = ["PART_RADII", "PLATFORM_THICKNESS", "DeltaBody", "collision_bodies", "fixture_clearance"]

#: Radius [m] of each kind of part.
PART_RADII = {"upper_arm": 0.025, "rod": 0.008, "tool": 0.01}
#: Thickness [m] of the platform's plate (its radius: platform radius + half the rod spacing).
PLATFORM_THICKNESS = 0.02


@dataclass(frozen=True)
class DeltaBody:
    """One collision body: ``name`` (``upper_arm_<i>``, ``rod_<i><a|b>``, ``platform``, ``tool``),
    its coal ``shape`` and its pose ``base_to_body`` (4, 4) in the delta's base frame."""

    name: str
    shape: object
    base_to_body: np.ndarray


def _along(p0: np.ndarray, p1: np.ndarray) -> np.ndarray:
    """(4, 4) at the middle of p0 → p1 whose z axis runs along it (coal's capsules and cylinders)."""
    z = (p1 - p0) / np.linalg.norm(p1 - p0)
    helper = np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = np.cross(helper, z)
    x /= np.linalg.norm(x)
    T = np.eye(4)
    T[:3, 0], T[:3, 1], T[:3, 2], T[:3, 3] = x, np.cross(z, x), z, 0.5 * (p0 + p1)
    return T


def collision_bodies(delta: DeltaRobot, theta) -> list[DeltaBody]:
    """The delta's bodies at motor angles ``theta`` (3,) [rad] (module doc).

    Raises:
        DeltaInputError: ``theta`` not three finite angles."""
    th = np.asarray(theta, dtype=float)
    if th.shape != (3,) or not np.all(np.isfinite(th)):
        raise DeltaInputError(f"theta must be three finite motor angles [rad], got {np.asarray(theta).tolist()!r}")
    g = delta.geometry
    elbows = elbow_positions(g, th)
    rods = rod_endpoints(delta, delta.configuration(th))
    p = forward_position(g, th)
    tcp = delta.tcp_position(delta.configuration(th))
    out = []
    for i in range(3):
        motor = g.base_radius * g.radial[i]
        out.append(DeltaBody(f"upper_arm_{i + 1}", coal.Capsule(PART_RADII["upper_arm"], g.upper_arm),
                             _along(motor, elbows[i])))
        for r, tag in enumerate("ab"):
            a, b = rods[i, r, 0], rods[i, r, 1]
            out.append(DeltaBody(f"rod_{i + 1}{tag}", coal.Capsule(PART_RADII["rod"], float(np.linalg.norm(b - a))),
                                 _along(a, b)))
    plate = np.eye(4)
    plate[:3, 3] = p
    out.append(DeltaBody("platform", coal.Cylinder(g.platform_radius + 0.5 * g.rod_spacing, PLATFORM_THICKNESS), plate))
    if np.linalg.norm(tcp - p) > 1e-9:
        out.append(DeltaBody("tool", coal.Capsule(PART_RADII["tool"], float(np.linalg.norm(tcp - p))), _along(p, tcp)))
    return out


def _tf(T: np.ndarray) -> coal.Transform3s:
    return coal.Transform3s(np.ascontiguousarray(T[:3, :3]), np.ascontiguousarray(T[:3, 3]))


def fixture_clearance(delta: DeltaRobot, theta, fixture: object, base_to_fixture) -> tuple[float, str]:
    """(distance [m], nearest body's name) from the delta at ``theta`` to a coal ``fixture`` shape at
    ``base_to_fixture`` (4, 4) in the delta's base frame; ≤ 0 where they touch."""
    T = np.asarray(base_to_fixture, dtype=float)
    best, name = np.inf, ""
    for body in collision_bodies(delta, theta):
        res = coal.DistanceResult()
        d = coal.distance(body.shape, _tf(body.base_to_body), fixture, _tf(T), coal.DistanceRequest(), res)
        if d < best:
            best, name = float(d), body.name
    return best, name
