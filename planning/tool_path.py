"""The tool's Cartesian path: straight lines between tcp poses, circular blends at the corners.

A :class:`ToolPath` is pure geometry (no robot, no time). Between consecutive poses
``T_k → T_{k+1}`` (tcp → base, m) the tool moves on a **straight line**:

* position linear, ``p(λ) = (1 − λ) p_k + λ p_{k+1}``;
* orientation by **SLERP**, ``R(λ) = R_k exp(λ φ_k)`` with ``φ_k = log(R_kᵀ R_{k+1})``
  (the shortest rotation, angle θ_k < π), at a constant angular rate.

Position and orientation are interpolated *separately* (not along the SE(3) geodesic,
whose position would follow a helix whenever the tool rotates): the tcp stays on the
segment whatever the rotation. ``λ`` is the same for both, so the two start and end
together.

**Arc length.** The path is parameterised by the arc length ``s`` of the metric
``ds² = |dp|² + w² |dθ|²`` with the weight ``w`` [m/rad] (default 0.1 m/rad: a rotation of
1 rad counts like 0.1 m of travel, the motion of a point 0.1 m from the rotation axis).
A line of length d turning θ has length ``sqrt(d² + w² θ²)``; a pure translation has
``s`` in metres of tcp travel exactly.

**Corners.** At an interior pose where the direction of travel changes the path is
*blended* when a blend radius ``r > 0`` is given: the tcp leaves the first line at
distance ``b = r tan(α/2)`` before the corner (α: the turning angle) and follows the
**circular arc** of radius ``r`` tangent to both lines, joining the second line ``b``
after the corner; it passes the corner at ``r (1/cos(α/2) − 1)``. The orientation over the
blend is ``R = R1 exp(β log(R1ᵀ R2))``, where R1 and R2 continue the SLERPs of the two
lines and ``β`` is the quintic smoothstep of the blend's progress: position and
orientation are continuous with continuous tangent (and angular rate) through the blend,
so the arm need not stop. On a straight corner (α = 0) where only the rotation rate
changes, the orientation is blended over ``±r`` along the line.

A corner is a **stop** (the tool comes to rest there; :attr:`ToolPath.stops`) when its
radius is 0 or it is listed in ``stops``, when the direction reverses (α = π: no arc
fits), or when a neighbouring segment only rotates. Where the tangent is continuous
(collinear poses with the same rotation rate) a pose is simply passed.

Units: m, rad; ``s`` in m (weighted, as above).
"""

from __future__ import annotations

from typing import Any, Iterable

import numpy as np

from pinarms.robots import so3 as _so3
from pinarms.planning._inputs import finite_array
from pinarms.planning.errors import BlendTooLarge, TrajectoryError

__all__ = ["ToolPath", "tool_path", "DEFAULT_WEIGHT"]

#: Default weight between rotation and translation in the arc length [m/rad].
DEFAULT_WEIGHT = 0.1

#: Nodes of the arc-length table of a blend that rotates (its s(ℓ) is integrated numerically).
_TABLE = 257


def _smoothstep(x: np.ndarray) -> np.ndarray:
    """Quintic smoothstep 10x³ − 15x⁴ + 6x⁵: 0 → 1 with zero first and second derivatives at both ends."""
    return x * x * x * (10.0 + x * (-15.0 + 6.0 * x))


def _check_poses(poses: Any) -> np.ndarray:
    P = finite_array(poses, "poses")
    if P.ndim != 3 or P.shape[1:] != (4, 4) or P.shape[0] < 2:
        raise TrajectoryError(f"poses must be (N, 4, 4) tcp → base transforms [m] with N >= 2, got shape {P.shape}")
    R = P[:, :3, :3]
    ortho = np.abs(R @ np.swapaxes(R, 1, 2) - np.eye(3)).max(axis=(1, 2))
    det = np.linalg.det(R)
    bad = np.flatnonzero((ortho > 1e-6) | (det < 0.0) | (np.abs(P[:, 3] - [0.0, 0.0, 0.0, 1.0]).max(axis=1) > 1e-9))
    if bad.size:
        k = int(bad[0])
        raise TrajectoryError(f"pose {k} is not a homogeneous transform (proper rotation within 1e-6, last row 0 0 0 1)")
    return P.copy()


class _Line:
    """Part ``λ ∈ [lam0, lam1]`` of the segment T_a → T_b (length ``L``); local s = (λ − lam0) L."""

    kind = "line"

    def __init__(self, Ta: np.ndarray, Tb: np.ndarray, phi: np.ndarray, L: float, lam0: float, lam1: float) -> None:
        self.pa, self.pb = Ta[:3, 3], Tb[:3, 3]
        self.Ra, self.Rb = Ta[:3, :3], Tb[:3, :3]
        self.phi, self.L, self.lam0 = phi, L, lam0
        self.length = (lam1 - lam0) * L
        self.d1 = np.concatenate([(self.pb - self.pa) / L, self.Ra @ phi / L])

    def evaluate(self, sigma: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        lam = self.lam0 + sigma / self.L
        n = lam.size
        T = np.zeros((n, 4, 4))
        T[:, 3, 3] = 1.0
        T[:, :3, 3] = (1.0 - lam)[:, None] * self.pa + lam[:, None] * self.pb
        first = lam <= 0.5  # each half from its own end: exact end poses
        R = np.empty((n, 3, 3))
        R[first] = self.Ra @ _so3.exp(lam[first, None] * self.phi)
        R[~first] = self.Rb @ _so3.exp(-(1.0 - lam[~first])[:, None] * self.phi)
        T[:, :3, :3] = R
        return T, np.broadcast_to(self.d1, (n, 6)).copy(), np.zeros((n, 6))


class _Blend:
    """Blend at a corner, local parameter ℓ ∈ [0, ℓ_b] (arc length of the position curve, m).

    ``R1(ℓ) = R_c exp(φ_in (ℓ − b) / d_in)`` and ``R2(ℓ) = R_c exp(φ_out (ℓ − ℓ_b + b) / d_out)``
    continue the SLERPs of the incoming and outgoing lines (R_c: the corner's orientation).
    """

    kind = "blend"

    def __init__(self, corner: np.ndarray, e_in: np.ndarray, e_out: np.ndarray, b: float, r: float, arc: bool,
                 Rc: np.ndarray, phi_in: np.ndarray, d_in: float, phi_out: np.ndarray, d_out: float,
                 weight: float) -> None:
        self.corner, self.e_in, self.b, self.r, self.arc = corner, e_in, b, r, arc
        self.Rc, self.w_in, self.w_out = Rc, phi_in / d_in, phi_out / d_out
        self.weight = weight
        if arc:
            alpha = float(np.arccos(np.clip(e_in @ e_out, -1.0, 1.0)))
            self.lb = r * alpha
            inward = e_out - e_in
            inward /= np.linalg.norm(inward)
            centre = corner + (r / np.cos(0.5 * alpha)) * inward
            start = corner - b * e_in
            self.centre, self.u, self.v = centre, (start - centre) / r, e_in
        else:
            self.lb = 2.0 * b
        self.rotates = bool(np.linalg.norm(self.w_in) + np.linalg.norm(self.w_out) > 0.0)
        if self.rotates:
            ell = np.linspace(0.0, self.lb, _TABLE)
            g = self._speed(ell)
            # composite Simpson on pairs of table intervals, trapezoid-consistent at odd nodes
            h = ell[1] - ell[0]
            s = np.zeros(_TABLE)
            s[2::2] = np.cumsum(h / 3.0 * (g[0:-2:2] + 4.0 * g[1:-1:2] + g[2::2]))
            mid = 0.5 * (ell[:-2:2] + ell[1:-1:2])
            s[1::2] = s[0:-2:2] + h / 6.0 * (g[0:-2:2] + 4.0 * self._speed(mid) + g[1:-1:2])
            self.table = (s, ell, 1.0 / g)
            self.length = float(s[-1])
        else:
            self.length = self.lb

    # ---------------------------------------------------------------- in ℓ
    def _rotation(self, ell: np.ndarray) -> np.ndarray:
        R1 = self.Rc @ _so3.exp((ell - self.b)[:, None] * self.w_in)
        R2 = self.Rc @ _so3.exp((ell - self.lb + self.b)[:, None] * self.w_out)
        beta = _smoothstep(ell / self.lb)
        return R1 @ _so3.exp(beta[:, None] * _so3.log(np.swapaxes(R1, 1, 2) @ R2))

    def _omega(self, ell: np.ndarray, h: float) -> np.ndarray:
        """Angular rate dθ/dℓ (N, 3) [rad/m] in base axes: central differences, Richardson-extrapolated (O(h⁴))."""
        def central(step: float) -> np.ndarray:
            Rp, Rm = self._rotation(ell + step), self._rotation(ell - step)
            return _so3.log(Rp @ np.swapaxes(Rm, 1, 2)) / (2.0 * step)

        return (4.0 * central(h) - central(2.0 * h)) / 3.0

    def _speed(self, ell: np.ndarray) -> np.ndarray:
        om = self._omega(ell, 1e-3 * self.lb)
        return np.sqrt(1.0 + self.weight**2 * np.sum(om * om, axis=1))

    def _ell(self, sigma: np.ndarray) -> np.ndarray:
        if not self.rotates:
            return sigma.copy()
        s, ell, slope = self.table
        k = np.clip(np.searchsorted(s, sigma, side="right") - 1, 0, s.size - 2)
        h = s[k + 1] - s[k]
        t = (sigma - s[k]) / h
        h00, h10 = (1 + 2 * t) * (1 - t) ** 2, t * (1 - t) ** 2
        h01, h11 = t * t * (3 - 2 * t), t * t * (t - 1)
        return h00 * ell[k] + h10 * h * slope[k] + h01 * ell[k + 1] + h11 * h * slope[k + 1]

    def evaluate(self, sigma: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        ell = self._ell(sigma)
        n = ell.size
        T = np.zeros((n, 4, 4))
        T[:, 3, 3] = 1.0
        if self.arc:
            c, s_ = np.cos(ell / self.r), np.sin(ell / self.r)
            T[:, :3, 3] = self.centre + self.r * (c[:, None] * self.u + s_[:, None] * self.v)
            p1 = -s_[:, None] * self.u + c[:, None] * self.v
            p2 = -(c[:, None] * self.u + s_[:, None] * self.v) / self.r
        else:
            T[:, :3, 3] = self.corner + (ell - self.b)[:, None] * self.e_in
            p1 = np.broadcast_to(self.e_in, (n, 3))
            p2 = np.zeros((n, 3))
        d1, d2 = np.zeros((n, 6)), np.zeros((n, 6))
        if not self.rotates:
            T[:, :3, :3] = self.Rc
            d1[:, :3], d2[:, :3] = p1, p2
            return T, d1, d2
        T[:, :3, :3] = self._rotation(ell)
        h = 1e-3 * self.lb
        om = self._omega(ell, h)
        om2 = (8.0 * (self._omega(ell + h, h) - self._omega(ell - h, h))
               - (self._omega(ell + 2.0 * h, h) - self._omega(ell - 2.0 * h, h))) / (12.0 * h)
        w2 = self.weight**2
        g = np.sqrt(1.0 + w2 * np.sum(om * om, axis=1))
        g1 = w2 * np.sum(om * om2, axis=1) / g
        l1 = 1.0 / g
        l2 = -g1 / g**3
        d1[:, :3] = p1 * l1[:, None]
        d1[:, 3:] = om * l1[:, None]
        d2[:, :3] = p2 * (l1 * l1)[:, None] + p1 * l2[:, None]
        d2[:, 3:] = om2 * (l1 * l1)[:, None] + om * l2[:, None]
        return T, d1, d2


class ToolPath:
    """Straight lines between tcp poses with optional blends at the corners (module docstring).

    Build one with :func:`tool_path`. Attributes:

    * ``poses`` (N, 4, 4): the given poses (tcp → base, m); ``weight`` [m/rad];
    * ``length`` [m, weighted]: the arc length of the whole path;
    * ``breaks`` (K+1,): arc lengths where its pieces (lines, blends) meet;
    * ``kinds``: ``"line"`` or ``"blend"`` per piece;
    * ``stops``: arc lengths of the interior corners where the tool stops (sorted);
    * ``via_s`` (N,): arc length at each pose (the middle of the blend for a blended corner);
    * ``radii`` (N-2,): the blend radius used at each interior pose [m] (0: none).
    """

    def __init__(self, poses: np.ndarray, pieces: list, stops: np.ndarray, via_s: np.ndarray, radii: np.ndarray,
                 weight: float) -> None:
        self.poses = poses
        self._pieces = pieces
        self.weight = float(weight)
        lengths = np.array([p.length for p in pieces])
        self.breaks = np.concatenate([[0.0], np.cumsum(lengths)])
        self.length = float(self.breaks[-1])
        self.kinds = tuple(p.kind for p in pieces)
        self.stops = np.asarray(stops, dtype=float)
        self.via_s = np.asarray(via_s, dtype=float)
        self.radii = np.asarray(radii, dtype=float)
        for arr in (self.poses, self.breaks, self.stops, self.via_s, self.radii):
            arr.flags.writeable = False

    def __repr__(self) -> str:
        return (f"ToolPath({self.poses.shape[0]} poses, length={self.length:.6g} m, "
                f"{self.kinds.count('blend')} blends, {self.stops.size} stops, weight={self.weight:g} m/rad)")

    def _arc(self, s: Any) -> tuple[np.ndarray, bool]:
        arr = finite_array(s, "arc length s")
        single = arr.ndim == 0
        arr = np.atleast_1d(arr)
        if arr.ndim != 1:
            raise TrajectoryError(f"arc length s must be a scalar or 1-D [m], got shape {arr.shape}")
        tol = 1e-12 * max(1.0, self.length)
        if arr.size and (arr.min() < -tol or arr.max() > self.length + tol):
            raise TrajectoryError(f"arc length s must lie in [0, {self.length!r}] m, got {arr.min()!r} .. {arr.max()!r}")
        return np.clip(arr, 0.0, self.length), single

    def evaluate(self, s: Any, side: str = "right") -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Pose and its first two derivatives in s at the arc lengths ``s`` [m].

        Returns ``(T (N, 4, 4), d1 (N, 6), d2 (N, 6))``: ``d1 = (dp/ds, ω)`` with ω the angular
        rate per unit s in base axes [rad/m] (dR/ds = [ω]× R), ``d2`` their derivatives in s.
        At a break between two pieces ``side="right"`` uses the piece that starts there
        (``"left"``: the one that ends there); they differ at a stop (tangent) and where a
        line meets an arc (curvature).
        """
        arr, _ = self._arc(s)
        if side not in ("left", "right"):
            raise TrajectoryError(f"side must be 'left' or 'right', got {side!r}")
        m = len(self._pieces)
        idx = np.clip(np.searchsorted(self.breaks, arr, side=side) - 1, 0, m - 1)
        T = np.empty((arr.size, 4, 4))
        d1 = np.empty((arr.size, 6))
        d2 = np.empty((arr.size, 6))
        for k in np.unique(idx):  # one call per piece (a handful)
            sel = idx == k
            T[sel], d1[sel], d2[sel] = self._pieces[k].evaluate(arr[sel] - self.breaks[k])
        return T, d1, d2

    def pose(self, s: Any) -> np.ndarray:
        """tcp pose(s) at arc length ``s`` [m]: (4, 4) for a scalar, (N, 4, 4) for (N,)."""
        arr, single = self._arc(s)
        T = self.evaluate(arr)[0]
        return T[0] if single else T

    def position(self, s: Any) -> np.ndarray:
        """tcp position(s) [m] at ``s``: (3,) or (N, 3)."""
        return self.pose(s)[..., :3, 3]

    def as_dict(self) -> dict[str, Any]:
        """JSON-able summary (SI units)."""
        return {"poses": self.poses.tolist(), "weight_m_per_rad": self.weight, "length_m": self.length,
                "breaks_m": self.breaks.tolist(), "kinds": list(self.kinds), "stops_m": self.stops.tolist(),
                "via_s_m": self.via_s.tolist(), "blend_radii_m": self.radii.tolist()}


def tool_path(poses: Any, *, blend: Any = 0.0, weight: float = DEFAULT_WEIGHT, stops: Iterable[int] = ()) -> ToolPath:
    """Straight lines through tcp ``poses`` with circular blends at the corners (module docstring).

    Args:
        poses: (N, 4, 4) tcp → base poses [m], N >= 2.
        blend: corner radius [m], one for every interior pose or (N-2,) per pose; 0: stop there.
        weight: w [m/rad] of the arc length ``ds² = |dp|² + w² dθ²`` (> 0).
        stops: indices (1 .. N-2) of interior poses where the tool must stop (no blend).

    Raises:
        TrajectoryError: malformed poses, two equal consecutive poses, a half-turn (π) between
            consecutive orientations (its direction is ambiguous: add a pose), bad ``blend``,
            ``weight`` or ``stops``.
        BlendTooLarge: a corner's blend needs more of a line than is left; the message gives
            the largest radius that fits.
    """
    P = _check_poses(poses)
    n = P.shape[0]
    w = float(weight) if isinstance(weight, (int, float, np.floating, np.integer)) and not isinstance(weight, bool) else -1.0
    if not (np.isfinite(w) and w > 0.0):
        raise TrajectoryError(f"weight must be a positive number of m/rad, got {weight!r}")
    r = finite_array(blend, "blend radius [m]")
    if r.ndim == 0:
        r = np.full(n - 2, float(r))
    if r.shape != (n - 2,) or np.any(r < 0.0):
        raise TrajectoryError(f"blend must be one radius >= 0 [m] or one per interior pose ({n - 2}), got {blend!r}")
    stop_set = set()
    for k in stops:
        if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or not 1 <= int(k) <= n - 2:
            raise TrajectoryError(f"stops must be indices of interior poses (1 .. {n - 2}), got {k!r}")
        stop_set.add(int(k))

    p, R = P[:, :3, 3], P[:, :3, :3]
    d = np.linalg.norm(np.diff(p, axis=0), axis=1)
    phi = _so3.log(np.swapaxes(R[:-1], 1, 2) @ R[1:])  # body rotation vector of each segment
    theta = np.linalg.norm(phi, axis=1)
    L = np.sqrt(d * d + w * w * theta * theta)
    for k in range(n - 1):
        if L[k] <= 1e-12:
            raise TrajectoryError(f"poses {k} and {k + 1} are equal: remove one")
        if theta[k] > np.pi - 1e-6:
            raise TrajectoryError(f"poses {k} and {k + 1} differ by a half-turn ({np.degrees(theta[k]):.4f}°): the "
                                  "direction of rotation is ambiguous; add a pose between them")
    translating = d > 1e-12
    e = np.where(translating[:, None], np.diff(p, axis=0) / np.where(translating, d, 1.0)[:, None], 0.0)
    tangent = np.concatenate([np.diff(p, axis=0), w * np.einsum("kij,kj->ki", R[:-1], phi)], axis=1) / L[:, None]

    # classify the corners: b[k] = tangent length of a blend at pose k (0: none), arc flag
    b = np.zeros(n)
    arc = np.zeros(n, dtype=bool)
    is_stop = np.zeros(n, dtype=bool)
    used = np.zeros(n)
    for k in range(1, n - 1):
        if np.linalg.norm(tangent[k - 1] - tangent[k]) <= 1e-9:
            continue  # smooth: passed without blend or stop
        rk = r[k - 1]
        if k in stop_set or rk == 0.0 or not (translating[k - 1] and translating[k]):
            is_stop[k] = True
            continue
        alpha = float(np.arccos(np.clip(e[k - 1] @ e[k], -1.0, 1.0)))
        if alpha >= np.pi - 1e-6:
            is_stop[k] = True  # reversal: no arc fits
            continue
        arc[k] = alpha > 1e-9
        b[k] = rk * np.tan(0.5 * alpha) if arc[k] else rk
        used[k] = rk
    for k in range(n - 1):
        if b[k] + b[k + 1] > d[k] * (1.0 + 1e-12) + 1e-15:
            corner = k if b[k] >= b[k + 1] else k + 1
            other = b[k + 1] if corner == k else b[k]
            alpha = float(np.arccos(np.clip(e[corner - 1] @ e[corner], -1.0, 1.0)))
            fits = max(d[k] - other, 0.0) / (np.tan(0.5 * alpha) if arc[corner] else 1.0)
            shared = f", {other:.6g} m already used by the other blend" if other else ""
            raise BlendTooLarge(
                f"the blend of radius {used[corner]:g} m at pose {corner} needs {b[corner]:.6g} m of line {k} "
                f"(poses {k}–{k + 1}, {d[k]:.6g} m long{shared}); use a radius <= {fits:.6g} m there"
            )

    pieces: list = []
    via_s = np.zeros(n)
    stop_s = []
    s_now = 0.0
    for k in range(n - 1):
        lam0 = b[k] / d[k] if b[k] > 0.0 else 0.0
        lam1 = 1.0 - (b[k + 1] / d[k] if b[k + 1] > 0.0 else 0.0)
        if lam1 - lam0 > 1e-12:
            piece = _Line(P[k], P[k + 1], phi[k], float(L[k]), lam0, lam1)
            pieces.append(piece)
            s_now += piece.length
        if k + 1 < n - 1:
            if b[k + 1] > 0.0:
                blend_piece = _Blend(p[k + 1], e[k], e[k + 1], float(b[k + 1]), float(r[k]), bool(arc[k + 1]),
                                     R[k + 1], phi[k], float(d[k]), phi[k + 1], float(d[k + 1]), w)
                pieces.append(blend_piece)
                via_s[k + 1] = s_now + 0.5 * blend_piece.length
                s_now += blend_piece.length
            else:
                via_s[k + 1] = s_now
                if is_stop[k + 1]:
                    stop_s.append(s_now)
    via_s[-1] = s_now
    return ToolPath(P, pieces, np.array(stop_s), via_s, np.where(b[1:-1] > 0.0, r, 0.0), w)
