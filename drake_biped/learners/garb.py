"""GARB (Kimura & Kobayashi's policy gradient with an eligibility trace and a running reward baseline), as
the paper applies it to the torque-free period (eq. 4-12, Table II). Plain numpy, no Drake.

Policy: a 2-D Gaussian over (t1, t2) with mean T̄ and covariance diag(variance, variance). For episode i
(counted from 1) with sample t and reward r, `update` applies, in this order:

    e = t - T̄                          (eq. 12: eq. 11's 1/sigma^2 folded into the learning rate)
    Z = e + beta * Z                    (eq. 6)
    B = B + (r - B) / i                 (eq. 7: the running mean of the rewards so far, this one included)
    T̄ = T̄ + alpha_p(i) * (r - B) * Z   (eq. 4 with eq. 8)

Eq. 4 and eq. 8 both print alpha_p; multiplying by it twice would make the step alpha_p^2 (1e-6 by episode
401), which no schedule would be written for, so it is applied once. alpha_p(i) follows Table II.
The learner holds its own random generator; `state()` / `from_state()` save and restore everything, so a
resumed run continues with exactly the samples an uninterrupted one would draw.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from drake_biped.learners.base import Learner
from drake_biped.learners.common import check_mean, check_number, check_seed, restored
from drake_biped.paper import TABLE_II


def learning_rate(episode: int, schedule: Sequence[tuple[int | None, float]] = TABLE_II) -> float:
    """alpha_p for episode `episode` (1-based)."""
    if not isinstance(episode, int) or episode < 1:
        raise ValueError(f"episode must be an integer >= 1, got {episode!r}")
    for last, rate in schedule:
        if last is None or episode <= last:
            return float(rate)
    return float(schedule[-1][1])


def _check_schedule(schedule) -> tuple[tuple[int | None, float], ...]:
    out = []
    previous = 0
    for k, band in enumerate(schedule):
        last, rate = band
        rate = check_number(rate, f"GarbLearner: schedule[{k}]", "learning rate", 0.0)
        if last is None:
            if k != len(schedule) - 1:
                raise ValueError(f"schedule[{k}]: only the last band may be open-ended (None)")
        elif not isinstance(last, int) or isinstance(last, bool) or last <= previous:
            raise ValueError(f"schedule[{k}]: band ends must be increasing integers, got {last!r}")
        else:
            previous = last
        out.append((last, float(rate)))
    if not out:
        raise ValueError("schedule is empty")
    return tuple(out)


class GarbLearner(Learner):
    """Gaussian policy over (t1, t2), updated once per episode (see the module docstring)."""

    name = "garb"
    SETTINGS = ("beta", "schedule")

    def __init__(
        self,
        mean: Sequence[float] = (0.5, 0.5),
        variance: float = 0.04,
        beta: float = 0.8,
        schedule: Sequence[tuple[int | None, float]] = TABLE_II,
        seed: int | None = None,
    ):
        self.mean = check_mean(mean, "GarbLearner")
        self.variance = check_number(variance, "GarbLearner", "variance", 0.0, lo_open=True)
        self.beta = check_number(beta, "GarbLearner", "beta", 0.0, 1.0, hi_open=True)
        self.schedule = _check_schedule(schedule)
        self.trace = np.zeros(2)
        self.baseline = 0.0
        self.episodes = 0  # updates so far
        self._rng = np.random.default_rng(check_seed(seed, "GarbLearner"))

    def sample(self) -> np.ndarray:
        """(t1, t2) for the next episode, drawn from N(mean, variance * I)."""
        return self.mean + math.sqrt(self.variance) * self._rng.standard_normal(2)

    def update(self, sample: Sequence[float], reward: float) -> None:
        """One GARB step with the episode's sample and reward."""
        t = np.asarray(sample, dtype=float)
        if t.shape != (2,) or not np.all(np.isfinite(t)):
            raise ValueError(f"sample must be two finite numbers, got {sample!r}")
        if not math.isfinite(reward):
            raise ValueError(f"reward must be finite, got {reward!r}")
        i = self.episodes + 1
        e = t - self.mean
        self.trace = e + self.beta * self.trace
        self.baseline += (reward - self.baseline) / i
        self.mean = self.mean + learning_rate(i, self.schedule) * (reward - self.baseline) * self.trace
        self.episodes = i

    def ask(self) -> np.ndarray:
        """The learner interface's name for `sample`."""
        return self.sample()

    def tell(self, sample: Sequence[float], reward: float) -> None:
        """The learner interface's name for `update`."""
        self.update(sample, reward)

    def info(self) -> dict[str, float]:
        """What a learning record keeps of the learner after each episode."""
        return {"baseline": self.baseline}

    def state(self) -> dict[str, Any]:
        """Everything needed to continue exactly where this learner is (JSON-serialisable)."""
        return {
            "learner": self.name,
            "mean": self.mean.tolist(),
            "variance": self.variance,
            "beta": self.beta,
            "schedule": [list(b) for b in self.schedule],
            "trace": self.trace.tolist(),
            "baseline": self.baseline,
            "episodes": self.episodes,
            "rng": self._rng.bit_generator.state,
        }

    def restarted(self, seed: int | None = None) -> GarbLearner:
        """A new run that starts from this learner's policy: the same mean, variance, beta, schedule and
        eligibility trace; the episode count back at 0, so alpha_p follows the schedule from its first band
        and the baseline becomes the running mean of the new run's rewards (eq. 7 from i = 1); its own RNG."""
        learner = GarbLearner(self.mean, self.variance, self.beta, self.schedule, seed=seed)
        learner.trace = self.trace.copy()
        learner.baseline = self.baseline
        return learner

    @classmethod
    def from_settings(cls, settings: Mapping[str, Any], seed: int | None) -> GarbLearner:
        """GARB of a learning run's settings: its beta and schedule are settings of their own (Table II)."""
        return cls(settings["mean"], settings["variance"], beta=settings["beta"],
                   schedule=[tuple(b) for b in settings["schedule"]], seed=seed, **dict(settings.get("options", {})))

    @classmethod
    def from_state(cls, state: dict[str, Any]) -> GarbLearner:
        """The learner a `state()` was saved from; ParameterError naming what a state lacks."""

        def restore(state: dict[str, Any]) -> GarbLearner:
            learner = cls(state["mean"], state["variance"], state["beta"], [tuple(b) for b in state["schedule"]])
            learner.trace = np.asarray(state["trace"], dtype=float)
            learner.baseline = float(state["baseline"])
            learner.episodes = int(state["episodes"])
            learner._rng.bit_generator.state = state["rng"]
            return learner

        return restored(cls.__name__, state, ("mean", "variance", "beta", "schedule", "trace", "baseline",
                                              "episodes", "rng"), restore)
