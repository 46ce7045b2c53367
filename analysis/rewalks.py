"""Learned torque-free periods re-walked where the learner did not walk them (the record's summary and report;
the walks: `drake_biped.common.walks.rewalk`).

A walk's saving is 1 - C_mt(window) / C_mt(no window) under the same change, each the walk's long-run C_mt
(analysis.long_run: the walks are 110 m, the first 10 m dropped) where the record has it, else the episode's
(records made before walks were long); where either walk falls it has none (a fall is counted, never
averaged). A trial's saving is the mean of its four walks' (as learned and the
three changes); the run's figure is the mean over trials with its standard deviation. A trial holds when every
one of its four walks walks and saves at least HOLD_SAVING.

The `rewalk` command (drake_biped/experiments/rewalk.py) walks the windows again; this module, named for its
records by design, reduces them.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from drake_biped.analysis.cost_of_transport import format_cost
from drake_biped.analysis.long_run import measure_text
from drake_biped.analysis.series import cmt_change, spread_text, window_text

__all__ = ["CHANGES", "HOLD_SAVING", "headline", "markdown", "measured_cost", "summary", "window_acted"]

# The walk as learned, then the changes it is re-walked under.
CHANGES = ("as_learned", "half_step", "speed_0.95", "speed_1.05")
CHANGE_WORDS = {"as_learned": "as learned", "half_step": "half the plant step",
                "speed_0.95": "0.95 x the initiation speed", "speed_1.05": "1.05 x the initiation speed"}
# A learned window holds when it saves at least this much in every re-walk.
HOLD_SAVING = 0.35
# What a re-walk keeps of an episode's result.
KEEP = ("cost_of_transport", "distance_m", "fell", "mean_speed_mps", "step_period_s")


# What identifies a walk in an evaluation row: the same simulation gives the same figures to the last digit.
_WALK = ("cost_of_transport", "distance_m", "mean_speed_mps", "step_period_s")


def window_acted(row: dict[str, Any], no_window: dict[str, Any] | None) -> bool:
    """Whether a trial's final policy mean (an evaluation row) freed the hip in its walk: it has a window
    (t̄2 > t̄1), and its walk is not the walk without one to the last digit (`no_window`: the evaluation's row;
    None: not compared). A window that opens only after every step has ended (t̄1 beyond the step period)
    never frees the hip, and the simulation is the one without it."""
    if not float(row["t2"]) > max(0.0, float(row["t1"])):
        return False
    if not no_window:
        return True
    return any(row.get(k) != no_window.get(k) for k in _WALK)


def measured_cost(row: dict[str, Any]) -> float | None:
    """A re-walk's C_mt: its long-run one where it was measured, else the episode's."""
    if "long_run_cost_of_transport" in row:
        return row["long_run_cost_of_transport"]
    return row["cost_of_transport"]


def _saving(row: dict[str, Any], base: dict[str, Any]) -> float | None:
    cost, base_cost = measured_cost(row), measured_cost(base)
    if row["fell"] or base["fell"] or not cost or not base_cost:
        return None
    return 1.0 - cost / base_cost


def summary(time_step_s: float, speed_mps: float, learned: list[dict[str, Any]],
            rows: dict[str, dict[Any, dict[str, Any]]]) -> dict[str, Any]:
    """The re-walks' record from their results (walks at plant step `time_step_s` from `speed_mps`, before the
    changes). learned: {"trial", "t1", "t2"} per trial; rows[change]: the walk without a window under the change
    as "no_window", trial k's as k (module docstring)."""
    trials = []
    for t in learned:
        walks = {change: rows[change][t["trial"]] for change in CHANGES}
        savings = {change: _saving(walks[change], rows[change]["no_window"]) for change in CHANGES}
        kept = [s for s in savings.values() if s is not None]
        trials.append({**t, "walks": walks, "savings": savings,
                       "mean_saving": float(np.mean(kept)) if kept else None,
                       "least_saving": min(kept) if len(kept) == len(CHANGES) else None,
                       "falls": len(CHANGES) - len(kept),
                       "holds": len(kept) == len(CHANGES) and min(kept) >= HOLD_SAVING})
    means = [t["mean_saving"] for t in trials if t["mean_saving"] is not None]
    return {
        "changes": list(CHANGES),
        "hold_saving": HOLD_SAVING,
        "time_step_s": time_step_s,
        "speed_mps": speed_mps,
        "no_window": {change: rows[change]["no_window"] for change in CHANGES},
        "trials": trials,
        "mean_saving": float(np.mean(means)) if means else None,
        "std_saving": float(np.std(means)) if means else None,
        "saving_trials": len(means),
        "holding": sum(t["holds"] for t in trials),
    }


def saving_spread(record: dict[str, Any]) -> str:
    """The spread of the mean saving over the trials that have one: "± 1.2 %", or "(1 trial)"."""
    count = record.get("saving_trials")
    if count is None:  # a record before the count was kept: its trials tell, else its spread prints as kept
        count = sum(t["mean_saving"] is not None for t in record["trials"]) if "trials" in record else 2
    return spread_text(record["std_saving"], count, lambda sd: f"{100 * sd:.1f} %")


def _change(saving: float | None) -> str:
    """A saving as the C_mt change it is ("-45.0 %"), or "falls"."""
    return "falls" if saving is None else cmt_change(saving)


def markdown(record: dict[str, Any]) -> str:
    """The re-walks as a table: each trial's saving (C_mt change against no window) under each change."""
    words = [CHANGE_WORDS[c] for c in record["changes"]]
    clock = record.get("controller_clock")
    clock = ("" if clock is None else "; the controller at every plant step, halved with it" if clock == "plant step"
             else f"; the controller a fixed-rate loop of {1e3 * record['update_period_s']:g} ms, kept")
    lines = [f"Each learned window re-walked: {', '.join(words)}; each against the walk without a window "
             f"under the same change (plant step {1e3 * record['time_step_s']:g} ms{clock}, initiation "
             f"{record['speed_mps']:g} m/s"
             + (f"; {measure_text(record['distance_m'])}" if record.get("distance_m") else "")
             + f"). A trial holds when it saves ≥ {100 * record['hold_saving']:.0f} % in every walk.", "",
             "C_mt change against no window (−: C_mt fell, a saving).", "",
             "| trial | window | " + " | ".join(words) + " | mean | holds |",
             "|---|---|" + "---:|" * len(words) + "---:|---|"]
    base = " | ".join(f"C_mt {format_cost(measured_cost(r))}" if not r["fell"] and measured_cost(r) else "falls"
                      for r in record["no_window"].values())
    lines.append(f"| no window | — | {base} | | |")
    for t in record["trials"]:
        cells = " | ".join(_change(t["savings"][c]) for c in record["changes"])
        window = window_text(t["t1"], t["t2"])
        as_learned, plain = t["walks"].get("as_learned"), record["no_window"].get("as_learned")
        if as_learned and plain and not window_acted({**as_learned, "t1": t["t1"], "t2": t["t2"]}, plain):
            window += " (never opens: the walk is the one without a window)" if "–" in window else ""
        lines.append(f"| {t['trial']} | {window} | {cells} | "
                     f"{_change(t['mean_saving'])} | "
                     f"{'yes' if t['holds'] else 'no'} |")
    lines += ["", headline(record)]
    return "\n".join(lines) + "\n"


def headline(record: dict[str, Any]) -> str:
    """One sentence: the mean saving over trials with its spread, and how many trials hold."""
    n = len(record["trials"])
    if record["mean_saving"] is None:
        return f"No trial's window walks under any change ({n} trials)."
    return (f"C_mt change with the learned windows, re-walked: {cmt_change(record['mean_saving'])} "
            f"({saving_spread(record).strip('()')}, mean over trials of each trial's mean over its "
            f"{len(record['changes'])} walks); {record['holding']} of {n} trials save ≥ "
            f"{100 * record['hold_saving']:.0f} % in every walk.")
