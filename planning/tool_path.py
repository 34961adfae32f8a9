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

from typing import Any, Iterable, NamedTuple

import numpy as np
from numpy.typing import ArrayLike

from pinarms.robots import so3 as _so3
from pinarms.planning._inputs import finite_array
from pinarms.planning.errors import BlendTooLarge, TrajectoryError
from pinarms.planning.tool_pieces import Blend, BlendCorner, Line

__all__ = ["ToolPath", "tool_path", "DEFAULT_WEIGHT"]

#: Default weight between rotation and translation in the arc length [m/rad].
DEFAULT_WEIGHT = 0.1

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

    def evaluate(self, s: ArrayLike, side: str = "right") -> tuple[np.ndarray, np.ndarray, np.ndarray]:
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

    def pose(self, s: ArrayLike) -> np.ndarray:
        """tcp pose(s) at arc length ``s`` [m]: (4, 4) for a scalar, (N, 4, 4) for (N,)."""
        arr, single = self._arc(s)
        T = self.evaluate(arr)[0]
        return T[0] if single else T

    def position(self, s: ArrayLike) -> np.ndarray:
        """tcp position(s) [m] at ``s``: (3,) or (N, 3)."""
        return self.pose(s)[..., :3, 3]

    def as_dict(self) -> dict[str, Any]:
        """JSON-able summary (SI units)."""
        return {"poses": self.poses.tolist(), "weight_m_per_rad": self.weight, "length_m": self.length,
                "breaks_m": self.breaks.tolist(), "kinds": list(self.kinds), "stops_m": self.stops.tolist(),
                "via_s_m": self.via_s.tolist(), "blend_radii_m": self.radii.tolist()}


def tool_path(poses: ArrayLike, *, blend: ArrayLike = 0.0, weight: float = DEFAULT_WEIGHT, stops: Iterable[int] = ()) -> ToolPath:
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
    w, r, stop_set = _options(P.shape[0], blend, weight, stops)
    seg = _segments(P, w)
    b, arc, is_stop = _corners(seg, r, stop_set)
    pieces, via_s, stop_s = _pieces(P, seg, r, b, arc, is_stop, w)
    return ToolPath(P, pieces, np.array(stop_s), via_s, np.where(b[1:-1] > 0.0, r, 0.0), w)


class _Segments(NamedTuple):
    """The straight segments between consecutive poses: positions p (N, 3) and rotations R (N, 3, 3) of the
    poses, then per segment its length d [m], body rotation vector φ (N-1, 3) [rad], arc length L [m],
    whether it translates, unit direction e (N-1, 3) (0 when it only rotates) and unit tangent (N-1, 6)."""

    p: np.ndarray
    R: np.ndarray
    d: np.ndarray
    phi: np.ndarray
    L: np.ndarray
    translating: np.ndarray
    e: np.ndarray
    tangent: np.ndarray


def _options(n: int, blend: Any, weight: float, stops: Iterable[int]) -> tuple[float, np.ndarray, set]:
    """The weight w [m/rad], one blend radius per interior pose (n-2,) [m] and the set of stop indices,
    checked (TrajectoryError naming the bad input)."""
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
    return w, r, stop_set


def _segments(P: np.ndarray, w: float) -> _Segments:
    """The segments between consecutive poses ``P`` (N, 4, 4); equal poses and half-turns are refused."""
    n = P.shape[0]
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
    return _Segments(p, R, d, phi, L, translating, e, tangent)


def _corners(seg: _Segments, r: np.ndarray, stop_set: set) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Classify the interior poses (module docstring, corners): per pose (N,) the tangent length b [m] of
    its blend (0: none), whether the blend is an arc, and whether the tool stops there.

    Raises:
        BlendTooLarge: two blends, or a blend and a segment's end, need more of a line than it has.
    """
    n = seg.p.shape[0]
    b = np.zeros(n)
    arc = np.zeros(n, dtype=bool)
    is_stop = np.zeros(n, dtype=bool)
    used = np.zeros(n)
    for k in range(1, n - 1):
        if np.linalg.norm(seg.tangent[k - 1] - seg.tangent[k]) <= 1e-9:
            continue  # smooth: passed without blend or stop
        rk = r[k - 1]
        if k in stop_set or rk == 0.0 or not (seg.translating[k - 1] and seg.translating[k]):
            is_stop[k] = True
            continue
        alpha = float(np.arccos(np.clip(seg.e[k - 1] @ seg.e[k], -1.0, 1.0)))
        if alpha >= np.pi - 1e-6:
            is_stop[k] = True  # reversal: no arc fits
            continue
        arc[k] = alpha > 1e-9
        b[k] = rk * np.tan(0.5 * alpha) if arc[k] else rk
        used[k] = rk
    _check_blends_fit(seg, b, arc, used)
    return b, arc, is_stop


def _check_blends_fit(seg: _Segments, b: np.ndarray, arc: np.ndarray, used: np.ndarray) -> None:
    """BlendTooLarge, with the largest radius that fits, when the blends at both ends of a line overlap."""
    d, e = seg.d, seg.e
    for k in range(seg.p.shape[0] - 1):
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


def _pieces(P: np.ndarray, seg: _Segments, r: np.ndarray, b: np.ndarray, arc: np.ndarray, is_stop: np.ndarray,
            w: float) -> tuple[list, np.ndarray, list]:
    """The path's pieces in order (what is left of each line, a blend at each blended corner), the arc
    length of every pose along the path (N,) [m] (a blend's middle for a blended one) and of every stop."""
    n = P.shape[0]
    p, R, d, phi, L, e = seg.p, seg.R, seg.d, seg.phi, seg.L, seg.e
    pieces: list = []
    via_s = np.zeros(n)
    stop_s = []
    s_now = 0.0
    for k in range(n - 1):
        lam0 = b[k] / d[k] if b[k] > 0.0 else 0.0
        lam1 = 1.0 - (b[k + 1] / d[k] if b[k + 1] > 0.0 else 0.0)
        if lam1 - lam0 > 1e-12:
            piece = Line(P[k], P[k + 1], phi[k], float(L[k]), lam0, lam1)
            pieces.append(piece)
            s_now += piece.length
        if k + 1 < n - 1:
            if b[k + 1] > 0.0:
                at = BlendCorner(p[k + 1], e[k], e[k + 1], float(b[k + 1]), float(r[k]), bool(arc[k + 1]))
                blend_piece = Blend(at, R[k + 1], phi[k], float(d[k]), phi[k + 1], float(d[k + 1]), w)
                pieces.append(blend_piece)
                via_s[k + 1] = s_now + 0.5 * blend_piece.length
                s_now += blend_piece.length
            else:
                via_s[k + 1] = s_now
                if is_stop[k + 1]:
                    stop_s.append(s_now)
    via_s[-1] = s_now
    return pieces, via_s, stop_s
