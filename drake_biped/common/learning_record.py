"""A learning run's record (learning.json): the fields every episode row holds, the check that a file is one,
and the learned torque-free period it ended on. Shared by the commands that read a learning record (learn,
rewalk, stability --policy, slope --policy, reproduce)."""

from __future__ import annotations

from typing import Any

from drake_biped.analysis.rewalks import window_acted
from drake_biped.params import ParameterError

__all__ = ["EPISODE_FIELDS", "best_learned_trial", "check_learning_record"]

EPISODE_FIELDS = ("reward", "cost_of_transport", "fell", "t1", "t2", "mean_t1", "mean_t2")


def check_learning_record(record: Any, source: str = "learning.json") -> dict[str, Any]:
    """`record` when it holds what the figures are drawn from (trials, each with its number and episodes of
    EPISODE_FIELDS, and the settings' distance); otherwise ParameterError naming `source` and what is missing."""

    def refuse(what: str):
        raise ParameterError(f"{source}: not a learning record (the learning.json of drake-biped learn): {what}")

    if not isinstance(record, dict):
        refuse(f"it holds a JSON {type(record).__name__}, not an object")
    trials = record.get("trials")
    if not isinstance(trials, list) or not trials:
        refuse("it has no 'trials' list" if "trials" not in record else "its 'trials' is not a non-empty list")
    for k, trial in enumerate(trials):
        episodes = trial.get("episodes") if isinstance(trial, dict) else None
        if not isinstance(episodes, list) or not episodes or "trial" not in trial:
            refuse(f"trials[{k}] is not a trial with its number and episodes")
        for i, episode in enumerate(episodes):
            missing = [f for f in EPISODE_FIELDS if not isinstance(episode, dict) or f not in episode]
            if missing:
                refuse(f"trials[{k}], episode {i + 1} has no {', '.join(map(repr, missing))}")
    try:
        float(record["settings"]["config"]["sim"]["distance_m"])
    except (KeyError, TypeError, ValueError):
        refuse("it has no settings.config.sim.distance_m")
    return record


def best_learned_trial(record: dict[str, Any], source: str = "learning.json") -> dict[str, Any]:
    """The learned torque-free period of a learning record: of the trials whose final policy mean has a
    window that acted (`window_acted`: t̄2 > t̄1, and the walk not the one without a window) and walked the
    distance in the evaluation, the one with the lowest C_mt (a mean over trials would blend trials that
    learned a window with trials that learned none). Its evaluation row (trial, t1, t2, cost_of_transport,
    ...); ParameterError if there is none."""
    try:
        no_window = record["evaluation"].get("no_window")
        rows = [r for r in record["evaluation"]["learned"]
                if not r["fell"] and r["cost_of_transport"] is not None and window_acted(r, no_window)]
    except (KeyError, TypeError, ValueError) as exc:
        raise ParameterError(f"{source}: not a learning record with an evaluation ({exc})") from None
    if not rows:
        raise ParameterError(f"{source}: no trial learned a torque-free period that walks "
                             "(every final mean has t2 <= t1, falls, or never frees the hip)")
    return min(rows, key=lambda r: float(r["cost_of_transport"]))
