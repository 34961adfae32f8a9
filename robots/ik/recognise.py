"""Which closed-form family an arm belongs to, told from its kinematic structure alone.

Names play no part: a family is recognised from the joints between the base and the tcp
as the loaded model gives them (joint types, ``<mimic>`` couplings, axis directions and
positions, the home pose), and proven on the robot by FK round trips.

For each family whose joint signature (how many independent revolute / prismatic joints,
how many mimics) fits, the family's solver is built: its constructor checks the geometry
the closed form assumes (parallel, intersecting or independent axes, parallelogram
couplings; :mod:`.geometry` tolerances) and then solves back the FK of
:data:`~.solver.PROOF_SAMPLES` seeded random configurations within the limits
(:meth:`~.solver.AnalyticIK._self_check`). The first family that passes is the robot's.

The solvers read every length from the model, so a recognised arm with its own lengths
(a 600 mm SCARA, a scaled UR) gets a closed form that is exact for it.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field

import numpy as np

from pinarms.errors import ModelError
from pinarms.robots.ik.families import FAMILIES
from pinarms.robots.ik.geometry import chain_axes
from pinarms.robots.ik.solver import AnalyticIK

__all__ = ["Recognition", "recognise"]


@dataclass(frozen=True)
class Recognition:
    """The outcome of :func:`recognise`.

    Attributes:
        family: key of the recognised family (``"scara"``, ``"ur_type"``, ``"gantry"``,
            ``"koji"``) or ``None``.
        solver: its closed-form solver (``None`` when no family matched).
        rejected: ``{family: reason}`` for every family whose joint signature fits but
            which was refused (the structure check or the FK proof that failed).
    """

    family: str | None
    solver: AnalyticIK | None
    rejected: dict[str, str] = field(default_factory=dict)


def _signature(robot, frame: str) -> tuple[Counter, int]:
    """Counts of independent revolute/prismatic joints and the number of mimics on the path to ``frame``."""
    axes = chain_axes(robot, frame).axes
    kinds = Counter(a.kind for a in axes if not a.is_mimic)
    return kinds, sum(a.is_mimic for a in axes)


#: Joint signature of each family: (independent revolute, independent prismatic, mimics) on the
#: path to the tcp, which must hold all of the robot's coordinates.
_SIGNATURES = {
    "ur_type": (6, 0, 0),
    "scara": (3, 1, 0),
    "gantry": (0, 3, 0),
    "koji": (4, 0, 2),
}


def recognise(robot, frame: str = "tcp") -> Recognition:
    """The closed-form family of ``robot`` (for targets of ``frame``), recognised by geometry and proven.

    Never raises for a model that does not fit: the result then has ``family=None`` and
    says in :attr:`Recognition.rejected` why each family was refused.
    """
    kinds, mimics = _signature(robot, frame)
    sig = (kinds["revolute"], kinds["prismatic"], mimics)
    rejected: dict[str, str] = {}
    for key, cls in FAMILIES.items():
        want = _SIGNATURES.get(key)
        if want is not None and (want != sig or robot.nq != want[0] + want[1]):
            continue  # not this family's joints: no solver built
        try:
            solver = cls(robot, frame)
        except (ModelError, ArithmeticError, ValueError, np.linalg.LinAlgError) as exc:
            rejected[key] = str(exc)
            continue
        return Recognition(family=key, solver=solver, rejected=rejected)
    return Recognition(family=None, solver=None, rejected=rejected)
