"""The closed-form solver class of each arm family, by family name.

Its own module so that :func:`pinarms.robots.ik.recognise` and the package's
:func:`pinarms.robots.ik.analytic_solver` read the same table without importing each other.
"""

from __future__ import annotations

from pinarms.robots.ik.gantry import GantryIK
from pinarms.robots.ik.koji import KojiIK
from pinarms.robots.ik.scara import ScaraIK
from pinarms.robots.ik.solver import AnalyticIK
from pinarms.robots.ik.ur_type import URTypeIK

__all__ = ["FAMILIES"]

#: Closed-form solver classes by family name.
FAMILIES: dict[str, type[AnalyticIK]] = {
    "ur_type": URTypeIK,
    "scara": ScaraIK,
    "gantry": GantryIK,
    "koji": KojiIK,
}
