"""The interface every learner of the torque-free window (t1, t2) declares, and that the registry checks."""

from __future__ import annotations

import abc
from collections.abc import Mapping, Sequence
from typing import Any, ClassVar

import numpy as np

__all__ = ["Learner"]


class Learner(abc.ABC):
    """A learner of (t1, t2) from one reward per episode.

    A subclass sets `name` (how `make_learner`, `drake-biped learn --learner` and its saved states name it),
    keeps `mean` (the current estimate of (t1, t2): an attribute or a property), and implements `ask`, `tell`,
    `info`, `state` and `from_state`; `__init__(mean, variance, seed=None, **options)` builds it from a learning
    run's settings (`from_settings`, which a learner whose options live elsewhere in the settings overrides).
    `register_learner` refuses a class that is not a Learner or leaves one of these abstract.
    """

    name: ClassVar[str]
    # A learning run's settings of this learner beyond the mean, the variance and its `options`, recorded with
    # the run (GARB: its beta and Table II's schedule); none for most learners.
    SETTINGS: ClassVar[tuple[str, ...]] = ()
    mean: np.ndarray

    @abc.abstractmethod
    def ask(self) -> np.ndarray:
        """(t1, t2) for the next episode."""

    @abc.abstractmethod
    def tell(self, sample: Sequence[float], reward: float) -> None:
        """The reward of the episode that walked `sample`."""

    @abc.abstractmethod
    def info(self) -> dict[str, float]:
        """What a learning record keeps of the learner after each episode."""

    @abc.abstractmethod
    def state(self) -> dict[str, Any]:
        """Everything needed to continue exactly where this learner is (JSON-serialisable), with "learner":
        `name`."""

    @classmethod
    @abc.abstractmethod
    def from_state(cls, state: dict[str, Any]) -> Learner:
        """The learner a `state()` was saved from."""

    @classmethod
    def from_settings(cls, settings: Mapping[str, Any], seed: int | None) -> Learner:
        """The learner of a learning run's settings["learner"] (its mean, variance and options), seeded `seed`."""
        return cls(settings["mean"], settings["variance"], seed=seed, **dict(settings.get("options", {})))

    def restarted(self, seed: int | None = None) -> Learner:
        """A new run that starts from this learner's policy, with its own generator (the slope experiment
        continues a level-ground run this way); a learner that cannot restart says so."""
        raise NotImplementedError(f"learner {self.name!r} cannot start a new run from a saved policy")
