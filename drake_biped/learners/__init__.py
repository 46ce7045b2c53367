"""Learners of the torque-free period: plain numpy, no Drake. GARB as the paper prints it (eq. 4-12)."""

from drake_biped.learners.garb import GarbLearner, learning_rate

__all__ = ["GarbLearner", "learning_rate"]
