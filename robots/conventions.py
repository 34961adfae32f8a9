"""The papers' kinematic conventions (and, from :mod:`pinarms.units`, the unit conversions).

The unit conversions (``deg_to_rad``, ``mm_to_m``, ``wrap_angle``, ...) live in
:mod:`pinarms.units`, the one units module; they stay importable from here.

Everything inside pinarms is SI (m, rad, s). The papers print millimetres and degrees,
and two of them use joint conventions that differ from the models':

* **AUBO-i3 (seed 001).** The model (``urdf/aubo_i3.urdf``) uses the manufacturer's joint
  zero and directions; the paper uses modified (Craig) D-H angles θ. Checked against the
  model over random configurations (tests/robots/test_aubo.py), exactly (≈1e-15 m)::

      θ = (q1, q2 − π/2, −q3, π/2 − q4, q5, −q6)
      T_base_link←flange(q) = Rz(π) · T_0←6^MDH(θ) · Rz(π)

  i.e. the paper's D-H base frame is the model's ``base_link`` turned 180° about z, and
  the paper's frame 6 is the ``flange`` turned 180° about its z. The paper's statement
  "the model matches the real robot at θ2 = −90°, θ4 = 90°, the other joints 0" is the
  manufacturer's zero pose q = 0 (arm upright).
* **Koji arm (seed 004).** :func:`koji_fk_paper` is the paper's forward kinematics
  T4 = T3′·Rot(z, θ4)·Trans(0, H, 0) with the parallelogram's absolute forearm angle, in
  closed form (docs/robots/koji_turner.md compares it with the printed expansion).
* **Gantry (seed 002).** The paper's limits are motor-side (rad/s, rad/s², rad/s³);
  :func:`gantry_motor_to_axis` maps them to the axis side (m/s, ...) with the chosen
  transmission :data:`GANTRY_TRANSMISSION_M_PER_RAD`.
"""

from __future__ import annotations

import numpy as np

from pinarms.errors import InvalidInput
from pinarms.units import as_float_array, deg_to_rad, m_to_mm, mm_to_m, rad_to_deg, wrap_angle

__all__ = [
    "deg_to_rad",
    "rad_to_deg",
    "mm_to_m",
    "m_to_mm",
    "wrap_angle",
    "AUBO_MDH",
    "AUBO_MDH_BASE_IN_BASE_LINK",
    "AUBO_FLANGE_IN_MDH6",
    "aubo_joint_to_mdh",
    "aubo_mdh_to_joint",
    "aubo_fk_mdh",
    "aubo_flange_from_mdh",
    "KOJI_A2",
    "KOJI_A3",
    "KOJI_D1",
    "KOJI_H",
    "koji_fk_paper",
    "GANTRY_TRANSMISSION_M_PER_RAD",
    "gantry_motor_to_axis",
]


# ---------------------------------------------------------------------------------------
# AUBO-i3 (seed 001)

#: Paper's modified D-H table (seed 001, table 1) with the manufacturer's lengths (m):
#: rows (alpha_{i-1} [rad], a_{i-1} [m], d_i [m]) for i = 1..6.
AUBO_MDH: np.ndarray = np.array(
    [
        [0.0, 0.0, 0.157],
        [-np.pi / 2, 0.0, 0.119],
        [0.0, 0.266, 0.0],
        [0.0, 0.2565, 0.0],
        [np.pi / 2, 0.0, 0.1025],
        [-np.pi / 2, 0.0, 0.094],
    ]
)
_RZ_PI = np.diag([-1.0, -1.0, 1.0, 1.0])
#: Pose of the paper's D-H base frame 0 in the model's ``base_link``: Rz(π).
AUBO_MDH_BASE_IN_BASE_LINK: np.ndarray = _RZ_PI.copy()
#: Pose of the model's ``flange`` in the paper's D-H frame 6: Rz(π).
AUBO_FLANGE_IN_MDH6: np.ndarray = _RZ_PI.copy()

# θ = sign * q + offset, joint by joint
_AUBO_SIGN = np.array([1.0, 1.0, -1.0, -1.0, 1.0, -1.0])
_AUBO_OFFSET = np.array([0.0, -np.pi / 2, 0.0, np.pi / 2, 0.0, 0.0])


def _six(x, what: str) -> np.ndarray:
    a = as_float_array(x, what)
    if a.ndim not in (1, 2) or a.shape[-1] != 6:
        raise InvalidInput(f"{what} must have shape (6,) or (N, 6), got {a.shape}")
    return a


def aubo_joint_to_mdh(q, wrap: bool = True) -> np.ndarray:
    """Manufacturer joint values q (rad, (6,) or (N,6)) → the paper's modified D-H angles θ.

    θ = (q1, q2 − π/2, −q3, π/2 − q4, q5, −q6); wrapped to [−π, π) when ``wrap``.
    """
    q = _six(q, "q")
    theta = _AUBO_SIGN * q + _AUBO_OFFSET
    return wrap_angle(theta) if wrap else theta


def aubo_mdh_to_joint(theta, wrap: bool = True) -> np.ndarray:
    """The paper's modified D-H angles θ (rad, (6,) or (N,6)) → manufacturer joint values q.

    Inverse of :func:`aubo_joint_to_mdh`: q = (θ1, θ2 + π/2, −θ3, π/2 − θ4, θ5, −θ6).
    """
    theta = _six(theta, "theta")
    q = _AUBO_SIGN * (theta - _AUBO_OFFSET)
    return wrap_angle(q) if wrap else q


def aubo_fk_mdh(theta) -> np.ndarray:
    """The paper's forward kinematics T_0←6 (frame 6 in the D-H base frame 0), vectorised.

    Craig's convention: T_{i-1←i} = Rot(x, α_{i-1}) Trans(a_{i-1}, 0, 0) Rot(z, θ_i) Trans(0, 0, d_i)
    with :data:`AUBO_MDH`. ``theta`` (rad) of shape (6,) → (4, 4); (N, 6) → (N, 4, 4); metres.
    """
    theta = _six(theta, "theta")
    batch = theta.reshape(-1, 6)
    n = batch.shape[0]
    out = np.broadcast_to(np.eye(4), (n, 4, 4)).copy()
    for i, (alpha, a, d) in enumerate(AUBO_MDH):  # loop over the 6 joints, not over samples
        ct, st = np.cos(batch[:, i]), np.sin(batch[:, i])
        ca, sa = np.cos(alpha), np.sin(alpha)
        link = np.zeros((n, 4, 4))
        link[:, 0, 0], link[:, 0, 1], link[:, 0, 3] = ct, -st, a
        link[:, 1, 0], link[:, 1, 1], link[:, 1, 2], link[:, 1, 3] = st * ca, ct * ca, -sa, -sa * d
        link[:, 2, 0], link[:, 2, 1], link[:, 2, 2], link[:, 2, 3] = st * sa, ct * sa, ca, ca * d
        link[:, 3, 3] = 1.0
        out = out @ link
    return out[0] if theta.ndim == 1 else out


def aubo_flange_from_mdh(theta) -> np.ndarray:
    """Pose of the model's ``flange`` in ``base_link`` computed from the paper's θ (rad).

    Rz(π) · T_0←6(θ) · Rz(π); shapes as :func:`aubo_fk_mdh`.
    """
    return AUBO_MDH_BASE_IN_BASE_LINK @ aubo_fk_mdh(theta) @ AUBO_FLANGE_IN_MDH6


# ---------------------------------------------------------------------------------------
# Koji arm (seed 004)

#: Upper arm a2, forearm a3, waist pivot height d1 (the arm hangs) and wrist reach H (m).
KOJI_A2, KOJI_A3, KOJI_D1, KOJI_H = 0.700, 0.650, -0.900, 0.250


def koji_fk_paper(theta) -> np.ndarray:
    """Seed 004's forward kinematics of the reach point (the model's ``tcp``), vectorised.

    ``theta`` = (θ1 waist, θ2 upper-arm pitch, θ3 forearm ABSOLUTE pitch (positive up),
    θ4 wrist), rad, shape (4,) or (N, 4). Returns T_base←tcp, (4, 4) or (N, 4, 4), metres::

        r = a2 cos θ2 + a3 cos θ3,      z = d1 + a2 sin θ2 + a3 sin θ3
        p = (−r sin θ1 − H sin(θ1+θ4),  r cos θ1 + H cos(θ1+θ4),  z)
        R = Rot(z, θ1 + θ4)                 (the parallelogram keeps the hand level)

    This is T4 = T3′·Rot(z, θ4)·Trans(0, H, 0) of the paper's eq. (6) with T3′'s position
    taken from the parallelogram (absolute forearm angle), which reproduces its first
    printed example; the printed expansion of P has typos (docs/robots/koji_turner.md).
    """
    t = as_float_array(theta, "theta")
    if t.ndim not in (1, 2) or t.shape[-1] != 4:
        raise InvalidInput(f"theta must have shape (4,) or (N, 4), got {t.shape}")
    b = t.reshape(-1, 4)
    t1, t2, t3, t4 = b.T
    r = KOJI_A2 * np.cos(t2) + KOJI_A3 * np.cos(t3)
    heading = t1 + t4
    out = np.zeros((b.shape[0], 4, 4))
    out[:, 0, 0], out[:, 0, 1] = np.cos(heading), -np.sin(heading)
    out[:, 1, 0], out[:, 1, 1] = np.sin(heading), np.cos(heading)
    out[:, 2, 2] = out[:, 3, 3] = 1.0
    out[:, 0, 3] = -r * np.sin(t1) - KOJI_H * np.sin(heading)
    out[:, 1, 3] = r * np.cos(t1) + KOJI_H * np.cos(heading)
    out[:, 2, 3] = KOJI_D1 + KOJI_A2 * np.sin(t2) + KOJI_A3 * np.sin(t3)
    return out[0] if t.ndim == 1 else out


# ---------------------------------------------------------------------------------------
# Gantry (seed 002)

#: Axis travel per motor radian (m/rad), chosen: e.g. a 5:1 reducer on a 50 mm-radius
#: pinion (0.05 m / 5). Seed 002 does not print its transmission.
GANTRY_TRANSMISSION_M_PER_RAD: float = 0.01


def gantry_motor_to_axis(value_motor, transmission_m_per_rad: float = GANTRY_TRANSMISSION_M_PER_RAD) -> np.ndarray:
    """Motor-side quantity (rad, rad/s, rad/s², rad/s³) → axis side (m, m/s, m/s², m/s³).

    The transmission is linear, so every derivative scales by the same factor. Seed 002's
    limits v 100 rad/s, a 1500 rad/s², jerk 20000 rad/s³ become 1.0 m/s, 15 m/s², 200 m/s³.
    """
    if not np.isfinite(transmission_m_per_rad) or transmission_m_per_rad <= 0:
        raise InvalidInput(f"transmission_m_per_rad must be a positive number, got {transmission_m_per_rad!r}")
    return as_float_array(value_motor, "value_motor") * float(transmission_m_per_rad)
