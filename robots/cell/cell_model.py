"""What the checks of a cell read from it: :class:`CellModel`, the structural type of a :class:`~pinarms.robots.cell.Cell`.

The modules that check, classify or move a cell's arms (:mod:`.collision`, :mod:`.motion`,
:mod:`.pairs`, :mod:`.timeline`, ...) are called by :class:`~pinarms.robots.cell.Cell`'s methods and
take the cell as their first argument. They annotate it with this protocol, which imports none of
them, so no module needs :mod:`.cell` to be understood and :mod:`.cell` needs none of them back:
no circle, not even through imports for type checkers.
"""

from __future__ import annotations

from typing import Any, Callable, Mapping, Protocol, TypeVar

import numpy as np
from numpy.typing import ArrayLike

__all__ = ["CellModel"]

T = TypeVar("T")


class CellModel(Protocol):
    """The attributes and methods of a cell that its checks use (see :class:`~pinarms.robots.cell.Cell` for each)."""

    name: str
    source: str
    urdf_text: str
    args: dict[str, str]
    spec: Any
    robot: Any
    model: Any
    collision_model: Any
    arms: tuple
    fixtures: tuple
    pairs: tuple
    allowed: tuple
    kinds: tuple[str, ...]

    @property
    def nq(self) -> int: ...

    @property
    def hold(self) -> np.ndarray: ...

    @property
    def candidates(self) -> tuple: ...

    @property
    def reach_bounds(self) -> np.ndarray: ...

    @property
    def pair_views(self) -> Any: ...

    @property
    def batched_placements(self) -> Any: ...

    def pair_count(self, clearance: float, *, strict: bool = False) -> int: ...

    def pairs_for(self, clearance: float) -> tuple: ...

    def pin_vector_or_none(self, q: ArrayLike) -> np.ndarray | None: ...

    def memo(self, key: str, build: Callable[[], T]) -> T: ...

    def arm(self, name: str) -> Any: ...

    def fixture(self, name: str) -> Any: ...

    def random_q(self, n: int, seed: int | np.random.Generator | None = 0) -> np.ndarray: ...

    def q_from_arms(self, arm_q: Mapping[str, ArrayLike], base: ArrayLike | None = None) -> np.ndarray: ...

    def in_collision(self, q: ArrayLike, *, margin: float = 0.0, threads: int = 1) -> bool | np.ndarray: ...
