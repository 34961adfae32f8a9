"""Inverse kinematics: closed forms per arm family and a numerical solver for any URDF."""

from __future__ import annotations

__all__ = ["attach_analytic_ik"]


def attach_analytic_ik(robot) -> None:
    """Give ``robot`` the closed-form solver of its arm family, if pinarms has one."""
    robot._analytic_ik = None
