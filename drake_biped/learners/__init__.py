"""Learners of the torque-free period (t1, t2): plain numpy (and pycma), no Drake.

Every learner has the same interface: `ask()` -> one (t1, t2) per episode, `tell(sample, reward)`, `mean`
(the current best estimate), `info()` (what a learning record keeps after each episode), `state()` and
`from_state()` for an exact resume. `make_learner(name, mean, variance, seed, **options)` builds one:

- "garb": GARB as the paper prints it (eq. 4-12, Table II; `GarbLearner`), options beta, schedule;
- "cmaes": CMA-ES through pycma (`CmaesLearner`), initial step sqrt(variance), option popsize;
- "pgpe": symmetric PGPE with normalised rewards and an adapted sigma (`PgpeLearner`), options mean_rate,
  sigma_rate.

A new learner is a class with that interface, added with `register_learner` (see examples/custom_learner.py).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from drake_biped.learners.cmaes import CmaesLearner
from drake_biped.learners.garb import GarbLearner, learning_rate
from drake_biped.learners.pgpe import PgpeLearner

__all__ = ["CmaesLearner", "GarbLearner", "LEARNERS", "PgpeLearner", "learner_from_state", "learning_rate",
           "make_learner", "register_learner"]

LEARNERS: dict[str, type] = {"garb": GarbLearner, "cmaes": CmaesLearner, "pgpe": PgpeLearner}


def register_learner(cls: type) -> type:
    """Make `cls` (with a `name`, the interface above, and __init__(mean, variance, seed, **options))
    available to make_learner and `drake-biped learn --learner` by its name. Returns cls (a decorator)."""
    for attr in ("name", "ask", "tell", "info", "state", "from_state"):
        if not hasattr(cls, attr):
            raise TypeError(f"{cls.__name__} has no {attr!r}: not a learner")
    LEARNERS[cls.name] = cls
    return cls


def make_learner(name: str, mean: Sequence[float] = (0.5, 0.5), variance: float = 0.04, seed: int | None = None,
                 **options: Any):
    """A learner by name (module docstring), starting at `mean` with exploration variance `variance` (s^2)."""
    try:
        cls = LEARNERS[name]
    except KeyError:
        raise ValueError(f"learner {name!r} is not one of {sorted(LEARNERS)}") from None
    return cls(mean, variance, seed=seed, **options)


def learner_from_state(state: dict[str, Any]):
    """The learner a `state()` was saved from (GARB for states that name none, as older records do)."""
    name = state.get("learner", "garb")
    try:
        return LEARNERS[name].from_state(state)
    except KeyError:
        raise ValueError(f"learner {name!r} of a saved state is not one of {sorted(LEARNERS)}") from None
