"""Closed-form position kinematics of a delta: three motor angles <-> platform centre [rad, m].

Forward: the platform centre is where three spheres meet, of radius l about the "virtual
elbows" ``C_i = E_i - r e_i`` (Williams 2015, docs/delta.md); two assembly modes, the lower
one (platform under the base) is the robot's. Inverse: each leg alone, ``A cos t + B sin t = K``
with ``A = -2 a L``, ``B = 2 z L``, ``K = l^2 - y^2 - a^2 - z^2 - L^2`` in the leg's frame
(``a = x - (R - r)``), so ``t = atan2(B, A) +/- acos(K / hypot(A, B))``: two branches a leg,
eight in all. Everything takes batches: ``theta`` (N, 3) or (3,), ``p`` (N, 3) or (3,).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from pinarms.robots.delta.errors import DeltaInputError, DeltaUnreachable
from pinarms.robots.delta.geometry import DeltaGeometry

__all__ = ["as_points", "virtual_elbows", "elbow_positions", "forward_position", "inverse_position_branches",
           "inverse_position", "BRANCH_COUNT", "PRIMARY_BRANCH", "branch_signs"]

#: IK branches: two per leg.
BRANCH_COUNT = 8
#: The branch every leg's elbow points outward (the robot's working branch).
PRIMARY_BRANCH = 0


def as_points(values: ArrayLike, what: str) -> tuple[np.ndarray, bool]:
    """``values`` as an (N, 3) float array and whether it was one (3,) row (``what`` names it in the error).

    Raises:
        DeltaInputError: another shape, or a value that is not finite.
    """
    arr = np.asarray(values, dtype=float)
    single = arr.ndim == 1
    arr = np.atleast_2d(arr)
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise DeltaInputError(f"{what} must have shape (3,) or (N, 3), got {np.shape(values)}")
    if not np.all(np.isfinite(arr)):
        raise DeltaInputError(f"{what} holds a value that is not finite (NaN or inf)")
    return arr, single


def elbow_positions(geom: DeltaGeometry, theta) -> np.ndarray:
    """Elbow centres ``E_i`` [m], shape (N, 3 legs, 3) (or (3, 3) for one ``theta``)."""
    th, single = as_points(theta, "theta")
    e, z = geom.radial, np.array([0.0, 0.0, 1.0])
    out = (geom.base_radius + geom.upper_arm * np.cos(th))[:, :, None] * e[None] \
        - (geom.upper_arm * np.sin(th))[:, :, None] * z
    return out[0] if single else out


def virtual_elbows(geom: DeltaGeometry, theta) -> np.ndarray:
    """Sphere centres ``C_i = E_i - r e_i`` [m], shape (N, 3, 3): the platform centre is l from each."""
    th, single = as_points(theta, "theta")
    out = elbow_positions(geom, th) - geom.platform_radius * geom.radial[None]
    return out[0] if single else out


def forward_position(geom: DeltaGeometry, theta, *, assembly: str = "lower") -> np.ndarray:
    """Platform centre [m] of motor angles ``theta`` [rad].

    Args:
        assembly: ``"lower"`` (the robot's mode: platform below the elbows) or ``"upper"``.

    Returns:
        (3,) or (N, 3); rows that cannot be assembled (the spheres do not meet) are NaN in a batch.

    Raises:
        DeltaUnreachable: one ``theta`` that cannot be assembled.
    """
    if assembly not in ("lower", "upper"):
        raise DeltaInputError(f"assembly must be 'lower' or 'upper', got {assembly!r}")
    th, single = as_points(theta, "theta")
    c = virtual_elbows(geom, th)
    c1, d2, d3 = c[:, 0], c[:, 1] - c[:, 0], c[:, 2] - c[:, 0]
    n = np.cross(d2, d3)
    nn = np.einsum("ij,ij->i", n, n)
    sq = np.einsum("nij,nij->ni", c, c)
    b2, b3 = 0.5 * (sq[:, 1] - sq[:, 0]), 0.5 * (sq[:, 2] - sq[:, 0])
    with np.errstate(divide="ignore", invalid="ignore"):
        p0 = (b2[:, None] * np.cross(d3, n) + b3[:, None] * np.cross(n, d2)) / nn[:, None]
        w = p0 - c1
        wn = np.einsum("ij,ij->i", w, n)
        disc = wn ** 2 - nn * (np.einsum("ij,ij->i", w, w) - geom.forearm ** 2)
        root = np.sqrt(disc)
        sign = -np.sign(n[:, 2]) if assembly == "lower" else np.sign(n[:, 2])
        t = (-wn + sign * root) / nn
        p = p0 + t[:, None] * n
    p[~(disc >= 0.0) | ~(nn > 0.0)] = np.nan
    if single:
        if np.isnan(p[0]).any():
            raise DeltaUnreachable(f"motor angles {th[0].tolist()} rad cannot be assembled: the forearms "
                                   f"({geom.forearm} m) do not reach a common platform position")
        return p[0]
    return p


def branch_signs(branch: int) -> np.ndarray:
    """Per-leg branch of IK branch ``branch`` (0..7): 0 = elbow outward, 1 = inward (bit i = leg i+1)."""
    if not 0 <= int(branch) < BRANCH_COUNT:
        raise DeltaInputError(f"branch must be 0..{BRANCH_COUNT - 1}, got {branch}")
    return np.array([(int(branch) >> k) & 1 for k in range(3)])


def inverse_position_branches(geom: DeltaGeometry, p) -> tuple[np.ndarray, np.ndarray]:
    """Every IK branch of platform centres ``p`` [m].

    Returns:
        ``(theta, real)``: ``theta`` (N, 8, 3) [rad] (NaN where a leg cannot reach), ``real``
        (N, 8) bool; branch ``b`` takes leg ``i``'s outward (bit 0) or inward (bit 1) root,
        see :func:`branch_signs`. Joint limits are not applied here.
    """
    pts, single = as_points(p, "p")
    e, u = geom.radial, geom.tangential
    x = pts @ e.T                                            # (N, 3 legs) along e_i
    y = pts @ u.T
    z = pts[:, 2:3]
    a = x - (geom.base_radius - geom.platform_radius)
    big_l = geom.upper_arm
    coef_a, coef_b = -2.0 * a * big_l, 2.0 * z * big_l
    k = geom.forearm ** 2 - y ** 2 - a ** 2 - z ** 2 - big_l ** 2
    rho = np.hypot(coef_a, coef_b)
    with np.errstate(invalid="ignore", divide="ignore"):
        half = np.arccos(k / rho)                            # NaN beyond reach
    base = np.arctan2(coef_b, coef_a)
    roots = np.stack([base + half, base - half], axis=-1)    # (N, 3, 2)
    roots = (roots + np.pi) % (2.0 * np.pi) - np.pi
    outward = np.cos(roots[..., 0]) >= np.cos(roots[..., 1])  # order: elbow farther out first
    roots = np.where(outward[..., None], roots, roots[..., ::-1])
    theta = np.empty((len(pts), BRANCH_COUNT, 3))
    for b in range(BRANCH_COUNT):
        s = branch_signs(b)
        theta[:, b] = roots[:, np.arange(3), s]
    real = ~np.isnan(theta).any(axis=2)
    if single:
        return theta[0], real[0]
    return theta, real


def inverse_position(geom: DeltaGeometry, p, *, branch: int = PRIMARY_BRANCH) -> np.ndarray:
    """Motor angles [rad] of platform centres ``p`` [m] on one IK branch (default: elbows outward).

    Returns:
        (3,) or (N, 3); unreachable rows are NaN in a batch.

    Raises:
        DeltaUnreachable: one ``p`` out of reach.
    """
    theta, real = inverse_position_branches(geom, p)
    theta = theta[..., int(branch), :] if theta.ndim == 3 else theta[int(branch)]
    if theta.ndim == 1 and np.isnan(theta).any():
        raise DeltaUnreachable(f"platform position {np.asarray(p).tolist()} m is out of the delta's reach "
                               f"(a forearm of {geom.forearm} m cannot meet its elbow)")
    return theta
