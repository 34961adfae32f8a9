"""Rebuild a trajectory from its JSON-able ``definition`` (used by saved sessions).

Every constructor of :mod:`pinarms.planning` records its inputs in ``Trajectory.definition``;
:func:`from_definition` calls the same constructor again, so the rebuilt trajectory is
the same (same breaks and coefficients). Derived trajectories record how they were
derived (``"scaled"``, ``"shifted"``, ``"concatenated"``); a trajectory built directly
from breaks and coefficients is stored as ``"ppoly"``.
"""

from __future__ import annotations

from functools import reduce
from typing import Any, Callable

from pinarms.planning.bspline import quintic_bspline
from pinarms.planning.errors import TrajectoryError
from pinarms.planning.multi_quintic import multi_quintic
from pinarms.planning.piecewise import piecewise_polynomial
from pinarms.planning.point_to_point import double_s, trapezoidal
from pinarms.planning.polynomial import polynomial
from pinarms.planning.trajectory import Trajectory

__all__ = ["from_definition", "KINDS"]


def _get(d: dict, key: str) -> Any:
    if key not in d:
        raise TrajectoryError(f"trajectory definition of kind {d.get('kind')!r} lacks the field {key!r}")
    return d[key]


_BUILDERS: dict[str, Callable[[dict], Trajectory]] = {
    "polynomial": lambda d: polynomial(_get(d, "times"), _get(d, "positions"), _get(d, "degree")),
    "piecewise_polynomial": lambda d: piecewise_polynomial(
        _get(d, "times"),
        _get(d, "positions"),
        _get(d, "degrees"),
        continuity=d.get("continuity", 2),
        end_order=d.get("end_order", 2),
    ),
    "multi_quintic": lambda d: multi_quintic(
        _get(d, "times"), _get(d, "positions"), d.get("velocities"), d.get("accelerations")
    ),
    "quintic_bspline": lambda d: quintic_bspline(
        _get(d, "times"),
        _get(d, "positions"),
        start_velocity=d.get("start_velocity", 0.0),
        end_velocity=d.get("end_velocity", 0.0),
        start_acceleration=d.get("start_acceleration", 0.0),
        end_acceleration=d.get("end_acceleration", 0.0),
    ),
    "trapezoidal": lambda d: trapezoidal(
        _get(d, "q0"), _get(d, "q1"), _get(d, "vmax"), _get(d, "amax"), synchronized=d.get("synchronized", True)
    ),
    "double_s": lambda d: double_s(
        _get(d, "q0"),
        _get(d, "q1"),
        _get(d, "vmax"),
        _get(d, "amax"),
        _get(d, "jmax"),
        synchronized=d.get("synchronized", True),
    ),
    "scaled": lambda d: _nested(_get(d, "base"), d).scaled(_get(d, "factor")),
    "shifted": lambda d: _nested(_get(d, "base"), d).shifted(_get(d, "start_time")),
    "concatenated": lambda d: reduce(lambda a, b: a.concatenated(b), [_nested(p, d) for p in _parts(d)]),
    "ppoly": lambda d: Trajectory(_get(d, "breaks"), _get(d, "coefficients")),
}

#: Deepest nesting of derived definitions (scaled of shifted of concatenated of ...) rebuilt.
MAX_DEPTH = 32


def _nested(part: Any, parent: dict) -> Trajectory:
    return from_definition(part, _depth=parent["_depth"] + 1)


def _parts(d: dict) -> list:
    parts = _get(d, "parts")
    if not isinstance(parts, list) or not parts:
        raise TrajectoryError("a 'concatenated' definition needs a non-empty 'parts' list of definitions")
    return parts


#: Kinds :func:`from_definition` understands.
KINDS: tuple[str, ...] = tuple(sorted(_BUILDERS))


def from_definition(definition: dict, *, _depth: int = 0) -> Trajectory:
    """Rebuild the trajectory described by ``definition`` (a dict as given by ``Trajectory.definition``).

    Raises:
        TrajectoryError: not a dict, an unknown kind, a missing field, derived definitions
            nested deeper than :data:`MAX_DEPTH`; the constructors' own errors otherwise.
    """
    if not isinstance(definition, dict):
        raise TrajectoryError(f"a trajectory definition must be a dict, got {type(definition).__name__}")
    if _depth > MAX_DEPTH:
        raise TrajectoryError(f"trajectory definitions nest deeper than {MAX_DEPTH} levels")
    kind = definition.get("kind")
    if not isinstance(kind, str) or kind not in _BUILDERS:
        raise TrajectoryError(f"unknown trajectory kind {str(kind)[:100]!r}; known kinds: {', '.join(KINDS)}")
    return _BUILDERS[kind]({**definition, "_depth": _depth})
