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

from drake_biped.learners.cmaes import CmaesLearner
from drake_biped.learners.garb import GarbLearner, learning_rate
from drake_biped.learners.pgpe import PgpeLearner
from drake_biped.learners.registry import LEARNERS, learner_from_state, make_learner, register_learner

__all__ = ["CmaesLearner", "GarbLearner", "LEARNERS", "PgpeLearner", "learner_from_state", "learning_rate",
           "make_learner", "register_learner"]
