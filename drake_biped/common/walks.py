"""What the experiments do to a walk in common: the window a learner's sample walks, the conditions without and
with a window, the steady step a push lands in, what a walk settled on (its attractor), and the re-walks of learned
windows under the changes a learner did not walk (`rewalk`: the plant step halved, the initiation speed scaled;
what a saving and a trial's holding mean is `drake_biped.analysis.rewalks`)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from drake_biped.analysis.attractor import PERIOD_TOLERANCE_S, PERIOD_WINDOW, step_period_label
from drake_biped.analysis.long_run import LONG_RUN_M, TRANSIENT_M, long_run_cost, long_run_of_record
from drake_biped.analysis.rewalks import CHANGES, KEEP, summary
from drake_biped.params import (
    GRAVITY_MPS2,
    EpisodeConfig,
    ParameterError,
    TorqueFreeWindow,
    walked_the_distance,
)

__all__ = ["CONDITIONS", "JITTER_MAX_PERIOD", "JITTER_TOLERANCE_S", "REWALK_M", "attractor_of_walk", "changed",
           "condition_window", "rewalk", "steady_step", "window_of"]


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


# A re-walk's length: the initiation's transient, then the long-run mean's span.
REWALK_M = TRANSIENT_M + LONG_RUN_M


def changed(config: EpisodeConfig, change: str) -> EpisodeConfig:
    """`config` under one of CHANGES: the plant step halved (with it the controller under the paper's clock; a
    fixed-rate loop kept), or the initiation speed scaled."""
    if change == "as_learned":
        return config
    if change == "half_step":
        return config.override({"sim.time_step_s": 0.5 * config.sim.time_step_s})
    if change in ("speed_0.95", "speed_1.05"):
        return config.override({"initial.speed_mps": float(change[6:]) * config.initial.speed_mps})
    raise ParameterError(f"re-walk change {change!r} is not one of {list(CHANGES)}")


def rewalk(config: EpisodeConfig, learned: list[dict[str, Any]], client,
           distance_m: float = REWALK_M, keep: Path | None = None) -> dict[str, Any]:
    """Walk each learned window (`learned`: {"trial", "t1", "t2"}, a policy mean, per trial) and the gait
    without a window, as learned and under each change, `distance_m` each (the long-run C_mt is measured after
    the first 10 m), on the Dask `client`: the `summary` record. `keep`: a folder where each walk is kept as it
    finishes (`{change}-{trial or no_window}.json`) and read back by a rerun, so that an interrupted re-walk
    resumes; None keeps nothing."""
    from drake_biped.common.executor import map_episodes

    plain = config.replace(window=TorqueFreeWindow()).override(
        {"sim.distance_m": distance_m, "sim.max_time_s": max(config.sim.max_time_s, 6.0 * distance_m)})
    jobs: dict[tuple[str, Any], dict[str, Any]] = {}
    for change in CHANGES:
        base = changed(plain, change)
        jobs[change, "no_window"] = base.to_dict()
        for t in learned:
            window = window_of((t["t1"], t["t2"]))
            if window.active:  # an inactive window is the walk without one
                jobs[change, t["trial"]] = base.replace(window=window).to_dict()
    keys = list(jobs)
    paths = None if keep is None else [Path(keep) / f"{change}-{key}.json" for change, key in keys]
    results = dict(zip(keys, map_episodes(client, [jobs[k] for k in keys], paths)))
    rows: dict[str, dict[Any, dict[str, Any]]] = {change: {} for change in CHANGES}
    for (change, key), r in results.items():
        rows[change][key] = {f: r[f] for f in KEEP}
        if distance_m >= REWALK_M:  # long enough for a long-run mean: the saving is of it
            long_run = long_run_of_record(r, GRAVITY_MPS2)
            rows[change][key].update(long_run_cost_of_transport=long_run["cost_of_transport"],
                                     long_run_half_width=long_run["half_width"],
                                     step_period_std_s=long_run["step_period_std_s"])
    for change in CHANGES:
        for t in learned:
            rows[change].setdefault(t["trial"], rows[change]["no_window"])
    return {**summary(config.sim.time_step_s, config.initial.speed_mps, learned, rows), "distance_m": distance_m,
            "controller_clock": config.sim.clock, "update_period_s": config.sim.update_period_s}
