"""Learned torque-free periods re-walked where the learner did not walk them: with the plant step halved, and
from 0.95 and 1.05 x the initiation speed, each against the walk without a window under the same change.

A learner scores windows in one simulation, from one start; a saving that holds only there is an edge of that
simulation, not a property of the robot. Every learning run (`drake-biped learn`, `compare-learners`,
`reproduce`) re-walks each trial's final policy mean so, and `drake-biped rewalk --policy learning.json` does it
for any learning record. What a saving, a trial's figure and holding mean: `drake_biped.analysis.rewalks`.
"""

from __future__ import annotations

from typing import Any

from drake_biped.analysis.long_run import LONG_RUN_M, TRANSIENT_M, long_run_of_record
from drake_biped.analysis.rewalks import CHANGES, KEEP, summary
from drake_biped.params import GRAVITY_MPS2, EpisodeConfig, ParameterError, TorqueFreeWindow

# A re-walk's length: the initiation's transient, then the long-run mean's span.
REWALK_M = TRANSIENT_M + LONG_RUN_M

__all__ = ["changed", "rewalk", "window_of"]


def window_of(sample) -> TorqueFreeWindow:
    """The window a learner's sample (t1, t2) walks: times below 0 act as 0, above 10 s as 10 s."""
    t1, t2 = (max(0.0, min(float(x), 10.0)) for x in sample)
    return TorqueFreeWindow(t1, t2)


def changed(config: EpisodeConfig, change: str) -> EpisodeConfig:
    """`config` under one of CHANGES: the plant step halved (the control period kept), or the initiation speed
    scaled."""
    if change == "as_learned":
        return config
    if change == "half_step":
        return config.override({"sim.time_step_s": 0.5 * config.sim.time_step_s})
    if change in ("speed_0.95", "speed_1.05"):
        return config.override({"initial.speed_mps": float(change[6:]) * config.initial.speed_mps})
    raise ParameterError(f"re-walk change {change!r} is not one of {list(CHANGES)}")


def rewalk(config: EpisodeConfig, learned: list[dict[str, Any]], client,
           distance_m: float = REWALK_M) -> dict[str, Any]:
    """Walk each learned window (`learned`: {"trial", "t1", "t2"}, a policy mean, per trial) and the gait
    without a window, as learned and under each change, `distance_m` each (the long-run C_mt is measured after
    the first 10 m), on the Dask `client`: the `summary` record."""
    from drake_biped.experiments.executor import episode_task

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
    futures = {key: client.submit(episode_task, c, pure=False) for key, c in jobs.items()}
    results = dict(zip(futures, client.gather(list(futures.values()))))
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
    return {**summary(config.sim.time_step_s, config.initial.speed_mps, learned, rows), "distance_m": distance_m}
