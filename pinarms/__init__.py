"""pinarms: handling arms of food and agricultural production lines, on Pinocchio.

Where each family lives (imports go one way, top to bottom of this list read upwards):

- the floor, importable by every package: :mod:`pinarms.errors` (the exception hierarchy),
  :mod:`pinarms.execution` (serial loop or Dask) with :mod:`pinarms.chunks` (chunk seeds and
  sizes) and :mod:`pinarms.schedulers` (the ``scheduler`` argument), :mod:`pinarms.files` (atomic files),
  :mod:`pinarms.units`, :mod:`pinarms.compiled` (numba kernels and their caches) with
  :mod:`pinarms.compile_notice` (the command line's line while numba compiles);
- :mod:`pinarms.robots`: registry and ``Robot``, ``ik/``, ``reach/`` (workspace, reachability
  maps and their files, base placement, table band, layout check), ``cell/`` (cell, pairs with
  proven bounds, collision state, the one continuous motion check and its proof ladder
  ``cell/ladder.py``, the sphere cover of every geometry, scene files), payloads, dynamics;
- :mod:`pinarms.planning`: trajectories, Cartesian paths, limits as objects;
- :mod:`pinarms.optim`: ``ga/``, ``timing/`` (segment timing), ``topp/`` (time-optimal along a
  path), ``cycle/`` (the pick-and-place cycle), ``layout/`` (layout search), ``motion/``
  (planning around obstacles), ``line/`` (belts and items);
- :mod:`pinarms.viz`: sessions, MeshCat viewer, standalone HTML, plots;
- on top: ``cli/``, ``studies/`` (one module per paper study; :mod:`pinarms.demo` lists and
  runs them), ``export/`` (URDF, SRDF, MJCF, trajectories), :mod:`pinarms.warmup` (every kernel
  compiled ahead, ``pinarms warm``).
"""

from pinarms.lazy import lazy_exports

#: The front door: the names a user starts with, each loaded on first use (PEP 562), so that
#: ``import pinarms`` costs nothing and ``import pinarms.optim.line`` loads no planner.
_EXPORTS = {
    "load": "pinarms.robots.registry",
    "Robot": "pinarms.robots.robot",
    "load_cell": "pinarms.robots.cell.library",
    "Cell": "pinarms.robots.cell.cell",
    "plan_motion": "pinarms.optim.motion.plan",
    "MotionPlan": "pinarms.optim.motion.result",
    "plan_cycle": "pinarms.optim.cycle.plan",
    "CycleRequest": "pinarms.optim.cycle.request",
    "CycleResult": "pinarms.optim.cycle.spec",
    "run_line": "pinarms.optim.line.api",
    "LineSpec": "pinarms.optim.line.api",
    "LineResult": "pinarms.optim.line.api",
    "search_layout": "pinarms.optim.layout.search",
    "PinarmsError": "pinarms.errors",
}

__all__ = list(_EXPORTS)

__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
