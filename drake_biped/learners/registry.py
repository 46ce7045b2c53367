"""The learners by name: make_learner, register_learner, learner_from_state (see drake_biped.learners)."""


from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

from drake_biped.learners.base import Learner
from drake_biped.learners.cmaes import CmaesLearner
from drake_biped.learners.common import check_seed
from drake_biped.learners.garb import GarbLearner
from drake_biped.learners.pgpe import PgpeLearner
from drake_biped.params import ParameterError

__all__ = ["DEFAULT_LEARNER", "LEARNERS", "learner_class", "learner_from_state", "make_learner", "register_learner"]

LEARNERS: dict[str, type[Learner]] = {cls.name: cls for cls in (GarbLearner, CmaesLearner, PgpeLearner)}
# The paper's learner: the one a learning run uses unless told, and the one a saved state or a record that names
# no learner (as older records do) was made by.
DEFAULT_LEARNER = GarbLearner.name


def register_learner(cls: type) -> type:
    """Make `cls`, a subclass of `Learner` that implements its interface, available to make_learner and
    `drake-biped learn --learner` by its `name`. Returns cls (a decorator)."""
    if not (isinstance(cls, type) and issubclass(cls, Learner)):
        raise TypeError(f"{getattr(cls, '__name__', cls)!r} is not a subclass of drake_biped.learners.Learner")
    missing = sorted(getattr(cls, "__abstractmethods__", ()))
    if missing:
        raise TypeError(f"{cls.__name__} leaves {missing} of the Learner interface unimplemented")
    if not isinstance(getattr(cls, "name", None), str) or not cls.name:
        raise TypeError(f"{cls.__name__} has no name (a class attribute: how make_learner finds it)")
    LEARNERS[cls.name] = cls
    return cls


def learner_class(name: str) -> type[Learner]:
    """The registered learner `name`, or ParameterError naming the learners there are."""
    try:
        return LEARNERS[name]
    except (KeyError, TypeError):
        raise ParameterError(f"learner {name!r} is not one of {sorted(LEARNERS)}") from None


def make_learner(name: str, mean: Sequence[float] = (0.5, 0.5), variance: float = 0.04, seed: int | None = None,
                 **options: Any):
    """A learner by name (see drake_biped.learners), starting at `mean` with exploration variance `variance` (s^2)."""
    try:
        cls = learner_class(name)
    except ParameterError as exc:
        raise ParameterError(f"make_learner: {exc}") from None
    return cls(mean, variance, seed=check_seed(seed, f"make_learner({name!r})"), **options)


def learner_from_state(state: dict[str, Any]):
    """The learner a `state()` was saved from (DEFAULT_LEARNER for states that name none, as older records do)."""
    if not isinstance(state, Mapping):
        raise ParameterError(f"learner_from_state: expected the mapping a learner's state() returns, got "
                             f"{type(state).__name__}")
    name = state.get("learner", DEFAULT_LEARNER)
    try:
        cls = LEARNERS[name]
    except (KeyError, TypeError):
        raise ParameterError(f"learner {name!r} of a saved state is not one of {sorted(LEARNERS)}") from None
    return cls.from_state(state)
