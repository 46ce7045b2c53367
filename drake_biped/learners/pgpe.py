"""PGPE: policy gradients with parameter-based exploration and symmetric sampling (Sehnke et al. 2010).

A modern relative of GARB for the same two parameters. Each pair of episodes explores one perturbation e,
drawn per parameter from N(0, sigma^2), in both directions: t+ = mean + e and t- = mean - e. With their
rewards r+ and r- and m the best reward seen so far:

    mean  += mean_rate * e * (r+ - r-) / (2 m - r+ - r-)                  (the symmetric gradient, normalised)
    sigma += sigma_rate * (r_bar - b) / (m - b) * (e^2 - sigma^2) / sigma  (r_bar = (r+ + r-) / 2)
    b     += (r_bar - b) / 10                                              (a running baseline)

The normalisations make both steps independent of the reward's unit (GARB's step is not), and sigma adapts
instead of being fixed. sigma starts at sqrt(variance) and is kept in [1e-3, 1] s.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from drake_biped.learners.base import Learner
from drake_biped.learners.common import check_mean, check_number, check_seed, restored


class PgpeLearner(Learner):
    """Symmetric PGPE over (t1, t2), one episode per ask/tell (see the module docstring)."""

    name = "pgpe"
    SIGMA_RANGE = (1e-3, 1.0)

    def __init__(self, mean: Sequence[float] = (0.5, 0.5), variance: float = 0.04, seed: int | None = None,
                 mean_rate: float = 0.2, sigma_rate: float = 0.1):
        self.mean = check_mean(mean, "PgpeLearner")
        variance = check_number(variance, "PgpeLearner", "variance", 0.0, lo_open=True)
        self.sigma = np.full(2, math.sqrt(variance))
        self.mean_rate = check_number(mean_rate, "PgpeLearner", "mean_rate", 0.0)
        self.sigma_rate = check_number(sigma_rate, "PgpeLearner", "sigma_rate", 0.0)
        self.baseline: float | None = None
        self.best = -math.inf
        self.episodes = 0
        self._perturbation: np.ndarray | None = None
        self._pending: list[np.ndarray] = []  # samples of the current pair handed out, not yet told
        self._rewards: list[float] = []
        self._rng = np.random.default_rng(check_seed(seed, "PgpeLearner"))

    def ask(self) -> np.ndarray:
        """(t1, t2) for the next episode: mean + e, then mean - e."""
        handed = len(self._rewards) + len(self._pending)
        if handed == 0:
            self._perturbation = self.sigma * self._rng.standard_normal(2)
        elif handed >= 2:
            raise RuntimeError("ask: both samples of this pair are out; tell their rewards first")
        sign = 1.0 if handed == 0 else -1.0
        sample = self.mean + sign * self._perturbation
        self._pending.append(sample)
        return sample.copy()

    def tell(self, sample: Sequence[float], reward: float) -> None:
        """The reward of the oldest sample handed out and not yet told (it must be `sample`)."""
        t = np.asarray(sample, dtype=float)
        if not self._pending or t.shape != (2,) or not np.allclose(t, self._pending[0], rtol=0, atol=1e-12):
            raise ValueError(f"tell: {sample!r} is not the next sample awaiting its reward")
        if not math.isfinite(reward):
            raise ValueError(f"reward must be finite, got {reward!r}")
        self._pending.pop(0)
        self._rewards.append(float(reward))
        self.episodes += 1
        if len(self._rewards) < 2:
            return
        r_plus, r_minus = self._rewards
        e = self._perturbation
        self.best = max(self.best, r_plus, r_minus)
        r_bar = 0.5 * (r_plus + r_minus)
        if self.baseline is None:
            self.baseline = r_bar
        denominator = 2.0 * self.best - r_plus - r_minus
        if denominator > 0.0:
            self.mean = self.mean + self.mean_rate * e * (r_plus - r_minus) / denominator
        if self.best > self.baseline:
            step = self.sigma_rate * (r_bar - self.baseline) / (self.best - self.baseline)
            self.sigma = np.clip(self.sigma + step * (e * e - self.sigma ** 2) / self.sigma, *self.SIGMA_RANGE)
        self.baseline += (r_bar - self.baseline) / 10.0
        self._rewards, self._perturbation = [], None

    def info(self) -> dict[str, float]:
        """What a learning record keeps of the learner after each episode."""
        return {"sigma_t1": float(self.sigma[0]), "sigma_t2": float(self.sigma[1])}

    def state(self) -> dict[str, Any]:
        return {
            "learner": self.name, "mean": self.mean.tolist(), "sigma": self.sigma.tolist(),
            "mean_rate": self.mean_rate, "sigma_rate": self.sigma_rate, "baseline": self.baseline,
            "best": self.best if math.isfinite(self.best) else None, "episodes": self.episodes,
            "perturbation": None if self._perturbation is None else self._perturbation.tolist(),
            "pending": [p.tolist() for p in self._pending], "rewards": list(self._rewards),
            "rng": self._rng.bit_generator.state,
        }

    @classmethod
    def from_state(cls, state: dict[str, Any]) -> PgpeLearner:
        """The learner a `state()` was saved from; ParameterError naming what a state lacks."""

        def restore(state: dict[str, Any]) -> PgpeLearner:
            learner = cls(state["mean"], 0.04, mean_rate=state["mean_rate"], sigma_rate=state["sigma_rate"])
            learner.sigma = np.asarray(state["sigma"], dtype=float)
            learner.baseline = state["baseline"]
            learner.best = -math.inf if state["best"] is None else float(state["best"])
            learner.episodes = int(state["episodes"])
            p = state["perturbation"]
            learner._perturbation = None if p is None else np.asarray(p, dtype=float)
            learner._pending = [np.asarray(x, dtype=float) for x in state["pending"]]
            learner._rewards = [float(r) for r in state["rewards"]]
            learner._rng.bit_generator.state = state["rng"]
            return learner

        return restored(cls.__name__, state, ("mean", "mean_rate", "sigma_rate", "sigma", "baseline", "best",
                                              "episodes", "perturbation", "pending", "rewards", "rng"), restore)
