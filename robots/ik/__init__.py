"""Inverse kinematics: closed forms per arm family and a numerical solver for any URDF.

- :class:`URTypeIK` (UR3/5/10, AUBO-i3), :class:`ScaraIK`, :class:`GantryIK`,
  :class:`KojiIK`: every solution within the joint limits, batched over targets.
- :class:`NumericalIK`: damped least squares on Pinocchio's SE(3) log error with joint
  limits and seeded random restarts, for any arm (mimic joints and 7-DoF included).
- :func:`near_limit_solutions`: closed-form solutions a little outside the joint ranges,
  and by how much (to tell users; ``limit_tolerance=`` accepts them).

Users normally call :meth:`robots.Robot.ik_all` and :meth:`robots.Robot.ik`.
"""

from __future__ import annotations

from .gantry import GantryIK
from .koji import KojiIK
from .near_limits import OutsideLimits, limit_excess, near_limit_solutions
from .numerical import IKResult, NumericalIK
from .scara import ScaraIK
from .solver import FK_TOL, LIMIT_TOL, AnalyticIK
from .ur_type import URTypeIK

__all__ = [
    "attach_analytic_ik",
    "analytic_solver",
    "FAMILIES",
    "AnalyticIK",
    "URTypeIK",
    "ScaraIK",
    "GantryIK",
    "KojiIK",
    "NumericalIK",
    "IKResult",
    "OutsideLimits",
    "limit_excess",
    "near_limit_solutions",
    "FK_TOL",
    "LIMIT_TOL",
]

#: Closed-form solver classes by family name.
FAMILIES: dict[str, type[AnalyticIK]] = {
    "ur_type": URTypeIK,
    "scara": ScaraIK,
    "gantry": GantryIK,
    "koji": KojiIK,
}

#: Family of each registry robot that has a closed form (koji_turner_rail is redundant: numerical only).
_FAMILY_OF = {
    "scara_mushroom": "scara",
    "aubo_i3": "ur_type",
    "gantry_flower": "gantry",
    "koji_turner": "koji",
    "ur3": "ur_type",
    "ur5": "ur_type",
    "ur10": "ur_type",
}


def analytic_solver(robot, family: str, frame: str = "tcp") -> AnalyticIK:
    """Build the closed-form solver of ``family`` for ``robot`` (geometry read from its model).

    Raises:
        InvalidInput: unknown family.
        ModelError: the robot does not have the structure the family's solver assumes.
    """
    from ..errors import InvalidInput

    if family not in FAMILIES:
        raise InvalidInput(f"unknown IK family {family!r}; known: {', '.join(FAMILIES)}")
    return FAMILIES[family](robot, frame)


def attach_analytic_ik(robot, family: str | None = None) -> None:
    """Give ``robot`` the closed-form solver of its arm family (by registry name unless ``family`` is given).

    Robots without a known family keep ``robot._analytic_ik = None`` (numerical IK only).

    Raises:
        ModelError: the robot's model lacks the structure of its family.
    """
    family = family or _FAMILY_OF.get(robot.name)
    robot._analytic_ik = None if family is None else analytic_solver(robot, family)
