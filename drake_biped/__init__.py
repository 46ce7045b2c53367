"""drake-biped: a CPG-driven 7-link biped in Drake that learns a torque-free hip period (GARB).

The public API for analysis scripts; none of it imports dask or matplotlib::

    import drake_biped as db

    result = db.run_episode(db.EpisodeConfig(window=db.TorqueFreeWindow(0.2, 0.5)))
    print(result.cost_of_transport, result.distance_m, result.sections[:3])

    config = db.EpisodeConfig().override({"u_a": 1.7, "sim.distance_m": 4.0})  # dotted or short names
    climbing = db.load_gait("climbing")                                          # a shipped gait

Where things live: the CPG (eq. 2-3) in `cpg`, the gait's servos and touchdown rule in `gait`, the controller
(a Drake LeafSystem, the torque-free gate and the energy count) in `controller`, the plant in `model`, the
diagram in `diagram`, one episode in `episode`; C_mt (eq. 1) and the reward (eq. 13) in `analysis`, the
return-map fit in `analysis.return_map`, GARB (eq. 4-12) in `learners.garb`; each experiment (and its
command) in `experiments`; the paper's printed numbers in `paper`.

Names are imported on first use, so `import drake_biped` is cheap and a script pays only for what it uses.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from drake_biped.versions import PACKAGE_VERSION as __version__

# name -> module that defines it
_API = {
    # configuration (validated frozen dataclasses)
    "EpisodeConfig": "drake_biped.params",
    "CpgParams": "drake_biped.params",
    "GaitParams": "drake_biped.params",
    "InitialConditions": "drake_biped.params",
    "TorqueFreeWindow": "drake_biped.params",
    "Push": "drake_biped.params",
    "Ground": "drake_biped.params",
    "SimulationParams": "drake_biped.params",
    "ParameterError": "drake_biped.params",
    "DEFAULT_CPG": "drake_biped.params",
    "DEFAULT_GAIT": "drake_biped.params",
    "PAPER_CPG": "drake_biped.params",
    "RobotModel": "drake_biped.params",
    # shipped gaits
    "load_gait": "drake_biped.resources",
    "gait_names": "drake_biped.resources",
    "shipped_model_file": "drake_biped.resources",
    # simulation
    "build_plant": "drake_biped.model",
    "body_of_model": "drake_biped.model",
    "ModelError": "drake_biped.model",
    "JOINT_NAMES": "drake_biped.model",
    "build_diagram": "drake_biped.diagram",
    "BipedDiagram": "drake_biped.diagram",
    "CpgWalkingController": "drake_biped.controller",
    "run_episode": "drake_biped.episode",
    "simulate": "drake_biped.episode",
    "EpisodeResult": "drake_biped.episode",
    "StepRecord": "drake_biped.episode",
    "Kick": "drake_biped.episode",
    # learning and analysis
    "GarbLearner": "drake_biped.learners.garb",
    "Learner": "drake_biped.learners.base",
    "make_learner": "drake_biped.learners.registry",
    "register_learner": "drake_biped.learners.registry",
    "reward": "drake_biped.analysis.reward",
    "cost_of_transport": "drake_biped.analysis.cost_of_transport",
    "cost_of_transport_per_kg": "drake_biped.analysis.cost_of_transport",
    "fit_return_map": "drake_biped.analysis.return_map",
    "ReturnMapFit": "drake_biped.analysis.return_map",
    "moving_average": "drake_biped.analysis.series",
    "DrakeFailure": "drake_biped.api_guard",
}

__all__ = ["__version__", *_API]

# The functions that run Drake, handed out through `api_guard.api_function`: a configuration of the wrong
# type is a ParameterError naming the argument, and a failed check inside Drake (a DRAKE_DEMAND, which
# pydrake raises as SystemExit and `except Exception` misses) is a DrakeFailure naming the function.
_RUN_DRAKE = {"build_plant", "build_diagram", "run_episode", "simulate"}


def __getattr__(name: str) -> Any:
    module = _API.get(name)
    if module is None:
        raise AttributeError(f"module 'drake_biped' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    if name in _RUN_DRAKE:
        from drake_biped.api_guard import api_function

        value = api_function(value)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_API))


if TYPE_CHECKING:  # for type checkers and IDEs: the same names, imported eagerly
    from drake_biped.analysis.cost_of_transport import cost_of_transport, cost_of_transport_per_kg
    from drake_biped.analysis.return_map import ReturnMapFit, fit_return_map
    from drake_biped.analysis.reward import reward
    from drake_biped.analysis.series import moving_average
    from drake_biped.api_guard import DrakeFailure
    from drake_biped.controller import CpgWalkingController
    from drake_biped.diagram import BipedDiagram, build_diagram
    from drake_biped.episode import EpisodeResult, Kick, StepRecord, run_episode, simulate
    from drake_biped.learners.base import Learner
    from drake_biped.learners.garb import GarbLearner
    from drake_biped.model import JOINT_NAMES, ModelError, build_plant
    from drake_biped.params import (
        DEFAULT_CPG,
        DEFAULT_GAIT,
        PAPER_CPG,
        CpgParams,
        EpisodeConfig,
        GaitParams,
        Ground,
        InitialConditions,
        ParameterError,
        Push,
        SimulationParams,
        TorqueFreeWindow,
    )
    from drake_biped.resources import gait_names, load_gait
