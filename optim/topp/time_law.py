"""The time law s(t) of a path timing: a piecewise polynomial in t, and q(s(t)) composed from it.

A law is ``(tb, C)``: breaks ``tb`` (P+1,) [s] and ascending coefficients ``C`` (P, k+1) of
s(t) in the time since each piece's start (k = 2 for the time-optimal profile, 3 once
smoothed under a jerk limit, the shape's degree for :func:`pinarms.optim.time_scaled`). This module
builds laws (:func:`bang_bang`, :func:`smoothed`, :func:`scaled_law`), evaluates them
(:func:`law_eval`), and turns them into a :class:`pinarms.planning.Trajectory` exactly
(:func:`assemble`: pieces cut at the path's breaks, ``q(s(t))`` a polynomial in t on each).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from pinarms.planning import Trajectory
from pinarms.planning.poly_pieces import taylor_shift

if TYPE_CHECKING:
    from pinarms.planning.joint_path import JointPath

__all__ = ["law_eval", "polyval", "bang_bang", "smoothed", "split_at_breaks", "compose_law", "assemble",
           "scaled_law", "acceleration_jumps"]


def law_eval(tb: np.ndarray, C: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """s, ṡ, s̈ of the piecewise polynomial law (breaks tb, ascending coefficients C) at instants t."""
    tt = np.clip(t, tb[0], tb[-1])
    k = np.clip(np.searchsorted(tb, tt, side="right") - 1, 0, C.shape[0] - 1)
    tau = tt - tb[k]
    c = C[k]
    deg = C.shape[1] - 1
    out = []
    for r in range(3):
        acc = np.zeros_like(tau)
        for d in range(deg, r - 1, -1):
            fall = np.prod(np.arange(d, d - r, -1)) if r else 1.0
            acc = acc * tau + fall * c[:, d]
        out.append(acc)
    return out[0], out[1], out[2]


def polyval(C: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Row-wise values of ascending coefficients C (P, k+1) at x (P,)."""
    out = np.zeros(C.shape[0])
    for d in range(C.shape[1] - 1, -1, -1):
        out = out * x + C[:, d]
    return out


def bang_bang(grid: np.ndarray, x: np.ndarray, u: np.ndarray, f2: float) -> tuple[np.ndarray, np.ndarray]:
    """The reachability profile as a law: one quadratic per grid interval, dilated by f = √f2."""
    sd = np.sqrt(np.maximum(x, 0.0) / f2)
    uu = u / f2
    dt = 2.0 * np.diff(grid) / (sd[:-1] + sd[1:])
    tb = np.concatenate([[0.0], np.cumsum(dt)])
    return tb, np.stack([grid[:-1], sd[:-1], 0.5 * uu], axis=1)


def _polyint(C: np.ndarray) -> np.ndarray:
    """Antiderivatives (zero at the piece start) of ascending coefficients (P, k+1) -> (P, k+2)."""
    out = np.zeros((C.shape[0], C.shape[1] + 1))
    out[:, 1:] = C / np.arange(1, C.shape[1] + 1)
    return out


def smoothed(tb: np.ndarray, C: np.ndarray, tau: float) -> tuple[np.ndarray, np.ndarray]:
    """The law averaged over a trailing window τ: ``s_τ(t) = (1/τ) ∫_{t−τ}^{t} s`` on [t0, t_end + τ].

    (:mod:`pinarms.optim.topp.path_timing`, jerk.) The law is extended at rest before its start and after its end.
    """
    a, b = C[0, 0], law_eval(tb, C, tb[-1:])[0][0]
    # the law at rest before its start and after its end, one piece each (length τ)
    eb = np.concatenate([[tb[0] - tau], tb, [tb[-1] + tau]])
    width = C.shape[1]
    EC = np.zeros((C.shape[0] + 2, width))
    EC[0, 0], EC[1:-1], EC[-1, 0] = a, C, b
    S = _polyint(EC)  # (P+2, k+2)
    lengths = np.diff(eb)
    ends = polyval(S, lengths)
    S[:, 0] = np.concatenate([[0.0], np.cumsum(ends)[:-1]])  # continuous antiderivative
    new = np.unique(np.concatenate([tb, tb + tau]))
    new = new[(new >= tb[0]) & (new <= tb[-1] + tau)]
    out = np.zeros((new.size - 1, S.shape[1]))
    for sign, shift in ((1.0, 0.0), (-1.0, tau)):
        start = new[:-1] - shift
        k = np.clip(np.searchsorted(eb, start + 1e-15 * max(1.0, abs(tb[-1])), side="right") - 1, 0, S.shape[0] - 1)
        local = taylor_shift(S[k][:, :, None], start - eb[k])[:, :, 0]
        out += sign * local
    return new, out / tau


def split_at_breaks(tb: np.ndarray, C: np.ndarray, s_breaks: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Cut law pieces where s(t) crosses a path break, so that each piece lies in one path piece."""
    s0 = C[:, 0]
    s1 = polyval(C, np.diff(tb))
    cuts_t, cuts_k = [], []
    tol = 1e-12 * max(1.0, float(np.abs(s_breaks).max()) if s_breaks.size else 1.0)
    for sb in s_breaks:
        inside = np.flatnonzero((s0 < sb - tol) & (s1 > sb + tol))
        for i in inside:  # a monotone law crosses once: bisection
            lo, hi = 0.0, tb[i + 1] - tb[i]
            for _ in range(80):
                mid = 0.5 * (lo + hi)
                if np.polyval(C[i, ::-1], mid) < sb:
                    lo = mid
                else:
                    hi = mid
            cuts_t.append(tb[i] + 0.5 * (lo + hi))
            cuts_k.append(i)
    if not cuts_t:
        return tb, C
    new = np.sort(np.concatenate([tb, cuts_t]))
    k = np.clip(np.searchsorted(tb, new[:-1], side="right") - 1, 0, C.shape[0] - 1)
    out = taylor_shift(C[k][:, :, None], new[:-1] - tb[k])[:, :, 0]
    return new, out


def compose_law(path: JointPath, tb: np.ndarray, C: np.ndarray) -> np.ndarray:
    """Coefficients (P, D·k+1, n) in the local time of q(s(t)) on each law piece (path_timing, step 5)."""
    breaks, Q = np.asarray(path.breaks), path.coefficients  # (K, D+1, n)
    h = np.diff(tb)
    mid = polyval(C, 0.5 * h)
    k = np.clip(np.searchsorted(breaks, mid, side="right") - 1, 0, Q.shape[0] - 1)
    D = Q.shape[1] - 1
    deg = C.shape[1] - 1
    width = D * deg + 1
    sigma = C.copy()
    sigma[:, 0] -= breaks[k]
    P = C.shape[0]
    power = np.zeros((P, width))
    power[:, 0] = 1.0
    out = Q[k, 0][:, None, :] * power[:, :, None]
    for d in range(1, D + 1):
        nxt = np.zeros((P, width))
        for j in range(deg + 1):
            nxt[:, j:] += sigma[:, j : j + 1] * power[:, : width - j]
        power = nxt
        out = out + Q[k, d][:, None, :] * power[:, :, None]
    return out


def assemble(path: JointPath, laws: list[tuple[np.ndarray, np.ndarray]]) -> tuple[np.ndarray, np.ndarray, Trajectory]:
    """Sections' laws end to end (each cut at the path breaks) and the composed trajectory."""
    tbs, Cs, offset = [], [], 0.0
    width = max(C.shape[1] for _, C in laws)
    for tb, C in laws:
        tb, C = split_at_breaks(tb, C, np.asarray(path.breaks)[1:-1])
        pad = np.zeros((C.shape[0], width))
        pad[:, : C.shape[1]] = C
        tbs.append(tb - tb[0] + offset)
        Cs.append(pad)
        offset = float(tbs[-1][-1])
    tb = np.concatenate([tbs[0]] + [t[1:] for t in tbs[1:]])
    C = np.concatenate(Cs)
    traj = Trajectory(tb, compose_law(path, tb, C))
    return tb, C, traj


def scaled_law(tb: np.ndarray, C: np.ndarray, f: float) -> tuple[np.ndarray, np.ndarray]:
    """The law slowed uniformly by f: t -> f t."""
    return tb[0] + (tb - tb[0]) * f, C / f ** np.arange(C.shape[1])


def acceleration_jumps(traj: Trajectory) -> np.ndarray:
    """Largest jump (n,) of each joint's acceleration at the trajectory's breaks (from and to rest included)."""
    c = traj.coefficients
    h = traj.segment_durations
    k = np.arange(2, c.shape[1])
    start = 2.0 * c[:, 2] if c.shape[1] > 2 else np.zeros((c.shape[0], c.shape[2]))
    end = np.einsum("mkn,mk->mn", c[:, 2:], (k * (k - 1))[None] * h[:, None] ** (k - 2)[None]) if c.shape[1] > 2 \
        else np.zeros_like(start)
    jumps = np.concatenate([start[:1], start[1:] - end[:-1], -end[-1:]])
    return np.abs(jumps).max(axis=0)
