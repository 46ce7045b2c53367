"""The learners by name: make_learner, register_learner, learner_from_state (see drake_biped.learners)."""


from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

from drake_biped.learners.cmaes import CmaesLearner
from drake_biped.learners.common import check_seed
from drake_biped.learners.garb import GarbLearner
from drake_biped.learners.pgpe import PgpeLearner
from drake_biped.params import ParameterError

__all__ = ["LEARNERS", "learner_from_state", "make_learner", "register_learner"]

LEARNERS: dict[str, type] = {"garb": GarbLearner, "cmaes": CmaesLearner, "pgpe": PgpeLearner}


def register_learner(cls: type) -> type:
    """Make `cls` (with a `name`, the interface of drake_biped.learners, and __init__(mean, variance, seed, **options))
    available to make_learner and `drake-biped learn --learner` by its name. Returns cls (a decorator)."""
    for attr in ("name", "ask", "tell", "info", "state", "from_state"):
        if not hasattr(cls, attr):
            raise TypeError(f"{cls.__name__} has no {attr!r}: not a learner")
    LEARNERS[cls.name] = cls
    return cls


def make_learner(name: str, mean: Sequence[float] = (0.5, 0.5), variance: float = 0.04, seed: int | None = None,
                 **options: Any):
    """A learner by name (see drake_biped.learners), starting at `mean` with exploration variance `variance` (s^2)."""
    try:
        cls = LEARNERS[name]
    except (KeyError, TypeError):
        raise ParameterError(f"make_learner: learner {name!r} is not one of {sorted(LEARNERS)}") from None
    return cls(mean, variance, seed=check_seed(seed, f"make_learner({name!r})"), **options)


def learner_from_state(state: dict[str, Any]):
    """The learner a `state()` was saved from (GARB for states that name none, as older records do)."""
    if not isinstance(state, Mapping):
        raise ParameterError(f"learner_from_state: expected the mapping a learner's state() returns, got "
                             f"{type(state).__name__}")
    name = state.get("learner", "garb")
    try:
        cls = LEARNERS[name]
    except (KeyError, TypeError):
        raise ParameterError(f"learner {name!r} of a saved state is not one of {sorted(LEARNERS)}") from None
    return cls.from_state(state)
