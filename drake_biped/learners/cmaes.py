"""CMA-ES over the torque-free window (t1, t2), through pycma, the reference implementation.

The strategy starts at the learner's `mean` with the initial step sigma0 = sqrt(variance) (the step GARB's
policy explores with) and its default population (6 for two parameters). The population is handed out one
sample per `ask()`, so episodes stream one at a time as they do for GARB; once every sample of a generation
has been told its reward, the strategy updates (it minimises, so it is told minus the reward). `mean` is the
distribution's mean, the current best estimate.

Randomness: the samples come from a numpy Generator seeded from (seed, generation), passed to pycma as its
`randn`, so nothing touches numpy's global state and a generation's samples depend only on the seed and on
the rewards before it. `state()` is the start, the seed, every (sample, reward) so far and how many samples are out awaiting
their rewards; `from_state()` replays them into a new strategy, which ends exactly where the saved one was.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from drake_biped.learners.base import Learner
from drake_biped.learners.common import check_mean, check_number, check_seed, restored


class CmaesLearner(Learner):
    """CMA-ES with ask/tell one episode at a time (see the module docstring)."""

    name = "cmaes"

    def __init__(self, mean: Sequence[float] = (0.5, 0.5), variance: float = 0.04, seed: int | None = None,
                 popsize: int | None = None):
        start = check_mean(mean, "CmaesLearner")
        variance = check_number(variance, "CmaesLearner", "variance", 0.0, lo_open=True)
        if popsize is not None and (not isinstance(popsize, int) or isinstance(popsize, bool) or popsize < 2):
            raise ValueError(f"popsize must be an integer >= 2, got {popsize!r}")
        seed = check_seed(seed, "CmaesLearner")
        if seed is None:
            seed = int(np.random.SeedSequence().generate_state(1)[0])
        self._start = start
        self.variance = float(variance)
        self.seed = int(seed)
        self.popsize = popsize
        self._history: list[tuple[float, float, float]] = []
        self._generation = 0
        self._rng = np.random.default_rng([self.seed, 0])
        self._es = self._strategy()
        self._population: list[np.ndarray] = []  # the current generation, in the order handed out
        self._rewards: list[float] = []  # rewards told so far in this generation
        self._handed = 0  # samples of this generation handed out

    def _randn(self, *shape: int) -> np.ndarray:
        return self._rng.standard_normal(shape)

    def _strategy(self):
        import cma

        opts = {"seed": math.nan, "randn": self._randn, "verbose": -9, "CMA_mirrors": 0}
        if self.popsize is not None:
            opts["popsize"] = self.popsize
        return cma.CMAEvolutionStrategy(self._start.tolist(), math.sqrt(self.variance), opts)

    @property
    def mean(self) -> np.ndarray:
        """The distribution's mean (t1, t2): the current best estimate."""
        return np.asarray(self._es.mean, dtype=float).copy()

    @property
    def step(self) -> float:
        """The strategy's overall step size sigma."""
        return float(self._es.sigma)

    @property
    def episodes(self) -> int:
        return len(self._history)

    def ask(self) -> np.ndarray:
        """(t1, t2) for the next episode: the next sample of the current generation."""
        if self._handed == len(self._population):
            if self._population:
                raise RuntimeError("ask: every sample of this generation is out; tell their rewards first")
            self._generation += 1
            self._rng = np.random.default_rng([self.seed, self._generation])
            self._population = [np.asarray(x, dtype=float) for x in self._es.ask()]
            self._handed = 0
        sample = self._population[self._handed].copy()
        self._handed += 1
        return sample

    def tell(self, sample: Sequence[float], reward: float) -> None:
        """The reward of the oldest sample handed out and not yet told (it must be `sample`)."""
        t = np.asarray(sample, dtype=float)
        k = len(self._rewards)
        if k >= self._handed or t.shape != (2,) or not np.allclose(t, self._population[k], rtol=0, atol=1e-12):
            raise ValueError(f"tell: {sample!r} is not the next sample awaiting its reward")
        if not math.isfinite(reward):
            raise ValueError(f"reward must be finite, got {reward!r}")
        self._rewards.append(float(reward))
        self._history.append((float(t[0]), float(t[1]), float(reward)))
        if len(self._rewards) == len(self._population):
            self._es.tell(self._population, [-r for r in self._rewards])
            self._population, self._rewards, self._handed = [], [], 0

    def info(self) -> dict[str, float]:
        """What a learning record keeps of the learner after each episode."""
        return {"step": self.step}

    def state(self) -> dict[str, Any]:
        """Everything needed to continue exactly where this learner is (JSON-serialisable)."""
        return {"learner": self.name, "start": self._start.tolist(), "variance": self.variance, "seed": self.seed,
                "popsize": self.popsize, "history": [list(h) for h in self._history],
                "pending": self._handed - len(self._rewards)}

    @classmethod
    def from_state(cls, state: dict[str, Any]) -> CmaesLearner:
        """The learner a `state()` was saved from; ParameterError naming what a state lacks."""

        def restore(state: dict[str, Any]) -> CmaesLearner:
            learner = cls(state["start"], state["variance"], seed=state["seed"], popsize=state.get("popsize"))
            for t1, t2, r in state["history"]:
                sample = learner.ask()
                if not np.allclose(sample, (t1, t2), rtol=0, atol=1e-9):
                    raise ValueError("CMA-ES state: its history does not replay (another pycma version?)")
                learner.tell(sample, r)
            for _ in range(int(state.get("pending", 0))):  # handed out before the save, not yet told
                learner.ask()
            return learner

        return restored(cls.__name__, state, ("start", "variance", "seed", "history"), restore)
