"""A delta robot in Pinocchio: the open tree, its loop closures as constraint models, the closed form.

:class:`DeltaRobot` holds the model built from the URDF (the tree opened at the platform), the
``RigidConstraintModel`` objects built from the closures file, the dimensions read from the
model (:class:`~.geometry.DeltaGeometry`) and the motor limits. It maps motor angles to a full
configuration of the tree (closed form, :meth:`DeltaRobot.configuration`) and solves every
passive joint by Newton's projection onto the closures with Pinocchio's constraint Jacobians
(:meth:`DeltaRobot.project`).

Configuration ``q`` (nq = nv = 12, 13 with the fourth axis), indices from the model: three motor
angles, per leg the elbow's fold and swing, the platform's x, y, z, the tool angle.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from pinarms.robots.delta.closures import ClosureSet, constraint_models
from pinarms.robots.delta.errors import DeltaInputError, ProjectionFailed
from pinarms.robots.delta.geometry import LEG_COUNT, DeltaGeometry, motor_joint
from pinarms.robots.delta.kinematics import forward_position

__all__ = ["DeltaRobot", "MotorLimits"]


@dataclass(frozen=True)
class MotorLimits:
    """Arm-side limits of each of the three motors: position [rad], speed [rad/s], acceleration
    [rad/s^2], torque [N m] (position, speed and torque from the URDF; acceleration from the
    delta's registry entry, URDF having no field for it)."""

    lower: float
    upper: float
    velocity: float
    acceleration: float
    torque: float


class DeltaRobot:
    """A delta: Pinocchio model of the open tree + its loop-closure constraint models + the closed form.

    Build it with :func:`~.shipped.load_delta` or :func:`~.shipped.delta_from_files`.

    Attributes:
        model: the tree (``pin.Model``); ``constraint_models``: one ``RigidConstraintModel`` per closure.
        closures: the :class:`~.closures.ClosureSet` read from the closures file.
        geometry: :class:`~.geometry.DeltaGeometry`; ``limits``: :class:`MotorLimits`.
        motor_q, fold_q, swing_q, platform_q: indices in ``q`` (and ``v``: nq = nv) of the three
            motors, the elbows' fold and swing angles, the platform's x, y, z; ``passive_q`` all
            the passive ones sorted; ``tool_q`` the fourth axis or None.
        urdf_text: the tree's URDF (exports); ``payloads``: the masses added by :meth:`with_payload`.
    """

    def __init__(self, model: pin.Model, closures: ClosureSet, *, name: str, acceleration: float,
                 source: str = "", description: str = "", urdf_text: str = "") -> None:
        self.model = model
        self.urdf_text = urdf_text   # the open tree's URDF (exports)
        #: point masses added by :meth:`with_payload`: ``(mass [kg], offset from the tcp [m])``
        self.payloads: tuple[tuple[float, tuple[float, float, float]], ...] = ()
        self.name = name
        self.source = source
        self.description = description
        self.closures = closures
        self.constraint_models = constraint_models(model, closures, source or name)
        self.geometry = DeltaGeometry.from_model(model)
        jid = [model.getJointId(motor_joint(i)) for i in range(1, LEG_COUNT + 1)]
        q_of = lambda name: model.joints[model.getJointId(name)].idx_q  # noqa: E731
        self.motor_q = np.array([model.joints[j].idx_q for j in jid])
        self.fold_q = np.array([q_of(f"leg{i}_elbow_fold") for i in range(1, 4)])
        self.swing_q = np.array([q_of(f"leg{i}_elbow_swing") for i in range(1, 4)])
        self.platform_q = np.array([q_of(f"platform_{a}") for a in "xyz"])
        self.tool_q = q_of("tool") if model.existJointName("tool") else None
        self.passive_q = np.sort(np.concatenate([self.fold_q, self.swing_q, self.platform_q]))
        j0 = jid[0]
        self.limits = MotorLimits(float(model.lowerPositionLimit[self.motor_q[0]]),
                                  float(model.upperPositionLimit[self.motor_q[0]]),
                                  float(model.velocityLimit[model.joints[j0].idx_v]), float(acceleration),
                                  float(model.effortLimit[model.joints[j0].idx_v]))
        self.tcp_frame = model.getFrameId("tcp")
        self._data = model.createData()
        self._cdata = [cm.createData() for cm in self.constraint_models]

    def __repr__(self) -> str:
        return f"DeltaRobot({self.name!r}, nq={self.model.nq}, closures={len(self.constraint_models)})"

    @property
    def has_tool_axis(self) -> bool:
        """Whether the platform carries the fourth (tool) axis."""
        return self.tool_q is not None

    def _theta(self, theta) -> tuple[np.ndarray, bool]:
        arr = np.asarray(theta, dtype=float)
        single = arr.ndim == 1
        arr = np.atleast_2d(arr)
        if arr.ndim != 2 or arr.shape[1] != 3 or not np.all(np.isfinite(arr)):
            raise DeltaInputError(f"theta must be finite motor angles of shape (3,) or (N, 3), got shape {np.shape(theta)}")
        return arr, single

    def configuration(self, theta, tool=0.0) -> np.ndarray:
        """Full configuration(s) of the tree for motor angles ``theta`` [rad], every passive joint
        from the closed form (platform: lower assembly). Shape (nq,) or (N, nq); NaN rows where
        the angles cannot be assembled."""
        th, single = self._theta(theta)
        g = self.geometry
        p = forward_position(g, th)
        q = np.zeros((len(th), self.model.nq))
        q[:, self.motor_q] = th
        q[:, self.platform_q] = p
        e, u = g.radial, g.tangential
        elbow = (g.base_radius + g.upper_arm * np.cos(th))[:, :, None] * e - (g.upper_arm * np.sin(th))[:, :, None] \
            * np.array([0.0, 0.0, 1.0])
        rod = (p[:, None, :] + g.platform_radius * e[None] - elbow) / g.forearm     # unit rod directions (N, 3, 3)
        # rod in the upper arm's frame: R_y(theta)^T [e u z]^T rod = (cos a cos b, sin b, -sin a cos b)
        dx, dy, dz = np.einsum("nij,ij->ni", rod, e), np.einsum("nij,ij->ni", rod, u), rod[..., 2]
        c, s = np.cos(th), np.sin(th)
        lx, lz = c * dx - s * dz, s * dx + c * dz
        q[:, self.swing_q] = np.arcsin(np.clip(dy, -1.0, 1.0))
        q[:, self.fold_q] = np.arctan2(-lz, lx)
        if self.tool_q is not None:
            q[:, self.tool_q] = tool
        return q[0] if single else q

    def closure_residuals(self, q) -> np.ndarray:
        """Distance [m] between the two frames of each closure, shape (n_closures,) or (N, n_closures)."""
        qs = np.atleast_2d(np.asarray(q, dtype=float))
        out = np.empty((len(qs), len(self.constraint_models)))
        for n, qn in enumerate(qs):
            out[n] = [np.linalg.norm(r) for r in self._residual_parts(qn)]
        return out[0] if np.ndim(q) == 1 else out

    def _residual_parts(self, q: np.ndarray) -> list[np.ndarray]:
        pin.forwardKinematics(self.model, self._data, q)
        parts = []
        for cm, cd in zip(self.constraint_models, self._cdata):
            cm.calc(self.model, self._data, cd)
            parts.append(-cd.c1Mc2.translation.copy())   # frame1 - frame2, in frame1's axes
        return parts

    def constraint_jacobian(self, q) -> np.ndarray:
        """Stacked Jacobian of the closures at ``q`` (Pinocchio's ``getConstraintsJacobian``), shape (9, nv)."""
        q = np.asarray(q, dtype=float)
        pin.computeJointJacobians(self.model, self._data, q)
        for cm, cd in zip(self.constraint_models, self._cdata):
            cm.calc(self.model, self._data, cd)
        return pin.getConstraintsJacobian(self.model, self._data, self.constraint_models, self._cdata)

    def project(self, theta, q_start=None, *, chain: bool = False, tol: float = 1e-12, max_iter: int = 60
                ) -> np.ndarray:
        """Solve every passive joint for motor angles ``theta`` by Newton's projection onto the closures.

        The motor (and tool) coordinates stay fixed; the passive ones move along
        ``-J_passive^+ r`` (Pinocchio's constraint Jacobian and residual) until every closure
        residual is below ``tol`` [m].

        Args:
            theta: (3,) or (N, 3) motor angles [rad].
            q_start: starting configuration(s) of the passive joints (default: :meth:`home`,
                platform under the base centre).
            chain: start each row from the previous row's solution (a sampled motion, or samples
                sorted so that neighbours are close: a few Newton steps each).

        Raises:
            ProjectionFailed: a configuration did not converge (the message names its row).
        """
        th, single = self._theta(theta)
        start = np.atleast_2d(self.home() if q_start is None else np.asarray(q_start, dtype=float))
        out = np.empty((len(th), self.model.nq))
        for n, tn in enumerate(th):
            q0 = out[n - 1] if chain and n else start[min(n, len(start) - 1)]
            if chain and n:   # predictor: the passive joints' first-order change with the motors' (J_c dq = 0)
                q0 = q0.copy()
                step = jac[:, self.motor_q] @ (tn - q0[self.motor_q])
                q0[self.passive_q] -= np.linalg.solve(jac[:, self.passive_q], step)
            q, res, jac = self._newton(q0, tn, tol, max_iter)
            if res > tol:  # far from the start: walk the motors there in steps (a homotopy), projecting at each
                q = q0.copy()
                for frac in np.linspace(0.125, 1.0, 8):
                    q, res, jac = self._newton(q, (1.0 - frac) * q0[self.motor_q] + frac * tn, tol, max_iter)
            if res > tol:
                raise ProjectionFailed(f"{self.name}: projection of row {n} (theta = {tn.tolist()} rad) did not "
                                       f"reach {tol} m in {max_iter} iterations (residual {res:.3g} m): a singular "
                                       "pose or one that cannot be assembled")
            out[n] = q
        return out[0] if single else out

    def _newton(self, q_start: np.ndarray, theta: np.ndarray, tol: float, max_iter: int
                ) -> tuple[np.ndarray, float, np.ndarray]:
        """Newton's projection with the motors at ``theta``; returns the configuration, its largest residual
        and the constraint Jacobian there.

        Each step solves ``J_passive dq = -r`` (Pinocchio's constraint Jacobian and residual at q),
        halved until the residual norm decreases."""
        q = q_start.copy()
        q[self.motor_q] = theta
        cols = self.passive_q
        r, jac = self._evaluate(q)
        for _ in range(max_iter):
            if np.abs(r).max() <= tol:
                break
            try:
                step = np.linalg.solve(jac[:, cols], r)    # square for a delta: 9 equations, 9 passive joints
            except np.linalg.LinAlgError:
                step = np.linalg.lstsq(jac[:, cols], r, rcond=None)[0]
            norm = np.linalg.norm(r)
            for _ in range(30):
                trial = q.copy()
                trial[cols] -= step
                r_trial, jac_trial = self._evaluate(trial)
                if np.linalg.norm(r_trial) < norm:
                    break
                step *= 0.5
            q, r, jac = trial, r_trial, jac_trial
        return q, float(np.abs(r).max()), jac

    def _evaluate(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Closure residual (frame1 - frame2 in frame1's axes, stacked) and constraint Jacobian at ``q``."""
        pin.computeJointJacobians(self.model, self._data, q)       # forward kinematics included
        for cm, cd in zip(self.constraint_models, self._cdata):
            cm.calc(self.model, self._data, cd)
        r = np.concatenate([-cd.c1Mc2.translation for cd in self._cdata])
        return r, pin.getConstraintsJacobian(self.model, self._data, self.constraint_models, self._cdata)

    def home(self) -> np.ndarray:
        """Configuration at motor angles midway between their limits (closed form)."""
        mid = 0.5 * (self.limits.lower + self.limits.upper)
        return self.configuration(np.full(3, mid))

    def tcp_position(self, q) -> np.ndarray:
        """Position [m] of the ``tcp`` frame in the base frame (Pinocchio's FK), (3,) or (N, 3)."""
        qs = np.atleast_2d(np.asarray(q, dtype=float))
        out = np.empty((len(qs), 3))
        for n, qn in enumerate(qs):
            pin.framesForwardKinematics(self.model, self._data, qn)
            out[n] = self._data.oMf[self.tcp_frame].translation
        return out[0] if np.ndim(q) == 1 else out

    def with_payload(self, mass: float, offset=(0.0, 0.0, 0.0)) -> "DeltaRobot":
        """A copy carrying a point ``mass`` [kg] at ``offset`` [m] from the tcp (tcp frame axes)."""
        if not (np.isfinite(mass) and mass >= 0.0):
            raise DeltaInputError(f"payload mass must be a finite number >= 0 kg, got {mass!r}")
        model = self.model.copy()
        frame = model.frames[self.tcp_frame]
        com = frame.placement.act(np.asarray(offset, dtype=float))
        model.inertias[frame.parentJoint] += pin.Inertia(float(mass), com, np.zeros((3, 3)))
        loaded = DeltaRobot(model, self.closures, name=self.name, acceleration=self.limits.acceleration,
                            source=self.source, description=self.description, urdf_text=self.urdf_text)
        loaded.payloads = (*self.payloads, (float(mass), tuple(float(v) for v in np.asarray(offset, dtype=float))))
        return loaded
