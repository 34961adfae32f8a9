"""GA settings: one frozen dataclass, with the papers' configurations as named presets.

Probabilities are per pair (crossover) and per gene (mutation). The two presets:

- :meth:`GASettings.seed000` - the SCARA paper (seed 000): population 50, crossover
  probability 0.7, mutation probability 0.1, linear-rank fitness with stochastic
  universal sampling, penalty handling of the velocity constraint.
- :meth:`GASettings.seed002` - the flower-packing gantry paper (seed 002), "improved GA":
  elitism + tournament selection, non-uniform mutation with shape c = 2, adaptive
  crossover/mutation probabilities (Srinivas-Patnaik form with pc1, pc2, pm1, pm2) and an
  adaptive penalty with fitness = 1 / (f + penalty).
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass, replace

from pinarms.optim.caps import MAX_GENERATIONS, MAX_POPULATION
from pinarms.optim.errors import InvalidSettings

__all__ = ["GASettings", "SELECTIONS", "CROSSOVERS", "MUTATIONS", "CONSTRAINT_HANDLINGS"]

SELECTIONS = ("tournament", "rank-sus")
CROSSOVERS = ("sbx", "arithmetic", "blend")
MUTATIONS = ("non-uniform", "polynomial")
CONSTRAINT_HANDLINGS = ("adaptive-penalty", "feasibility-rules")


@dataclass(frozen=True)
class GASettings:
    """Configuration of :func:`pinarms.optim.run_ga` (real coding, minimisation).

    Attributes:
        population: Number of individuals (>= 4, even numbers pair up cleanly).
        selection: ``"tournament"`` or ``"rank-sus"`` (linear ranking + stochastic
            universal sampling).
        tournament_size: Contestants per tournament (>= 2).
        rank_pressure: Selective pressure of linear ranking, in [1, 2] (2: best gets
            twice the average expected copies, worst none).
        crossover: ``"sbx"`` (simulated binary, bounded), ``"arithmetic"`` (random convex
            combination per pair) or ``"blend"`` (BLX-alpha).
        crossover_probability: Probability that a pair is crossed (fixed mode).
        sbx_eta: Distribution index of SBX (larger: children closer to parents).
        blend_alpha: Extension factor of BLX-alpha.
        mutation: ``"non-uniform"`` (Michalewicz; seed 002's formula) or ``"polynomial"``.
        mutation_probability: Probability that a gene is mutated (fixed mode).
        nonuniform_shape: Shape c of the non-uniform mutation (seed 002: c = 2).
        polynomial_eta: Distribution index of the polynomial mutation.
        elitism: Number of best individuals copied unchanged into the next generation.
        adaptive: If True, pc and pm follow the Srinivas-Patnaik rules from f_max,
            f_avg and the individual's fitness, with ``pc1 >= pc2`` and ``pm1 >= pm2``.
        pc1, pc2, pm1, pm2: Parameters of the adaptive probabilities.
        constraint_handling: ``"adaptive-penalty"`` (fitness 1 / (f + lambda * v), lambda
            adapted each generation) or ``"feasibility-rules"`` (Deb: feasible beats
            infeasible; two infeasible compare by violation).
        penalty_initial: Initial penalty factor lambda (times the normalised violation).
        penalty_increase: Factor on lambda when the best individual was infeasible for
            ``penalty_window`` generations in a row.
        penalty_decrease: Factor dividing lambda when it was feasible that long.
        penalty_window: Generations of the lambda update rule (Hadj-Alouane and Bean).
        max_generations: Default generation budget (G of the non-uniform mutation).
        stall_generations: Stop when the best has not improved by more than
            ``stall_tolerance`` (relative) for that many generations; None: never.
        stall_tolerance: Relative improvement counted as progress.
    """

    population: int = 50
    selection: str = "tournament"
    tournament_size: int = 2
    rank_pressure: float = 2.0
    crossover: str = "sbx"
    crossover_probability: float = 0.9
    sbx_eta: float = 15.0
    blend_alpha: float = 0.5
    mutation: str = "polynomial"
    mutation_probability: float = 0.25
    nonuniform_shape: float = 2.0
    polynomial_eta: float = 20.0
    elitism: int = 1
    adaptive: bool = False
    pc1: float = 0.9
    pc2: float = 0.6
    pm1: float = 0.1
    pm2: float = 0.001
    constraint_handling: str = "feasibility-rules"
    penalty_initial: float = 10.0
    penalty_increase: float = 2.0
    penalty_decrease: float = 1.5
    penalty_window: int = 5
    max_generations: int = 200
    stall_generations: int | None = 60
    stall_tolerance: float = 1e-9

    def __post_init__(self) -> None:
        try:
            self._validate()
        except TypeError:  # e.g. None or a string where a number belongs
            fields = {k: v for k, v in self.__dict__.items()
                      if k not in ("selection", "crossover", "mutation", "constraint_handling",
                                   "adaptive")
                      and not (v is None and k == "stall_generations")
                      and (isinstance(v, bool) or not isinstance(v, (int, float)))}
            raise InvalidSettings(f"GASettings: {fields} must be numbers") from None

    def _validate(self) -> None:
        def bad(name: str, value: object, what: str) -> InvalidSettings:
            return InvalidSettings(f"GASettings.{name}={value!r}: {what}")

        pop = self.population
        if isinstance(pop, bool) or not isinstance(pop, numbers.Real):
            raise TypeError("population")  # named with the other non-numbers by __post_init__
        if not math.isfinite(pop) or int(pop) != pop or not 4 <= pop <= MAX_POPULATION:
            raise bad("population", self.population, f"use an integer from 4 to {MAX_POPULATION:,}")
        if self.selection not in SELECTIONS:
            raise bad("selection", self.selection, f"use one of {SELECTIONS}")
        if self.crossover not in CROSSOVERS:
            raise bad("crossover", self.crossover, f"use one of {CROSSOVERS}")
        if self.mutation not in MUTATIONS:
            raise bad("mutation", self.mutation, f"use one of {MUTATIONS}")
        if self.constraint_handling not in CONSTRAINT_HANDLINGS:
            raise bad("constraint_handling", self.constraint_handling,
                      f"use one of {CONSTRAINT_HANDLINGS}")
        if self.tournament_size < 2 or self.tournament_size > self.population:
            raise bad("tournament_size", self.tournament_size, "use 2 .. population")
        if not 1.0 <= self.rank_pressure <= 2.0:
            raise bad("rank_pressure", self.rank_pressure, "use a value in [1, 2]")
        for name in ("crossover_probability", "mutation_probability", "pc1", "pc2", "pm1", "pm2"):
            value = getattr(self, name)
            if not 0.0 <= value <= 1.0:
                raise bad(name, value, "a probability must lie in [0, 1]")
        if self.pc1 < self.pc2 or self.pm1 < self.pm2:
            raise bad("pc1/pm1", (self.pc1, self.pm1), "need pc1 >= pc2 and pm1 >= pm2")
        for name in ("sbx_eta", "polynomial_eta", "nonuniform_shape", "penalty_initial"):
            value = getattr(self, name)
            if not value > 0.0:
                raise bad(name, value, "use a positive value")
        if self.blend_alpha < 0.0:
            raise bad("blend_alpha", self.blend_alpha, "use a value >= 0")
        if not 0 <= self.elitism < self.population:
            raise bad("elitism", self.elitism, "use 0 .. population - 1")
        if self.penalty_increase < 1.0 or self.penalty_decrease < 1.0 or self.penalty_window < 1:
            raise bad("penalty_*", (self.penalty_increase, self.penalty_decrease,
                                    self.penalty_window), "factors >= 1 and window >= 1")
        if not 1 <= self.max_generations <= MAX_GENERATIONS:
            raise bad("max_generations", self.max_generations, f"use 1 to {MAX_GENERATIONS:,}")
        if self.stall_generations is not None and self.stall_generations < 1:
            raise bad("stall_generations", self.stall_generations, "use >= 1 or None")

    def replace(self, **changes: object) -> "GASettings":
        """A copy with some fields changed (validated again)."""
        return replace(self, **changes)

    @classmethod
    def seed000(cls) -> "GASettings":
        """Seed 000's GA: population 50, pc 0.7, pm 0.1, rank fitness + stochastic sampling.

        The paper gives no selection pressure, crossover or mutation operator; linear
        ranking (pressure 2), arithmetic crossover and non-uniform mutation (the usual
        real-coded MATLAB choices) are assumed. One elite keeps the best; the paper
        handles the velocity limit as a constraint: an adaptive penalty is used.
        """
        return cls(population=50, selection="rank-sus", rank_pressure=2.0,
                   crossover="arithmetic", crossover_probability=0.7,
                   mutation="non-uniform", mutation_probability=0.1, nonuniform_shape=2.0,
                   elitism=1, adaptive=False, constraint_handling="adaptive-penalty",
                   max_generations=200, stall_generations=None)

    @classmethod
    def seed002(cls) -> "GASettings":
        """Seed 002's improved GA: elitism + tournament, non-uniform mutation (c = 2),
        adaptive pc/pm and an adaptive penalty, fitness = 1 / (f + p).

        The paper prints none of pc1, pc2, pm1, pm2 nor the crossover operator (arithmetic
        here) or the generation budget. pc1 0.9 and pc2 0.6 are the usual values of this
        rule; pm1 0.2, pm2 0.01 and 600 generations were chosen over the usual pm1 0.1,
        pm2 0.001 and 300 generations by a 20-seed comparison on the seed 002 gantry
        timing (median gap to the exact optimum 0.41 % instead of 1.06 %, worst 1.05 %
        instead of 2.25 %; docs/optim.md). Nothing in the GA depends on the problem.
        """
        return cls(population=50, selection="tournament", tournament_size=2,
                   crossover="arithmetic", crossover_probability=0.9,
                   mutation="non-uniform", mutation_probability=0.1, nonuniform_shape=2.0,
                   elitism=2, adaptive=True, pc1=0.9, pc2=0.6, pm1=0.2, pm2=0.01,
                   constraint_handling="adaptive-penalty", max_generations=600,
                   stall_generations=None)
