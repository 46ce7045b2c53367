"""What the experiments do to a walk in common: the window a learner's sample walks, the conditions without and
with a window, the steady step a push lands in, and what a walk settled on (its attractor)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from drake_biped.analysis.attractor import PERIOD_TOLERANCE_S, PERIOD_WINDOW, step_period_label
from drake_biped.analysis.long_run import TRANSIENT_M, long_run_cost
from drake_biped.params import GRAVITY_MPS2, TorqueFreeWindow, walked_the_distance

__all__ = ["CONDITIONS", "JITTER_MAX_PERIOD", "JITTER_TOLERANCE_S", "attractor_of_walk", "condition_window",
           "steady_step", "window_of"]


def window_of(sample) -> TorqueFreeWindow:
    """The window a learner's sample (t1, t2) walks: times below 0 act as 0, above 10 s as 10 s."""
    t1, t2 = (max(0.0, min(float(x), 10.0)) for x in sample)
    return TorqueFreeWindow(t1, t2)


CONDITIONS = ("without", "with")


def condition_window(condition: str, window: tuple[float, float]) -> TorqueFreeWindow:
    """The torque-free window of a condition: `window` "with", none "without"."""
    return TorqueFreeWindow(*window) if condition == "with" else TorqueFreeWindow(0.0, 0.0)


def steady_step(result: dict[str, Any], settle_s: float) -> tuple[float, float] | None:
    """(T_k, T_k+1): the first whole step of an unpushed walk that starts at or after `settle_s`."""
    times = [s["touchdown_time_s"] for s in result["steps"]]
    for a, b in zip(times, times[1:]):
        if a >= settle_s:
            return a, b
    return None


# The step periods of a regular gait jitter by a few ms (the controller sees a touchdown at its next update):
# the tolerance of the reading at that scale, and the longest period it names (every k-th of 20 periods is too
# few to tell a period-4 at 10 ms from an irregular walk).
JITTER_TOLERANCE_S = 0.01
JITTER_MAX_PERIOD = 2


def attractor_of_walk(result: dict[str, Any], distance_m: float, transient_m: float = TRANSIENT_M,
                      window: int = PERIOD_WINDOW, tolerance_s: float = PERIOD_TOLERANCE_S) -> dict[str, Any]:
    """What a walk (an episode's result dictionary) settled on: its steps after the transient (step periods,
    section states), the attractor they show (analysis.attractor.step_period_label: "period-k", "irregular",
    "fell", or "too short" when the walk kept too few steps), and its long-run C_mt with the 95 % interval."""
    steps = result["steps"]
    times = np.array([s["touchdown_time_s"] for s in steps], dtype=float)
    com = np.array([s["com_x_m"] for s in steps], dtype=float)
    work = np.array([math.nan if s["positive_work_j"] is None else s["positive_work_j"] for s in steps], dtype=float)
    fell = not walked_the_distance(result["fell"], result["distance_m"], distance_m)
    first = int(np.searchsorted(com - com[0], transient_m, side="left")) if len(com) else 0
    periods = np.diff(times[first:])
    sections = [[s["hip_angle_rad"], s["hip_rate_radps"]] for s in steps[first + 1:]]
    label = step_period_label(periods, fell=fell, window=window, tolerance_s=tolerance_s)
    long_run = long_run_cost(times, com, work, result["mass_kg"], GRAVITY_MPS2, transient_m) if not fell else None
    return {"fell": fell, "fall_reason": result.get("fall_reason") or None, "distance_m": result["distance_m"],
            "first_kept_step": first, "step_periods_s": [float(t) for t in periods], "sections": sections,
            **label,
            "cost_of_transport": None if long_run is None else long_run["cost_of_transport"],
            "interval_95": None if long_run is None else long_run["interval_95"]}
