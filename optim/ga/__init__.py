"""The genetic algorithm that times trajectories: the engine and its operators.

- :mod:`.request` (:class:`GARequest`: objective, bounds and budgets, checked when built;
  :class:`GAStop`), :mod:`.engine` (:func:`run_ga`: history, progress, result), :mod:`.settings`
  (:class:`GASettings`), :mod:`.problem` (:class:`TimingProblem`: segment times under
  limits, the fitness the GA minimises);
- operators: :mod:`.selection`, :mod:`.crossover`, :mod:`.mutation`, :mod:`.adaptive`
  (adaptive rates), :mod:`.constraints` (penalties and feasibility rules).

The public names are re-exported by :mod:`pinarms.optim` (old module paths: docs/README.md).
"""

__all__: list[str] = []
