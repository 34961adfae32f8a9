"""The pairs a cell's deltas form, which of them are checked, and their distances (coal, exact).

Every body of a delta (:mod:`.delta_arm`) is paired with every collision geometry of the cell's
tree (fixtures, the serial arms' links), every body of every other delta, and every body of its
own delta. A pair is **not checked** (:class:`~pinarms.robots.pair_rules.AllowedPair`) only for
these reasons:

``adjacent``
    two bodies of one delta joined at a joint by design: the base and each upper arm (the
    motor), each upper arm and its two rods (the upper ball joints), each rod and the platform
    (the lower ball joints), the platform and the tool; and, with a note, the two rods of
    neighbouring legs whose lower ball centres on the platform are closer than two rod radii
    (:func:`meeting_rods`; in the shipped FlexPicker, Williams' platform triangle puts them
    10.5 mm apart, the rods are 16 mm thick): the platform rigidly holds both ends, so their
    capsules overlap there in every configuration, by design;
``rigid``
    the delta's base housing and a geometry that does not move either (a fixture, a serial
    arm's fixed base parts, another delta's base): their distance never changes.

Every other pair of the kinds the cell checks (:attr:`Cell.kinds`, :meth:`Cell.with_pairs`) is a
checked :class:`~pinarms.robots.cell.pairs.CollisionPair` (``index_a`` −1: the delta's body is not
in the cell's collision model; ``index_b`` the other's index there, or −1 for another delta's
body), of kind ``"self"`` (two bodies of one delta: the rods of one parallelogram included, they
stay ``rod_spacing`` apart along the motor axis but their distance changes with the elbow's
swing), ``"arm-arm"`` or ``"arm-fixture"``.

Distances (:class:`DeltaPairSet`): per configuration, every delta's bodies are posed from the
closed form, the cell's geometries by the cell's batched forward kinematics
(:meth:`Cell.geometry_placements`); a pair's distance is bounded from below by the spheres that
cover the delta's bodies (:attr:`~.delta_arm.CellDelta.spheres`) against the other body's spheres
or the other geometry's own bounding box (in its frame), two capsules by their axes' exact distance
(:func:`segment_distance`) less their radii, and coal's exact distance is computed in
increasing order of that bound until the next bound exceeds the smallest distance found
(clearance) or the margin (contacts), and is not negative (two bodies whose bounds overlap may
overlap by any depth: coal's signed distance is computed for each). The result is the exact
minimum over every checked pair.
"""

from __future__ import annotations

from dataclasses import dataclass

import coal
import numpy as np

from pinarms.errors import CollisionGeometryError
from pinarms.robots.cell.delta_arm import CellDelta
from pinarms.robots.cell.pairs import CollisionPair
from pinarms.robots.delta.collision import PART_RADII
from pinarms.robots.pair_rules import AllowedPair, PairReason

__all__ = ["DeltaPairSet", "delta_pair_set", "adjacent_bodies", "meeting_rods", "segment_distance"]


def adjacent_bodies(has_tool: bool) -> frozenset[frozenset[str]]:
    """The body pairs of one delta joined at a joint (names without the arm's prefix)."""
    out = []
    for i in (1, 2, 3):
        out.append(("base", f"upper_arm_{i}"))
        for r in "ab":
            out += [(f"upper_arm_{i}", f"rod_{i}{r}"), (f"rod_{i}{r}", "platform")]
    if has_tool:
        out.append(("platform", "tool"))
    return frozenset(frozenset(p) for p in out)


def meeting_rods(delta: CellDelta) -> dict[frozenset[str], float]:
    """``{pair of body names (without prefix): distance of their lower ball centres [m]}`` of the rods of
    neighbouring legs (``rod_{i}a``, ``rod_{i+1}b``) whose lower ends, held by the platform, are closer than
    two rod radii: their capsules overlap at the platform in every configuration (module doc)."""
    g = delta.delta.geometry
    e, u = g.radial, g.tangential
    out = {}
    for i in range(3):
        j = (i + 1) % 3
        a = g.platform_radius * e[i] + 0.5 * g.rod_spacing * u[i]
        b = g.platform_radius * e[j] - 0.5 * g.rod_spacing * u[j]
        gap = float(np.linalg.norm(a - b))
        if gap < 2.0 * PART_RADII["rod"]:
            out[frozenset((f"rod_{i + 1}a", f"rod_{j + 1}b"))] = gap
    return out


def segment_distance(p1: np.ndarray, q1: np.ndarray, p2: np.ndarray, q2: np.ndarray) -> np.ndarray:
    """Distance between the segments ``p1 q1`` and ``p2 q2`` (each (..., 3), of nonzero length), exact: the
    closest parameters of the two lines, each clamped to its segment and the other recomputed (Ericson,
    *Real-Time Collision Detection*, 5.1.9)."""
    d1, d2, r = q1 - p1, q2 - p2, p1 - p2
    a, e = np.einsum("...i,...i", d1, d1), np.einsum("...i,...i", d2, d2)
    b, c, f = np.einsum("...i,...i", d1, d2), np.einsum("...i,...i", d1, r), np.einsum("...i,...i", d2, r)
    denom = a * e - b * b
    with np.errstate(divide="ignore", invalid="ignore"):
        s = np.where(denom > 1e-12 * a * e, np.clip((b * f - c * e) / denom, 0.0, 1.0), 0.0)
        t = (b * s + f) / e
        s = np.where(t < 0.0, np.clip(-c / a, 0.0, 1.0), np.where(t > 1.0, np.clip((b - c) / a, 0.0, 1.0), s))
        t = np.clip(t, 0.0, 1.0)
    return np.linalg.norm(p1 + d1 * s[..., None] - p2 - d2 * t[..., None], axis=-1)


def _reduce_min(out: np.ndarray, pair: np.ndarray, values: np.ndarray) -> None:
    """``out[:, k]`` = min of ``values[:, i]`` over the ``i`` with ``pair[i] == k`` (``pair`` sorted), in place."""
    starts = np.flatnonzero(np.r_[True, pair[1:] != pair[:-1]])
    out[:, pair[starts]] = np.minimum.reduceat(values, starts, axis=1)


def _transform(T: np.ndarray) -> coal.Transform3s:
    return coal.Transform3s(np.ascontiguousarray(T[:3, :3]), np.ascontiguousarray(T[:3, 3]))


@dataclass(frozen=True, eq=False)
class _Side:
    """Where a pair's second body is: a cell geometry (``delta`` −1, ``index`` its geometry index) or a delta's part."""

    delta: int
    index: int


class DeltaPairSet:
    """The checked and allowed pairs of a cell's deltas and their exact distances (module doc).

    Attributes:
        pairs: the checked pairs (:class:`CollisionPair`), ``allowed``: the others with their reason.
    """

    def __init__(self, cell, deltas: tuple[CellDelta, ...]) -> None:
        self.cell, self.deltas = cell, deltas
        gm, model = cell.collision_model, cell.model
        owner_of = {link: arm.name for arm in cell.spec.arms for link in arm.links}
        geoms = []
        for g, obj in enumerate(gm.geometryObjects):
            link = model.frames[obj.parentFrame].name
            static = obj.parentJoint == 0
            geoms.append((g, link, owner_of.get(link, link), link in owner_of, static))
        self._geom_shapes = [obj.geometry for obj in gm.geometryObjects]
        boxes = []
        for shape in self._geom_shapes:
            shape.computeLocalAABB()
            boxes.append((np.asarray(shape.aabb_local.min_), np.asarray(shape.aabb_local.max_)))
        self._geom_lo = np.array([b[0] for b in boxes]).reshape(-1, 3)
        self._geom_hi = np.array([b[1] for b in boxes]).reshape(-1, 3)
        names = [d.body_names for d in deltas]
        self._geom_shapes = self._geom_shapes
        pairs, allowed, sides_a, sides_b = [], [], [], []
        for k, d in enumerate(deltas):
            short = [n[len(d.name) + 1:] for n in names[k]]
            adjacent = adjacent_bodies("tool" in short)
            meeting = meeting_rods(d)
            for j, body in enumerate(names[k]):
                for g, link, owner, is_arm, static in geoms:
                    if short[j] == "base" and static:
                        allowed.append(AllowedPair(body, gm.geometryObjects[g].name, body, link, PairReason.RIGID,
                                                   index_b=g))
                        continue
                    kind = "arm-arm" if is_arm else "arm-fixture"
                    if kind not in cell.kinds:
                        continue
                    pairs.append(CollisionPair(-1, g, body, gm.geometryObjects[g].name, body, link, d.name, owner, kind))
                    sides_a.append((k, j)), sides_b.append(_Side(-1, g))
                for k2 in range(k, len(deltas)):
                    for j2, other in enumerate(names[k2]):
                        if k2 == k and j2 <= j:
                            continue
                        if k2 == k and frozenset((short[j], short[j2])) in adjacent:
                            allowed.append(AllowedPair(body, other, body, other, PairReason.ADJACENT))
                            continue
                        if k2 == k and frozenset((short[j], short[j2])) in meeting:
                            gap = meeting[frozenset((short[j], short[j2]))]
                            allowed.append(AllowedPair(body, other, body, other, PairReason.ADJACENT, note=(
                                f"both held by the platform: lower ball centres {gap * 1e3:.1f} mm apart, less "
                                f"than two rod radii")))
                            continue
                        if k2 != k and short[j] == "base" and names[k2][j2].endswith("_base"):
                            allowed.append(AllowedPair(body, other, body, other, PairReason.RIGID))
                            continue
                        kind = "self" if k2 == k else "arm-arm"
                        if kind not in cell.kinds:
                            continue
                        pairs.append(CollisionPair(-1, -1, body, other, body, other, d.name, deltas[k2].name, kind))
                        sides_a.append((k, j)), sides_b.append(_Side(k2, j2))
        self.pairs: tuple[CollisionPair, ...] = tuple(pairs)
        self.allowed: tuple[AllowedPair, ...] = tuple(allowed)
        self._a = np.array(sides_a, dtype=int).reshape(-1, 2)
        self._b_delta = np.array([s.delta for s in sides_b], dtype=int)
        self._b_index = np.array([s.index for s in sides_b], dtype=int)
        self._sphere_pairs()

    def _sphere_pairs(self) -> None:
        """Index arrays of every (sphere, sphere) and (sphere, geometry) a pair's lower bound looks at, by pair."""
        offsets = np.cumsum([0] + [len(d.spheres[1]) for d in self.deltas])
        spheres_of = [[offsets[k] + np.flatnonzero(d.spheres[2] == j) for j in range(len(d.body_names))]
                      for k, d in enumerate(self.deltas)]
        first = np.cumsum([0] + [len(d.body_names) for d in self.deltas])
        capsule = np.concatenate([[isinstance(s, coal.Capsule) for s in d.shapes] for d in self.deltas])
        dd, dg, cc = [], [], []   # (pair, sphere a, sphere b), (pair, sphere a, geometry), (pair, body a, body b)
        for m, (k, j) in enumerate(self._a):
            sa = spheres_of[k][j]
            if self._b_delta[m] < 0:
                dg += [(m, a, self._b_index[m]) for a in sa]
                continue
            ba, bb = first[k] + j, first[self._b_delta[m]] + self._b_index[m]
            if capsule[ba] and capsule[bb]:   # two capsules: their axes' exact distance less the radii
                cc.append((m, ba, bb))
            else:
                sb = spheres_of[self._b_delta[m]][self._b_index[m]]
                dd += [(m, a, b) for a in sa for b in sb]
        self._dd = np.array(dd, dtype=int).reshape(-1, 3)
        self._dg = np.array(dg, dtype=int).reshape(-1, 3)
        self._cc = np.array(cc, dtype=int).reshape(-1, 3)
        self._capsule = capsule

    # ---------------------------------------------------------------- batches
    def _state(self, arr: np.ndarray, threshold: float = np.inf):
        """World poses of every delta's bodies (per delta (N, B, 4, 4)), the cell geometries' placements and a
        lower bound (N, P) of every pair's distance, for configurations ``arr (N, nq)``: each body's bounding
        sphere against the other's (or the other geometry's box, in its frame); for the pairs where that is
        below ``threshold`` somewhere, the spheres covering the bodies (:attr:`~.delta_arm.CellDelta.spheres`)."""
        N = arr.shape[0]
        poses = [d.poses(d.theta(arr)) for d in self.deltas]
        body_c = np.concatenate([T[..., :3, 3] for T in poses], axis=1)             # (N, all bodies, 3)
        body_r = np.concatenate([d.radii for d in self.deltas])
        first = np.cumsum([0] + [len(d.body_names) for d in self.deltas])
        ia = first[self._a[:, 0]] + self._a[:, 1]
        geo = self._b_delta < 0
        R = p = None
        lb = np.empty((N, len(self.pairs)))
        if geo.any():
            R, p = self.cell.geometry_placements(arr)
            g = self._b_index[geo]
            lb[:, geo] = self._box_gap(R[:, g], p[:, g], body_c[:, ia[geo]], g) - body_r[ia[geo]]
        if (~geo).any():
            ib = first[np.maximum(self._b_delta[~geo], 0)] + self._b_index[~geo]
            lb[:, ~geo] = np.linalg.norm(body_c[:, ia[~geo]] - body_c[:, ib], axis=2) - body_r[ia[~geo]] - body_r[ib]
        fine = np.flatnonzero((lb < threshold).any(axis=0))
        if fine.size:
            self._fine_bounds(lb, fine, poses, R, p)
        return poses, R, p, lb

    def _box_gap(self, R: np.ndarray, p: np.ndarray, centres: np.ndarray, g: np.ndarray) -> np.ndarray:
        """Distance from ``centres (N, K, 3)`` to geometry ``g (K,)``'s own bounding box, placed at ``R, p (N, K, ...)``."""
        local = np.einsum("nkji,nkj->nki", R, centres - p)
        gap = np.maximum(np.maximum(self._geom_lo[g] - local, local - self._geom_hi[g]), 0.0)
        return np.linalg.norm(gap, axis=2)

    def _fine_bounds(self, lb: np.ndarray, pairs: np.ndarray, poses, R, p) -> None:
        """Raise ``lb`` of ``pairs`` to the covering spheres' bound (in place)."""
        centres, radii = [], []
        for d, T in zip(self.deltas, poses):
            c, r, body = d.spheres
            Tb = T[:, body]
            centres.append(np.einsum("nsij,sj->nsi", Tb[..., :3, :3], c) + Tb[..., :3, 3])
            radii.append(r)
        C, r = np.concatenate(centres, axis=1), np.concatenate(radii)
        wanted = np.zeros(len(self.pairs), dtype=bool)
        wanted[pairs] = True
        fine = np.full_like(lb, -np.inf)
        dg = self._dg[wanted[self._dg[:, 0]]] if len(self._dg) else self._dg
        if len(dg):
            m, a, g = dg.T
            _reduce_min(fine, m, self._box_gap(R[:, g], p[:, g], C[:, a], g) - r[a])
        dd = self._dd[wanted[self._dd[:, 0]]] if len(self._dd) else self._dd
        if len(dd):
            m, a, b = dd.T
            _reduce_min(fine, m, np.linalg.norm(C[:, a] - C[:, b], axis=2) - r[a] - r[b])
        cc = self._cc[wanted[self._cc[:, 0]]] if len(self._cc) else self._cc
        if len(cc):
            T = np.concatenate(poses, axis=1)
            shapes = [s for d in self.deltas for s in d.shapes]
            half = np.array([s.halfLength if isinstance(s, coal.Capsule) else 0.0 for s in shapes])
            rad = np.array([s.radius if isinstance(s, coal.Capsule) else 0.0 for s in shapes])
            m, a, b = cc.T
            ends = lambda k: (T[:, k][..., :3, 3] - half[k][None, :, None] * T[:, k][..., :3, 2],  # noqa: E731
                              T[:, k][..., :3, 3] + half[k][None, :, None] * T[:, k][..., :3, 2])
            fine[:, m] = segment_distance(*ends(a), *ends(b)) - rad[a] - rad[b]
        np.maximum(lb, fine, out=lb)

    def _distance(self, m: int, n: int, poses, R, p) -> tuple[float, np.ndarray, np.ndarray]:
        """coal's exact distance of pair ``m`` at configuration ``n`` and its nearest points (world)."""
        k, j = self._a[m]
        shape_a, pose_a = self.deltas[k].shapes[j], poses[k][n, j]
        if self._b_delta[m] < 0:
            g = self._b_index[m]
            pose_b = np.eye(4)
            pose_b[:3, :3], pose_b[:3, 3] = R[n, g], p[n, g]
            shape_b = self._geom_shapes[g]
        else:
            k2, j2 = self._b_delta[m], self._b_index[m]
            shape_b, pose_b = self.deltas[k2].shapes[j2], poses[k2][n, j2]
        res = coal.DistanceResult()
        d = coal.distance(shape_a, _transform(pose_a), shape_b, _transform(pose_b), coal.DistanceRequest(), res)
        if not np.isfinite(d):
            raise CollisionGeometryError(f"coal returned distance {d} for {self.pairs[m]}")
        return float(d), np.array(res.getNearestPoint1()), np.array(res.getNearestPoint2())

    def clearance(self, arr: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``(distance (N,), pair (N,), point_a (N, 3), point_b (N, 3))``: the exact smallest distance over
        :attr:`pairs` at each cell configuration of ``arr (N, nq)`` (pair −1 and ``inf`` without pairs)."""
        dist, _, pair, pa, pb = self.bounded(arr, np.inf)
        return dist, pair, pa, pb

    def bounded(self, arr: np.ndarray, cutoff: float):
        """``(value (N,), exact (N,), pair (N,), point_a, point_b)`` at each configuration of ``arr (N, nq)``:
        the exact smallest distance over :attr:`pairs` where it is below ``cutoff`` [m] (``exact`` true),
        else a proven lower bound of it that is at least ``cutoff`` (bounding spheres; pair −1)."""
        N = arr.shape[0]
        dist, exact, pair = np.full(N, np.inf), np.ones(N, dtype=bool), np.full(N, -1)
        pa, pb = np.full((N, 3), np.nan), np.full((N, 3), np.nan)
        if not self.pairs or not N:
            return dist, exact, pair, pa, pb
        poses, R, p, lb = self._state(arr, cutoff)
        for n in range(N):
            best, stop = np.inf, np.inf
            for m in np.argsort(lb[n], kind="stable"):
                if lb[n, m] >= min(best, cutoff) and lb[n, m] >= 0.0:   # below 0 a pair may overlap by any depth
                    stop = lb[n, m]
                    break
                d, xa, xb = self._distance(int(m), n, poses, R, p)
                if d < best:
                    best, pair[n], pa[n], pb[n] = d, m, xa, xb
            if best < cutoff:
                dist[n] = best
            else:  # every pair at least `cutoff` away: the smaller of the exact ones and the next bound
                dist[n], exact[n], pair[n] = min(best, stop), False, -1
                pa[n] = pb[n] = np.nan
        return dist, exact, pair, pa, pb

    def touching(self, arr: np.ndarray, margin: float) -> list[tuple[int, ...]]:
        """Per configuration of ``arr (N, nq)``, the indices of :attr:`pairs` at distance ≤ ``margin`` [m]."""
        if not self.pairs or not arr.shape[0]:
            return [()] * arr.shape[0]
        poses, R, p, lb = self._state(arr, margin)
        return [tuple(int(m) for m in np.flatnonzero(lb[n] <= margin)
                      if self._distance(int(m), n, poses, R, p)[0] <= margin) for n in range(arr.shape[0])]

    def any_touching(self, arr: np.ndarray, margin: float) -> np.ndarray:
        """``(N,)`` bool: some pair of :attr:`pairs` at distance ≤ ``margin`` [m] (pairs by increasing bound, the
        first contact ends a configuration)."""
        out = np.zeros(arr.shape[0], dtype=bool)
        if not self.pairs or not arr.shape[0]:
            return out
        poses, R, p, lb = self._state(arr, margin)
        for n in range(arr.shape[0]):
            near = np.flatnonzero(lb[n] <= margin)
            for m in near[np.argsort(lb[n, near], kind="stable")]:
                if self._distance(int(m), n, poses, R, p)[0] <= margin:
                    out[n] = True
                    break
        return out

    def distances(self, arr: np.ndarray) -> np.ndarray:
        """``(N, P)`` coal's exact distance [m] of every pair at every configuration of ``arr (N, nq)``."""
        poses, R, p, lb = self._state(arr)
        return np.array([[self._distance(m, n, poses, R, p)[0] for m in range(len(self.pairs))]
                         for n in range(arr.shape[0])]).reshape(arr.shape[0], len(self.pairs))


def delta_pair_set(cell) -> DeltaPairSet:
    """The cell's :class:`DeltaPairSet`, built once (:meth:`Cell.memo`)."""
    return cell.memo("delta pairs", lambda: DeltaPairSet(cell, cell.deltas))
