"""Yoshikawa's manipulability of a frame Jacobian: the volume of its velocity ellipsoid.

``w = sqrt(det(J Jᵀ))`` of the chosen rows of a frame Jacobian ``(6, nq)`` (linear rows
first, as :meth:`pinarms.robots.Robot.jacobian` gives it): all six, the three linear rows
(position) or the three angular rows (orientation). When the Jacobian has fewer columns
than rows (an arm with fewer joints than task dimensions), ``w = sqrt(det(Jᵀ J))``: the
volume within the arm's own motion space.
"""

from __future__ import annotations

import math

import numpy as np

from pinarms.errors import InvalidInput

__all__ = ["PARTS", "manipulability_of_jacobian"]

#: Rows of the frame Jacobian each ``part`` takes.
PARTS = {"full": slice(0, 6), "position": slice(0, 3), "orientation": slice(3, 6)}


#: LAPACK's Cholesky (scipy), imported at the first one-configuration call: scipy.linalg takes about a second to
#: import, which every command line call paid (robots.Robot imports this module).
_POTRF: list = []


def _potrf():
    if not _POTRF:
        from scipy.linalg.lapack import dpotrf

        _POTRF.append(dpotrf)
    return _POTRF[0]


def manipulability_of_jacobian(J: np.ndarray, part: str = "full") -> float | np.ndarray:
    """``w`` of one Jacobian ``(6, nq)`` (a float) or of a batch ``(N, 6, nq)`` (an array ``(N,)``).

    One Jacobian: ``sqrt(det G)`` is the product of the Cholesky diagonal of ``G`` (LAPACK's
    ``dpotrf``), or ``sqrt(max(det G, 0))`` when ``G`` is singular in floating point, as a batch.

    Raises:
        InvalidInput: ``part`` is not one of :data:`PARTS`.
    """
    rows = PARTS.get(part) if isinstance(part, str) else None
    if rows is None:
        raise InvalidInput(f"part must be one of {sorted(PARTS)}, got {part!r}")
    J = J[..., rows, :]
    m, n = J.shape[-2:]
    if J.ndim == 2:  # one configuration: sqrt(det G) is the product of G's Cholesky diagonal
        G = J.dot(J.T) if m <= n else J.T.dot(J)
        L, info = _potrf()(G, overwrite_a=1)
        if info == 0:
            return math.prod(L.diagonal().tolist())
        G = J.dot(J.T) if m <= n else J.T.dot(J)  # singular in floating point: as the batch does
        return float(np.sqrt(max(np.linalg.det(G), 0.0)))
    G = J @ np.swapaxes(J, -1, -2) if m <= n else np.swapaxes(J, -1, -2) @ J
    return np.sqrt(np.clip(np.linalg.det(G), 0.0, None))
