"""Rigid-body dynamics of a :class:`pinarms.robots.Robot`: joint torques, energies, holding torques.

Conventions
-----------
- Gravity is ``g = (0, 0, -9.81) m/s²`` in the robot's base frame (Pinocchio's default):
  the base's +z points up.
- Joint torques ``tau`` are per *independent* joint, in ``q`` order, N·m for revolute and
  N for prismatic joints, the generalised forces that produce the motion
  ``tau = M(q) qdd + C(q, qd) qd + g(q)`` (no friction, no motor inertia). For an arm with
  ``<mimic>`` joints (the koji arm's parallelogram) the coupled joints are no coordinates:
  with ``q_full = G q + offset`` the torque on the independent joints is
  ``tau = Gᵀ tau_full`` (virtual work of the ideal coupling), which Pinocchio's RNEA on a
  model built with ``mimic=True`` computes directly.
- Batches: ``q, qd, qdd`` of shape ``(N, nq)`` give ``(N, nq)``; a single ``(nq,)`` gives
  ``(nq,)``. A batch goes to Pinocchio's RNEA in one call (``pinocchio.rneaInParallel``),
  without a Python loop over samples.
- A payload (:mod:`.payload`) changes the inertia of the body it is fixed to; the torques
  here are those of the robot's model, payload included.
"""

from __future__ import annotations

import weakref
from typing import Any

import numpy as np
from numpy.typing import ArrayLike
import pinocchio as pin

from pinarms.robots._checks import as_batch
from pinarms.errors import InvalidInput, ModelError
from pinarms.robots.robot_model import RobotModel

__all__ = [
    "GRAVITY",
    "MissingInertials",
    "check_inertials",
    "inverse_dynamics",
    "gravity_torques",
    "kinetic_energy",
    "potential_energy",
    "total_mass",
    "holding_torques",
]

#: Gravity [m/s²] in the base frame (Pinocchio's default model gravity).
GRAVITY = np.array([0.0, 0.0, -9.81])


class MissingInertials(ModelError):
    """The robot's URDF gives no mass to the links a joint moves: its torques would be meaningless."""


#: The Pinocchio models whose masses :func:`check_inertials` found complete (weakly held: a model that goes
#: away leaves; a robot with a payload has a model of its own, checked afresh).
_CHECKED_MODELS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def check_inertials(robot: RobotModel) -> None:
    """Raise :class:`MissingInertials` if a joint of ``robot`` moves no mass at all.

    Every independent joint must carry some mass beyond it (its links, or a payload): a URDF
    without ``<inertial>`` elements loads for kinematics, but its torques would all be zero.
    """
    model = robot.model
    if model in _CHECKED_MODELS:
        return
    data = model.createData()
    pin.computeSubtreeMasses(model, data)
    subtree = np.asarray(data.mass, dtype=float)  # mass supported by each joint (its subtree)
    massless = []
    for i in range(1, model.njoints):
        if "Mimic" in model.joints[i].shortname():
            continue
        if not subtree[i] > 0.0:
            massless.append(model.names[i])
    if massless:
        raise MissingInertials(
            f"robot '{robot.name}' has no mass beyond joint(s) {massless}: its URDF gives those links no "
            "<inertial> (mass, centre of mass, inertia); add them, or use robots.load(...) for a built-in arm "
            "whose URDF carries inertials"
        )
    _CHECKED_MODELS[model] = True


def total_mass(robot: RobotModel) -> float:
    """Mass [kg] of every body of ``robot`` (base link and payload included)."""
    return float(sum(robot.model.inertias[i].mass for i in range(robot.model.njoints)))


def _state(robot: RobotModel, values: Any, what: str, n: int | None) -> tuple[np.ndarray, bool]:
    arr, single = robot.check_q(values) if what == "q" else _as_rows(robot, values, what)
    if n is not None and arr.shape[0] != n:
        raise InvalidInput(f"{what} has {arr.shape[0]} rows but q has {n}: give one row per configuration")
    return arr, single


def _as_rows(robot: RobotModel, values: Any, what: str) -> tuple[np.ndarray, bool]:
    unit = {"qd": "rad/s or m/s", "qdd": "rad/s² or m/s²"}[what]
    return as_batch(values, robot.nq, f"{what} [{unit}] of '{robot.name}' (joints {list(robot.joint_names)})")


def _rnea_batch(robot: RobotModel, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray) -> np.ndarray:
    """Pinocchio's RNEA on N states at once: (N, nq) each → (N, nq)."""
    n = q.shape[0]
    if n == 0:
        return np.zeros((0, robot.nq))
    qp = robot.q_to_pinocchio(q).reshape(n, -1)
    # one model/data pair per call: calls from several threads never share a Data
    pool = pin.ModelPool(robot.model, 1)
    tau = pin.rneaInParallel(1, pool, np.asfortranarray(qp.T), np.asfortranarray(qd.T), np.asfortranarray(qdd.T))
    # a batch of one comes back as a vector (nv,) rather than (nv, 1)
    return np.ascontiguousarray(np.asarray(tau).reshape(robot.nq, n).T)


def inverse_dynamics(robot: RobotModel, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike) -> np.ndarray:
    """Joint torques ``tau = M(q) qdd + C(q, qd) qd + g(q)`` (module conventions).

    Args:
        q: (nq,) or (N, nq) [rad or m]; qd: same shape [rad/s or m/s]; qdd: same shape
            [rad/s² or m/s²].

    Returns:
        (nq,) or (N, nq) torques [N·m or N] on the independent joints.

    Raises:
        InvalidInput: shapes that disagree, NaN/inf.
        MissingInertials: the robot's URDF carries no inertials (see :func:`check_inertials`).
    """
    check_inertials(robot)
    qa, single = robot.check_q(q)
    va, _ = _state(robot, qd, "qd", qa.shape[0])
    aa, _ = _state(robot, qdd, "qdd", qa.shape[0])
    tau = _rnea_batch(robot, qa, va, aa)
    return tau[0] if single else tau


def gravity_torques(robot: RobotModel, q: ArrayLike) -> np.ndarray:
    """Torques [N·m or N] that hold ``q`` (nq,) or (N, nq) still against gravity: ``g(q)``."""
    check_inertials(robot)
    qa, single = robot.check_q(q)
    zero = np.zeros_like(qa)
    tau = _rnea_batch(robot, qa, zero, zero)
    return tau[0] if single else tau


def _has_mimic(model: pin.Model) -> bool:
    """Whether the model couples joints (``<mimic>``): Pinocchio's energy algorithms refuse those models."""
    return any("Mimic" in model.joints[i].shortname() for i in range(1, model.njoints))


def kinetic_energy(robot: RobotModel, q: ArrayLike, qd: ArrayLike) -> float | np.ndarray:
    """Kinetic energy ``½ qdᵀ M(q) qd`` [J], summed body by body (Pinocchio's ``computeKineticEnergy``).

    ``Σ_i ½ v_iᵀ Y_i v_i`` with ``v_i`` the spatial velocity of body i (mimic joints
    followed) and ``Y_i`` its spatial inertia: computed apart from RNEA, so the energy
    balance checks it. One configuration at a time (a reference for checks, not a batch kernel).
    Pinocchio refuses models with mimic joints (the koji arm): for those the same sum is
    taken body by body after ``forwardKinematics``.
    """
    check_inertials(robot)
    qa, single = robot.check_q(q)
    va, _ = _state(robot, qd, "qd", qa.shape[0])
    qp = robot.q_to_pinocchio(qa).reshape(qa.shape[0], -1)
    model = robot.model
    data = model.createData()
    out = np.empty(qa.shape[0])
    mimic = _has_mimic(model)
    for k in range(qa.shape[0]):
        if not mimic:
            out[k] = pin.computeKineticEnergy(model, data, qp[k], va[k])
            continue
        pin.forwardKinematics(model, data, qp[k], va[k])
        out[k] = 0.5 * sum(model.inertias[i].vtiv(data.v[i]) for i in range(1, model.njoints))
    return float(out[0]) if single else out


def potential_energy(robot: RobotModel, q: ArrayLike) -> float | np.ndarray:
    """Gravitational potential energy ``-Σ m_i g·c_i`` [J] of the moving bodies (zero at the base origin's height).

    Pinocchio's ``computePotentialEnergy`` (centres of mass ``c_i`` in the base frame from
    forward kinematics), one configuration at a time (a reference for checks); body by body
    after ``forwardKinematics`` for models with mimic joints, which Pinocchio's algorithm refuses.
    """
    check_inertials(robot)
    qa, single = robot.check_q(q)
    qp = robot.q_to_pinocchio(qa).reshape(qa.shape[0], -1)
    model = robot.model
    data = model.createData()
    out = np.empty(qa.shape[0])
    mimic = _has_mimic(model)
    for k in range(qa.shape[0]):
        if not mimic:
            out[k] = pin.computePotentialEnergy(model, data, qp[k])
            continue
        pin.forwardKinematics(model, data, qp[k])
        out[k] = -sum(
            model.inertias[i].mass * float(model.gravity.linear @ data.oMi[i].act(model.inertias[i].lever))
            for i in range(1, model.njoints)
        )
    return float(out[0]) if single else out


def holding_torques(
    robot: RobotModel, n: int = 20000, seed: int = 0, accel_time: float | None = None, starts: int = 3
) -> tuple[np.ndarray, np.ndarray]:
    """Largest torque each joint needs to hold the arm (and its payload) anywhere in its ranges.

    ``max over q within the joint limits of |g_j(q)|`` [N·m or N]: the static load a joint must
    carry before any acceleration (e.g. a rated payload at full reach). With ``accel_time``
    [s], the joint must also start from rest to its speed limit in that time at the worst
    place: ``max_q |g_j(q)| + M_jj(q) v_j / accel_time`` (the usual servo sizing: load torque
    plus acceleration torque; the other joints at rest). Found by ``n`` seeded uniform samples,
    the best ``starts`` per joint refined by a bounded quasi-Newton search.

    Returns:
        ``(torque (nq,), q (nq, nq))``: the maxima and, row j, the configuration of joint j's.
    """
    from scipy.optimize import minimize

    if accel_time is not None and not (isinstance(accel_time, (int, float)) and accel_time > 0.0):
        raise InvalidInput(f"accel_time must be a positive number of seconds, got {accel_time!r}")
    alpha = np.zeros(robot.nq) if accel_time is None else np.asarray(robot.velocity_limit, dtype=float) / accel_time

    def demand(q: np.ndarray, j: int) -> np.ndarray:
        """|g_j| + M_jj alpha_j for rows of q (N, nq)."""
        g = gravity_torques(robot, q)[:, j]
        if not alpha[j] > 0.0:
            return np.abs(g)
        qdd = np.zeros_like(q)
        qdd[:, j] = alpha[j]
        return np.abs(g) + (inverse_dynamics(robot, q, np.zeros_like(q), qdd)[:, j] - g)

    q = robot.random_q(n, seed=seed)
    best = np.zeros(robot.nq)
    where = np.tile(robot.neutral, (robot.nq, 1))
    bounds = list(zip(robot.lower, robot.upper))
    for j in range(robot.nq):
        values = demand(q, j)
        k_best = int(np.argmax(values))
        best[j], where[j] = values[k_best], q[k_best]
        if not best[j] > 0.0:
            continue
        for k in np.argsort(values)[-max(int(starts), 1):]:
            res = minimize(lambda x: -float(demand(x[None], j)[0]), q[k], method="L-BFGS-B",
                           bounds=bounds, options={"ftol": 1e-15, "gtol": 1e-10, "maxiter": 500})
            x = np.clip(res.x, robot.lower, robot.upper)
            value = float(demand(x[None], j)[0])
            if value > best[j]:
                best[j], where[j] = value, x
    return best, where
