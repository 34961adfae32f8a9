"""Settings of coal requests that pinarms' collision checks rely on.

Pinocchio's ``GeometryData`` enables coal's *cached GJK guess* by default: each pair's
GJK starts from the separating direction found for the previous configuration. For
configurations far apart (random samples, a planner's states) that warm start gives false
negatives: with one ``GeometryData`` reused over 3000 random AUBO-i3 configurations, a plain
``computeCollisions`` loop missed 70 penetrating configurations (up to 15 mm deep) that a
fresh ``GeometryData`` reports. :func:`cold_start` turns the warm start off; every
``GeometryData`` pinarms checks with goes through it.
"""

from __future__ import annotations

import threading
import warnings

import coal
import pinocchio as pin

__all__ = ["cold_start", "pair_probe"]

# ``warnings.catch_warnings`` swaps the process-wide filter list: two threads inside it at once
# restore each other's filters mid-block (a thread then meets coal's DeprecationWarning under
# the caller's filters, e.g. as an error). One thread at a time sets the deprecated flag.
_WARNINGS_LOCK = threading.Lock()


def cold_start(gd: pin.GeometryData, *, distance_tolerance: float | None = None) -> pin.GeometryData:
    """Start every GJK of ``gd`` from coal's default guess (no cache); optionally tighten distances.

    Args:
        distance_tolerance: GJK tolerance of the distance requests [m] (coal's default 1e-6).

    Returns:
        ``gd`` itself.
    """
    with _WARNINGS_LOCK, warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)  # coal renamed the flag, still honours it
        for req in list(gd.collisionRequests) + list(gd.distanceRequests):
            req.enable_cached_gjk_guess = False
            req.gjk_initial_guess = coal.GJKInitialGuess.DefaultGuess
    if distance_tolerance is not None:
        for req in gd.distanceRequests:
            req.gjk_tolerance = distance_tolerance
    return gd


def pair_probe(objs: list, pairs: list[tuple[int, int]], distance_tolerance: float
               ) -> tuple[pin.GeometryModel, pin.GeometryData]:
    """A geometry model of the geometry objects ``objs`` with only the collision ``pairs``
    (indices into ``objs``), and its data started cold with ``distance_tolerance`` [m]."""
    probe = pin.GeometryModel()
    for g in objs:
        probe.addGeometryObject(g)
    for a, b in pairs:
        probe.addCollisionPair(pin.CollisionPair(a, b))
    return probe, cold_start(pin.GeometryData(probe), distance_tolerance=distance_tolerance)
