"""Learners side by side against the known optimum: pure functions of learning records and a window map.

The ground truth is the window map's best walking window (lowest C_mt among the windows that walk). For a
learning run (a learning.json record) and that window:
- final C_mt: the mean over trials of the evaluated final policy means that walk, and its reduction against
  no window;
- re-walked saving: the mean over trials of each final mean's saving re-walked with the plant step halved and
  from 0.95 and 1.05 x the initiation speed, its spread and the trials that hold (`drake_biped.analysis.rewalks`);
- distance: of each trial's final mean to the best window (s), its mean;
- episodes to within 5 %: the first episode at which the trial's running C_mt (the mean over the last
  RUNNING episodes that walked) is within 5 % of the best window's; None where it never is;
- falls: episodes that fell, summed over trials.

Named for the `compare-learners` command (drake_biped/experiments/compare_learners.py) by design: that runs the
learners, this reduces their records and writes compare.md (`markdown`).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from drake_biped.analysis.cost_of_transport import format_cost
from drake_biped.analysis.rewalks import saving_spread
from drake_biped.analysis.series import cmt_change

__all__ = ["RUNNING", "best_walking_window", "compare", "episodes_to_within", "markdown", "running_cost"]

RUNNING = 20


def best_walking_window(window_map: dict[str, Any]) -> dict[str, Any]:
    """The row of a window_map.json record with the lowest C_mt among the windows that walk."""
    rows = [r for r in window_map["windows"] if r["walked"] and r["cost_of_transport"]]
    if not rows:
        raise ValueError("no window of the map walks: there is no best window to compare with")
    return min(rows, key=lambda r: r["cost_of_transport"])


def running_cost(episodes: list[dict[str, Any]], length: int = RUNNING) -> np.ndarray:
    """Per episode, the mean C_mt of the last `length` episodes that walked (NaN before the first)."""
    out = np.full(len(episodes), math.nan)
    recent: list[float] = []
    for i, e in enumerate(episodes):
        if not e["fell"] and e["cost_of_transport"]:
            recent = (recent + [e["cost_of_transport"]])[-length:]
        if recent:
            out[i] = float(np.mean(recent))
    return out


def episodes_to_within(episodes: list[dict[str, Any]], target: float, tolerance: float = 0.05,
                       length: int = RUNNING) -> int | None:
    """The first episode (1-based) whose running C_mt is within `tolerance` of `target`, else None."""
    running = running_cost(episodes, length)
    hits = np.flatnonzero(running <= target * (1.0 + tolerance))
    return int(hits[0]) + 1 if len(hits) else None


def compare(record: dict[str, Any], best: dict[str, Any] | None, tolerance: float = 0.05) -> dict[str, Any]:
    """One learner's row (module docstring) from its learning record and the best window's map row (None
    when no window of the map walks: then there is no distance and no episode count to report)."""
    ev = record["evaluation"]
    rewalks = ev.get("rewalks") or {}
    means = np.array([t["final_mean"] for t in record["trials"]], dtype=float)
    if best is None:
        distance = np.full(len(means), math.nan)
        reach = [None] * len(means)
    else:
        target = float(best["cost_of_transport"])
        distance = np.linalg.norm(means - np.array([best["t1"], best["t2"]]), axis=1)
        reach = [episodes_to_within(t["episodes"], target, tolerance) for t in record["trials"]]
    return {
        "final_cost_of_transport": ev.get("learned_mean_cost_of_transport"),
        "reduction": ev.get("reduction"),
        "learned_walks": ev.get("learned_walks"),
        "rewalked_saving": rewalks.get("mean_saving"),
        "rewalked_saving_std": rewalks.get("std_saving"),
        "rewalked_spread": saving_spread(rewalks) if rewalks.get("mean_saving") is not None else None,
        "rewalked_holding": rewalks.get("holding"),
        "trials": len(record["trials"]),
        "mean_distance_to_best_s": None if best is None else float(np.mean(distance)),
        "distance_to_best_s": None if best is None else distance.tolist(),
        "episodes_to_within": reach,
        "reached": sum(r is not None for r in reach),
        "falls": int(sum(e["fell"] for t in record["trials"] for e in t["episodes"])),
        "episodes": int(sum(len(t["episodes"]) for t in record["trials"])),
    }


def _cell(value, fmt: str) -> str:
    return "—" if value is None else format(value, fmt)


def _rewalked(row: dict[str, Any]) -> str:
    """The learner's re-walked C_mt change with its spread and the trials holding (`rewalks`)."""
    if row.get("rewalked_saving") is None:
        return "—"
    spread = row.get("rewalked_spread") or f"± {100 * row['rewalked_saving_std']:.1f} %"
    return f"{cmt_change(row['rewalked_saving'])} {spread} ({row['rewalked_holding']}/{row['trials']})"


def _wall(row: dict[str, Any]) -> str:
    if row.get("replayed_from"):
        return f"replayed from {Path(row['replayed_from']).name}/"  # the folder's name: the record keeps its path
    return f"{row['wall_s'] / 60:.1f}"


def markdown(record: dict[str, Any]) -> str:
    best = record["best_window"]
    s = record["settings"]
    head = ("No window of the map walks" if best is None else
            f"Best walking window of the map: ({best['t1']:g}, {best['t2']:g}) s, C_mt {format_cost(best['cost_of_transport'])}")
    lines = [f"{head} (no window {format_cost(record['no_window_cost_of_transport'], '—')}); {s['trials']} trials × "
             f"{s['episodes']} episodes from ({s['mean'][0]:g}, {s['mean'][1]:g}), variance {s['variance']:g} s².", "",
             "C_mt change against no window (−: C_mt fell, a saving); a trial holds when it saves ≥ 35 % in "
             "every re-walk.", "",
             "| learner | final C_mt | C_mt change | re-walked C_mt change (trials holding) | final means that "
             "walk | distance to best (s) | trials within 5 % (episode) | falls | wall (min) |",
             "|---|---:|---:|---:|---:|---:|---|---:|---:|"]
    for name, r in record["learners"].items():
        reach = ", ".join("—" if e is None else str(e) for e in r["episodes_to_within"])
        lines.append(f"| {name} | {format_cost(r['final_cost_of_transport'], '—')} | "
                     f"{cmt_change(r['reduction'])} | "
                     f"{_rewalked(r)} | {r['learned_walks']}/{r['trials']} | {_cell(r['mean_distance_to_best_s'], '.3f')} | "
                     f"{r['reached']}/{r['trials']} ({reach}) | {r['falls']}/{r['episodes']} | {_wall(r)} |")
    return "\n".join(lines) + "\n"
