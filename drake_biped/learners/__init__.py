"""Learners of the torque-free period (t1, t2): plain numpy (and pycma), no Drake.

Every learner declares the same interface, the abstract base `Learner` (drake_biped/learners/base.py): `ask()` -> one (t1, t2) per episode, `tell(sample, reward)`, `mean`
(the current best estimate), `info()` (what a learning record keeps after each episode), `state()` and
`from_state()` for an exact resume. `make_learner(name, mean, variance, seed, **options)` builds one:

- "garb": GARB as the paper prints it (eq. 4-12, Table II; `GarbLearner`), options beta, schedule;
- "cmaes": CMA-ES through pycma (`CmaesLearner`), initial step sqrt(variance), option popsize;
- "pgpe": symmetric PGPE with normalised rewards and an adapted sigma (`PgpeLearner`), options mean_rate,
  sigma_rate.

A new learner subclasses `Learner`, added with `register_learner`, which refuses a class that does not (see
examples/custom_learner.py).
"""

from drake_biped.learners.base import Learner
from drake_biped.learners.cmaes import CmaesLearner
from drake_biped.learners.garb import GarbLearner, learning_rate
from drake_biped.learners.pgpe import PgpeLearner
from drake_biped.learners.registry import LEARNERS, learner_from_state, make_learner, register_learner

__all__ = ["CmaesLearner", "GarbLearner", "LEARNERS", "Learner", "PgpeLearner", "learner_from_state", "learning_rate",
           "make_learner", "register_learner"]
