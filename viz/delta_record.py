"""Delta robots in a session: a shipped delta, where it hangs, and its motion as actuated angles over time.

A delta (:mod:`pinarms.robots.delta`) is a tree opened at the platform plus loop closures, not a
:class:`pinarms.robots.Robot`: a session stores it as a :class:`DeltaRecord`, the delta's registry
name, its base pose in the world and its motion as the **actuated** coordinates only, the three
motor angles (and the fourth axis' tool angle when the delta has one) at instants ``t``. The
passive joints (elbows, platform) are never stored: every reader solves them from the closed form
(:meth:`pinarms.robots.delta.DeltaRobot.configuration`), so a file cannot hold a chain that does
not close. In ``session.json`` a delta is an item of the optional section ``"deltas"`` (a row of
:data:`pinarms.viz.session_schema.KINDS`; absent when a session holds none, so older files and
readers are unaffected), bounded and checked like every other item; on load the decoder also checks
that the name is a shipped delta, the columns match its actuated joints, every motor angle lies in
its range and every row assembles.

Units: m, s, rad. Only shipped deltas (:func:`pinarms.robots.delta.delta_names`) are stored: a delta
built from other files (:func:`~pinarms.robots.delta.delta_from_files`) is refused with what to do.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from pinarms.errors import InvalidInput

from pinarms.viz.session_inputs import float_array, pose_array
from pinarms.viz.session_specs import SessionItemView

if TYPE_CHECKING:
    from pinarms.robots.delta import DeltaRobot

__all__ = ["DeltaRecord", "delta_record", "encode_delta", "decode_delta", "assembly_problem", "DELTA_RANGE_TOL"]

#: How far [rad] a stored motor angle may lie outside its range (rounding of a timed motion).
DELTA_RANGE_TOL = 1e-6


@dataclass(frozen=True, eq=False)
class DeltaRecord:
    """A shipped delta in the session and its motion.

    Attributes:
        name: its key in the session (scene path ``pinarms/deltas/<name>``).
        delta: the shipped delta's registry name (:func:`pinarms.robots.delta.load_delta`).
        base_to_world: (4, 4) pose of its base (the plane of the motor axes, z up) in the world [m].
        t: (N,) instants [s], strictly increasing (N = 1: the delta at rest).
        actuated: (N, 3) motor angles [rad], or (N, 4) with the tool angle [rad] of the fourth axis.
    """

    name: str
    delta: str
    base_to_world: np.ndarray
    t: np.ndarray
    actuated: np.ndarray

    @property
    def theta(self) -> np.ndarray:
        """(N, 3) motor angles [rad]."""
        return self.actuated[:, :3]

    @property
    def tool(self) -> np.ndarray:
        """(N,) tool angle [rad] (zeros for a delta without the fourth axis)."""
        return self.actuated[:, 3] if self.actuated.shape[1] == 4 else np.zeros(self.actuated.shape[0])

    @property
    def duration(self) -> float:
        """Length of the motion [s] (0 at rest)."""
        return float(self.t[-1] - self.t[0])

    def sample(self, times: np.ndarray) -> np.ndarray:
        """Actuated coordinates at ``times`` (F,) [s] from the motion's start (linear, held at the ends): (F, 3|4)."""
        tt = self.t[0] + np.asarray(times, dtype=float)
        if self.t.size == 1:
            return np.repeat(self.actuated, tt.size, axis=0)
        return np.stack([np.interp(tt, self.t, self.actuated[:, j]) for j in range(self.actuated.shape[1])], axis=1)


def _actuated_columns(delta: DeltaRobot) -> int:
    return 4 if delta.has_tool_axis else 3


def assembly_problem(delta: DeltaRobot, actuated: np.ndarray) -> str | None:
    """What is wrong with ``actuated`` (N, A) for ``delta`` (columns, motor range, rows that do not
    assemble), or ``None``."""
    from pinarms.robots.delta import forward_position

    cols = _actuated_columns(delta)
    if actuated.ndim != 2 or actuated.shape[1] != cols:
        return (f"holds {actuated.shape[-1] if actuated.ndim else 0} actuated columns; {delta.name} has {cols} "
                f"(3 motors{' and the tool axis' if cols == 4 else ''})")
    lim = delta.limits
    th = actuated[:, :3]
    out = np.flatnonzero(np.any((th < lim.lower - DELTA_RANGE_TOL) | (th > lim.upper + DELTA_RANGE_TOL), axis=1))
    if out.size:
        return (f"row {int(out[0])}: motor angles {th[out[0]].tolist()} rad outside the range "
                f"[{lim.lower:.6g}, {lim.upper:.6g}] rad")
    p = forward_position(delta.geometry, th)
    bad = np.flatnonzero(~np.all(np.isfinite(p), axis=1))
    if bad.size:
        return f"row {int(bad[0])}: motor angles {th[bad[0]].tolist()} rad do not assemble (the forearms' spheres do not meet)"
    return None


def delta_record(name: str, delta: DeltaRobot, base_to_world: ArrayLike | None,
                 motion: tuple[ArrayLike, ArrayLike] | None) -> DeltaRecord:
    """The record of ``delta`` (a shipped :class:`pinarms.robots.delta.DeltaRobot`) under ``name``, its base at
    ``base_to_world`` (checked 4 × 4 rigid), its ``motion`` a pair ``(t (N,) s, actuated (N, 3|4) rad)`` or
    ``None`` (at rest at its home configuration).

    Raises:
        InvalidInput: not a shipped delta, or a motion of the wrong shape, not increasing in time,
            outside the motor range or that does not assemble.
    """
    from pinarms.robots.delta import DeltaRobot, delta_names

    if not isinstance(delta, DeltaRobot):
        raise InvalidInput(f"delta {name!r} must be a robots.delta.DeltaRobot (load_delta), got {type(delta).__name__}")
    if delta.name not in delta_names() or _shipped(delta.name).urdf_text != delta.urdf_text:
        raise InvalidInput(f"delta {name!r} ({delta.name}) is not a shipped delta ({', '.join(delta_names())}): a session "
                           "stores deltas by registry name; ship it first (docs/delta.md, robots/delta/shipped.py)")
    if motion is None:
        home = delta.home()
        act = home[delta.motor_q] if delta.tool_q is None else np.append(home[delta.motor_q], 0.0)
        t, actuated = np.zeros(1), act[None]
    else:
        if not (isinstance(motion, (tuple, list)) and len(motion) == 2):
            raise InvalidInput(f"motion of delta {name!r} must be a pair (t (N,) s, actuated (N, 3|4) rad) or None")
        t = float_array(motion[0], f"t of delta {name!r}", 1)
        actuated = float_array(np.atleast_2d(np.asarray(motion[1], dtype=float)), f"actuated of delta {name!r}", 2)
        if t.size == 0 or actuated.shape[0] != t.size or np.any(np.diff(t) <= 0):
            raise InvalidInput(f"motion of delta {name!r}: t must be N >= 1 strictly increasing instants and actuated "
                               f"N rows; got t {t.shape}, actuated {actuated.shape}")
    problem = assembly_problem(delta, actuated)
    if problem:
        raise InvalidInput(f"motion of delta {name!r} {problem}")
    return DeltaRecord(name, delta.name, pose_array(base_to_world, f"base_to_world of delta {name!r}"), t, actuated)


def encode_delta(r: DeltaRecord) -> tuple[dict, dict, dict]:
    """JSON fields, arrays and texts of one record (see :class:`pinarms.viz.session_schema.Kind`)."""
    return {"name": r.name, "delta": r.delta}, {"base_to_world": r.base_to_world, "t": r.t, "actuated": r.actuated}, {}


@functools.lru_cache(maxsize=8)
def _shipped(name: str) -> DeltaRobot:
    """The shipped delta ``name``, loaded once per process: a file of many delta items costs one load each name
    (only its geometry and limits are read here)."""
    from pinarms.robots.delta import load_delta

    return load_delta(name)


def decode_delta(it: SessionItemView) -> DeltaRecord:
    """The record of a validated session item: a shipped delta's name, its motion checked against it (module doc)."""
    from pinarms.robots.delta import delta_names

    name = it.field("delta", str)
    if name not in delta_names():
        raise it.fail(f"{it.where}.delta {name!r} is not a delta this pinarms ships ({', '.join(delta_names())})")
    t, actuated = it.arrays["t"], it.arrays["actuated"]
    if np.any(np.diff(t) <= 0):
        raise it.fail(f"{it.where}.t must be strictly increasing")
    problem = assembly_problem(_shipped(name), actuated)
    if problem:
        raise it.fail(f"{it.where}.actuated {problem}")
    try:
        pose = pose_array(it.arrays["base_to_world"], f"{it.where}.base_to_world")
    except InvalidInput as exc:
        raise it.fail(str(exc)) from None
    return DeltaRecord(it.key, name, pose, t, actuated)
