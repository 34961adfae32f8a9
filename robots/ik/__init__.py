"""Inverse kinematics: closed forms per arm family and a numerical solver for any URDF.

- :class:`URTypeIK` (UR3/5/10, AUBO-i3), :class:`ScaraIK`, :class:`GantryIK`,
  :class:`KojiIK`: every solution within the joint limits, batched over targets.
- :class:`NumericalIK`: damped least squares on Pinocchio's SE(3) log error with joint
  limits and seeded random restarts, for any arm (mimic joints and 7-DoF included).
- :func:`near_limit_solutions`: closed-form solutions a little outside the joint ranges,
  and by how much (to tell users; ``limit_tolerance=`` accepts them).

Every robot loaded by :mod:`pinarms.robots.registry` (``load``, ``from_urdf``, ``from_urdf_text``,
``from_xacro``) and every arm of a cell gets the closed form of its family when its
kinematic structure matches one (:func:`recognise`, by geometry, proven by FK round trips
at load); ``robot.ik_family`` says which. Users normally call :meth:`pinarms.robots.Robot.ik_all`
and :meth:`pinarms.robots.Robot.ik`.
"""

from __future__ import annotations

from pinarms.robots.ik.families import FAMILIES
from pinarms.robots.ik.gantry import GantryIK
from pinarms.robots.ik.koji import KojiIK
from pinarms.robots.ik.near_limits import OutsideLimits, limit_excess, near_limit_solutions
from pinarms.robots.ik.numerical import IKResult, NumericalIK
from pinarms.robots.ik.recognise import Recognition, recognise
from pinarms.robots.ik.scara import ScaraIK
from pinarms.robots.ik.solver import FK_TOL, LIMIT_TOL, AnalyticIK
from pinarms.robots.ik.ur_type import URTypeIK

__all__ = [
    "attach_analytic_ik",
    "analytic_solver",
    "recognise",
    "Recognition",
    "FAMILIES",
    "FAMILY_OF",
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

#: Family of each registry robot that has a closed form (koji_turner_rail is redundant: numerical
#: only). Kept for reference and for callers that look a family up by name; robots get their
#: family by :func:`recognise`, never from this table.
FAMILY_OF = {
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
    from pinarms.errors import InvalidInput

    if family not in FAMILIES:
        raise InvalidInput(f"unknown IK family {family!r}; known: {', '.join(FAMILIES)}")
    return FAMILIES[family](robot, frame)


def attach_analytic_ik(robot, family: str | None = None) -> str | None:
    """Give ``robot`` the closed-form solver of its family; return the family's key (or ``None``).

    Without ``family`` the family is recognised from the robot's kinematic structure and
    proven by FK round trips (:func:`recognise`); a robot that matches none keeps
    ``robot.analytic_ik`` ``None`` (numerical IK only). With ``family`` that solver is built
    (and proven) or an error is raised.

    Raises:
        InvalidInput: unknown ``family``.
        ModelError: ``family`` is given and the robot's model lacks its structure.
    """
    if family is None:
        found = recognise(robot)
        robot.set_analytic_ik(found.solver, rejected=found.rejected, recognised=True)  # again if the tcp changes
        return found.family
    robot.set_analytic_ik(analytic_solver(robot, family))
    return family
