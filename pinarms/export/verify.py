"""An independent engine re-checks what pinarms planned: MuJoCo replays the motion through the exported MJCF.

:func:`compare_in_mujoco` exports the cell (:func:`pinarms.export.export_cell`, MJCF only)
unless given an MJCF, samples the planned motion (a cycle, a planned move, a line
schedule) at evenly spaced instants, and at each one sets MuJoCo's ``qpos`` (independent
joints by name; ``<mimic>`` joints from MuJoCo's own joint equalities), runs the
kinematics and the collision pass, and reads, **over the pairs pinarms checks at contact**:

- MuJoCo's signed distance of each pair (``mujoco.mj_geomDistance``, up to
  :data:`DISTMAX` m; negative: penetration) and the contacts its collision pass finds
  (``mj_collision``; those between checked pairs);
- pinarms' distance of each pair (coal, through Pinocchio's ``computeDistance``), exactly wherever a figure
  below may depend on it and a proven lower bound elsewhere (:mod:`pinarms.export.pair_distances`: the
  same figures as every exact distance, in seconds instead of minutes on meshes of 20 000 triangles).

Geometry each engine uses: pinarms/coal uses the URDF's primitives exactly (box,
cylinder, sphere) and a mesh as its triangles (the surface itself, concave parts
included); MuJoCo uses its own primitives for box, cylinder and sphere, and the **convex
hull** of a mesh. The hull contains the mesh, so for a pair with a mesh MuJoCo's distance
may be smaller than coal's (never larger, up to the tolerance): such pairs are compared
one-sided. Primitive pairs agree within :data:`TOLERANCE_M`.

The comparison passes when MuJoCo finds no contact between primitives where pinarms says clear
(distance > 0), and the distances agree as above. A contact of a mesh's hull where coal's mesh
is clear is counted apart (``hull_only``): the hull is larger than the mesh by design.
"""

from __future__ import annotations

import dataclasses
import math
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Mapping, TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from pinarms.errors import InvalidInput, ModelError

from pinarms.export.pair_distances import pinarms_distances
from pinarms.export.srdf import contact_pairs

if TYPE_CHECKING:
    from pinarms.robots.cell.cell import Cell

__all__ = ["EngineComparison", "compare_in_mujoco", "compare_configurations_in_mujoco", "motion_sampler", "TOLERANCE_M", "DISTMAX"]

#: Agreement asked of the two engines on a pair of primitives [m] (both iterate to ~1e-6 m or better).
TOLERANCE_M = 1e-6
#: Largest distance MuJoCo is asked to measure [m]; pairs farther apart in pinarms are not compared.
DISTMAX = 0.5


@dataclass(frozen=True, eq=False)
class EngineComparison:
    """What MuJoCo found along a planned motion, beside pinarms (module doc).

    Attributes:
        label: what was replayed; ``cell``: the cell's name; ``mjcf``: the model replayed.
        samples: instants (or configurations, as ``sampled`` says) compared; ``pairs``: pairs per sample.
        min_pinarms, min_mujoco: smallest distance over the pairs and the instants [m], and
            their pairs (``min_pinarms_pair``, ``min_mujoco_pair``).
        max_abs_difference: largest ``|d_mujoco − d_pinarms|`` over primitive pairs [m];
            ``max_mesh_excess``: largest ``d_mujoco − d_pinarms`` over pairs with a mesh (≤ tolerance
            when MuJoCo's hull is conservative), ``max_mesh_gap`` the largest ``d_pinarms − d_mujoco`` there.
        contacts_pinarms: (instant, pair) in contact for pinarms (distance ≤ 0);
            ``contacts_mujoco``: (instant, pair) with a contact from MuJoCo's collision pass
            (a box on a box gives several contact points: counted once);
            ``mujoco_only``: (instant, pair of primitives) where MuJoCo touches and pinarms says clear;
            ``hull_only``: (instant, pair with a mesh) where MuJoCo's convex hull touches and coal's mesh is clear
            (the hull contains the mesh: not a disagreement; its distances are checked by ``max_mesh_excess``).
        tolerance: :data:`TOLERANCE_M`.
    """

    label: str
    cell: str
    mjcf: str
    samples: int
    pairs: int
    min_pinarms: float
    min_pinarms_pair: str
    min_mujoco: float
    min_mujoco_pair: str
    max_abs_difference: float
    max_mesh_excess: float
    max_mesh_gap: float
    contacts_pinarms: int
    contacts_mujoco: int
    mujoco_only: int
    hull_only: int = 0
    tolerance: float = TOLERANCE_M
    #: what a sample is: ``instants`` of a motion, or ``configurations``
    sampled: str = "instants"

    @property
    def agrees(self) -> bool:
        """No MuJoCo contact where pinarms is clear, and distances agree (module doc)."""
        return (self.mujoco_only == 0 and self.max_abs_difference <= self.tolerance
                and self.max_mesh_excess <= self.tolerance)

    def as_dict(self) -> dict[str, Any]:
        return {k: getattr(self, k) for k in self.__dataclass_fields__} | {"agrees": self.agrees}

    def lines(self) -> list[str]:
        return [
            f"{self.label} in {self.cell}: {self.samples} {self.sampled} x {self.pairs} pairs",
            f"  min distance  pinarms (coal) {self.min_pinarms * 1e3:9.4f} mm  ({self.min_pinarms_pair})",
            f"  min distance  MuJoCo         {self.min_mujoco * 1e3:9.4f} mm  ({self.min_mujoco_pair})",
            f"  max |difference| primitives  {self.max_abs_difference:.3e} m (tolerance {self.tolerance:g} m)",
            (f"  meshes (MuJoCo: convex hull) MuJoCo above coal by at most {self.max_mesh_excess:.3e} m, "
             f"below by at most {self.max_mesh_gap:.3e} m") if math.isfinite(self.max_mesh_excess)
            else "  meshes: no pair with a mesh",
            f"  contacts (instant, pair): pinarms {self.contacts_pinarms}, MuJoCo {self.contacts_mujoco}, "
            f"MuJoCo only {self.mujoco_only}, hull only {self.hull_only}  -> {'agree' if self.agrees else 'DISAGREE'}",
        ]


def motion_sampler(source: Any, cell: Cell, *, arm: str | None = None,
                   cycles: Mapping[str, Any] | None = None) -> tuple[str, float, float, Any]:
    """``(label, start, end, q_of_t)`` of a planned motion in ``cell`` (``q_of_t(t (N,)) -> (N, nq)``)."""
    from pinarms.optim import CycleResult, LineSchedule
    from pinarms.optim.motion import MotionPlan
    from pinarms.robots.cell import ArmMotion

    if isinstance(source, MotionPlan):
        traj = source.cell_trajectory()
        return f"planned move ({', '.join(source.arms)})", traj.start_time, traj.end_time, lambda t: traj(t)
    if isinstance(source, CycleResult):
        if arm is None:
            raise InvalidInput("name the arm of the cell the cycle was planned for (arm=)")
        traj = source.trajectory
        return (f"cycle of arm {arm!r}", traj.start_time, traj.end_time,
                lambda t: cell.q_from_arms({arm: traj(t)}))
    if isinstance(source, LineSchedule):
        if cycles is None:
            raise InvalidInput("a line schedule is replayed with the cycles it scheduled (cycles=)")
        motions = [ArmMotion(n, cycles[n].trajectory, source.offsets[n], source.period) for n in source.arms]
        return (f"line schedule ({', '.join(source.arms)}, period {source.period:.3f} s)", 0.0, source.period,
                lambda t: cell.q_from_arms({m.arm: m.trajectory(m.local_time(t)) for m in motions}))
    raise InvalidInput(f"cannot replay {type(source).__name__}: give a CycleResult, MotionPlan or LineSchedule")


def _mujoco_setter(model: Any, cell: Any):
    """``set(data, q_cell)``: independent joints by name, the others from MuJoCo's joint equalities."""
    import mujoco

    addr = []
    for name in cell.joint_names:
        try:
            addr.append(int(model.jnt_qposadr[model.joint(name).id]))
        except KeyError as exc:
            raise ModelError(f"the MJCF has no joint {name!r} of cell {cell.name!r}: export the cell again") from exc
    eqs = [(int(model.jnt_qposadr[model.eq_obj1id[k]]), int(model.jnt_qposadr[model.eq_obj2id[k]]),
            model.eq_data[k, :5].copy()) for k in range(model.neq) if model.eq_type[k] == mujoco.mjtEq.mjEQ_JOINT]
    addr = np.array(addr)

    def set_q(data: Any, q: np.ndarray) -> None:
        data.qpos[:] = 0.0
        data.qpos[addr] = q
        for dep, lead, c in eqs:
            x = data.qpos[lead]
            data.qpos[dep] = c[0] + c[1] * x + c[2] * x**2 + c[3] * x**3 + c[4] * x**4

    return set_q


def compare_in_mujoco(cell: Cell, source: Any, *, arm: str | None = None, cycles: Mapping[str, Any] | None = None,
                      samples: int = 200, mjcf: str | Path | None = None,
                      packages: Mapping[str, str | Path] | None = None) -> EngineComparison:
    """Replay ``source`` in MuJoCo and compare with pinarms (module doc).

    Args:
        cell: the :class:`pinarms.robots.cell.Cell` the motion was planned in.
        source: a CycleResult (with ``arm``), a MotionPlan, or a LineSchedule (with ``cycles``).
        samples: evenly spaced instants, ends included (≥ 2).
        mjcf: an MJCF exported from this cell (default: exported to a temporary folder).
        packages: ``{NAME: FOLDER}`` of the cell's ``package://`` meshes, for that export.
    """
    _check_samples(samples, 2)
    label, start, end, q_of_t = motion_sampler(source, cell, arm=arm, cycles=cycles)
    qs = np.atleast_2d(q_of_t(np.linspace(start, end, int(samples))))
    return _compare(cell, label, qs, mjcf, packages)


def compare_configurations_in_mujoco(cell: Cell, qs: ArrayLike, *, label: str = "configurations",
                                     mjcf: str | Path | None = None,
                                     packages: Mapping[str, str | Path] | None = None) -> EngineComparison:
    """Compare pinarms and MuJoCo at the cell configurations ``qs (N, nq)`` (module doc; ``samples`` = N).

    The collision state of a cell itself, without a motion: e.g. at ``cell.random_q(N, seed=...)``.

    Raises:
        InvalidInput: ``qs`` is not ``(N, nq)`` finite numbers with N ≥ 1.
    """
    q = np.asarray(qs, dtype=float)
    q = q[None] if q.ndim == 1 else q
    if q.ndim != 2 or q.shape[0] < 1 or q.shape[1] != cell.nq or not np.all(np.isfinite(q)):
        raise InvalidInput(f"configurations must be (N, {cell.nq}) finite numbers with N >= 1, got shape "
                           f"{np.shape(qs)}")
    return dataclasses.replace(_compare(cell, label, q, mjcf, packages), sampled="configurations")


def _check_samples(samples: Any, least: int) -> None:
    if isinstance(samples, bool) or not isinstance(samples, (int, np.integer)) or samples < least:
        raise InvalidInput(f"samples must be an integer >= {least}, got {samples!r}")


#: The last MJCF read: ``(path, size, mtime_ns) -> MjModel`` (a CLI call compares configurations and a move in one).
_LAST_MODEL: dict = {}


def _mujoco_model(path: Path) -> Any:
    """MuJoCo's model of the MJCF file ``path``, read again only when the file changed (its meshes' hulls
    take seconds)."""
    import mujoco

    stat = Path(path).stat()
    key = (str(Path(path).resolve()), stat.st_size, stat.st_mtime_ns)
    if key not in _LAST_MODEL:
        _LAST_MODEL.clear()
        _LAST_MODEL[key] = mujoco.MjModel.from_xml_path(str(path))
    return _LAST_MODEL[key]


def _compare(cell: Any, label: str, qs: np.ndarray, mjcf: str | Path | None,
             packages: Mapping[str, str | Path] | None) -> EngineComparison:
    """Both engines' distances and contacts over the pinarms contact pairs at the configurations ``qs``."""
    import mujoco

    with tempfile.TemporaryDirectory() as tmp:
        if mjcf is None:
            from pinarms.export.cell import export_cell

            mjcf_path = export_cell(cell, Path(tmp) / "cell", srdf=False, packages=packages).mjcf
        else:
            mjcf_path = Path(mjcf)
        model = _mujoco_model(mjcf_path)
    data = mujoco.MjData(model)
    pairs = contact_pairs(cell)
    ids = np.array([[model.geom(p.geometry_a).id, model.geom(p.geometry_b).id] for p in pairs])
    is_mesh = np.array([model.geom_type[a] == mujoco.mjtGeom.mjGEOM_MESH or model.geom_type[b] == mujoco.mjtGeom.mjGEOM_MESH
                        for a, b in ids])
    checked = {frozenset(map(int, row)): k for k, row in enumerate(ids)}
    d_mj = np.empty((len(qs), len(pairs)))
    set_q = _mujoco_setter(model, cell)
    fromto = np.zeros(6)
    mj_touch = np.zeros_like(d_mj, dtype=bool)
    for i, q in enumerate(qs):
        set_q(data, q)
        mujoco.mj_kinematics(model, data)
        mujoco.mj_collision(model, data)
        for c in range(data.ncon):
            k = checked.get(frozenset((int(data.contact[c].geom1), int(data.contact[c].geom2))))
            if k is not None and data.contact[c].dist <= 0.0:
                mj_touch[i, k] = True
        for k, (a, b) in enumerate(ids):
            d_mj[i, k] = mujoco.mj_geomDistance(model, data, int(a), int(b), DISTMAX, fromto)
    # coal exactly wherever a figure below may depend on it, a proven lower bound elsewhere (pair_distances)
    d_pin = pinarms_distances(cell, pairs, qs, d_mj, is_mesh, DISTMAX - 1e-9).value
    near = d_pin < DISTMAX - 1e-9
    diff = d_mj - d_pin
    prim, mesh = near & ~is_mesh[None, :], near & is_mesh[None, :]
    i_pin, i_mj = np.unravel_index(np.argmin(d_pin), d_pin.shape), np.unravel_index(np.argmin(d_mj), d_mj.shape)
    name = lambda k: f"{pairs[k].geometry_a} - {pairs[k].geometry_b}"  # noqa: E731
    only = (mj_touch | (d_mj < 0.0)) & (d_pin > 0.0)
    return EngineComparison(
        label=label, cell=cell.name, mjcf=str(mjcf_path), samples=len(qs), pairs=len(pairs),
        min_pinarms=float(d_pin[i_pin]), min_pinarms_pair=name(i_pin[1]),
        min_mujoco=float(d_mj[i_mj]), min_mujoco_pair=name(i_mj[1]),
        max_abs_difference=float(np.abs(diff[prim]).max()) if prim.any() else 0.0,
        max_mesh_excess=float(diff[mesh].max()) if mesh.any() else -math.inf,
        max_mesh_gap=float((-diff[mesh]).max()) if mesh.any() else 0.0,
        contacts_pinarms=int((d_pin <= 0.0).sum()), contacts_mujoco=int(mj_touch.sum()),
        mujoco_only=int((only & ~is_mesh[None, :]).sum()), hull_only=int((only & is_mesh[None, :]).sum()),
    )
