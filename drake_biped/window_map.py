"""Map a grid of torque-free windows (t1, t2) for one gait: which walk the distance, and their C_mt
against the same gait with no window.

Episodes are independent, so they run in a process pool; each worker receives an EpisodeConfig
(numbers only) and builds its own diagram.
"""

from __future__ import annotations

import csv
import json
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

from drake_biped.params import EpisodeConfig, TorqueFreeWindow
from drake_biped.versions import versions


def window_grid(t1_max: float = 0.6, t2_max: float = 0.9, t1_step: float = 0.1, t2_step: float = 0.1,
                min_length: float = 0.1) -> list[tuple[float, float]]:
    """(t1, t2) pairs: t1 from 0 to t1_max, t2 from t1 + min_length to t2_max, rounded to 1e-6 s."""
    out = []
    for t1 in np.arange(0.0, t1_max + 1e-9, t1_step):
        for t2 in np.arange(t1 + min_length, t2_max + 1e-9, t2_step):
            out.append((round(float(t1), 6), round(float(t2), 6)))
    return out


def _evaluate(config: EpisodeConfig) -> dict:
    from drake_biped.episode import run_episode

    r = run_episode(config)
    hip = sum(v for k, v in r.positive_work_j.items() if k.endswith("hip"))
    return {
        "t1": config.window.start_s,
        "t2": config.window.end_s,
        "walked": (not r.fell) and r.distance_m >= config.sim.distance_m - 1e-6,
        "distance_m": r.distance_m,
        "fall_reason": r.fall_reason,
        "cost_of_transport": r.cost_of_transport,
        "positive_work_j": r.total_positive_work_j,
        "hip_positive_work_j": hip,
        "step_period_s": r.step_period_s,
        "step_length_m": r.step_length_m,
        "mean_speed_mps": r.mean_speed_mps,
    }


def evaluate_windows(config: EpisodeConfig, windows: list[tuple[float, float]], workers: int = 2,
                     progress: bool = True) -> tuple[dict, list[dict]]:
    """The no-window baseline and one row per window."""
    configs = [config.replace(window=TorqueFreeWindow(0.0, 0.0))]
    configs += [config.replace(window=TorqueFreeWindow(t1, t2)) for t1, t2 in windows]
    if workers <= 1:
        rows = [_evaluate(c) for c in _bar(configs, progress)]
    else:
        with ProcessPoolExecutor(max_workers=workers) as pool:
            rows = list(_bar(pool.map(_evaluate, configs), progress, total=len(configs)))
    baseline, rows = rows[0], rows[1:]
    for r in rows:
        ok = r["walked"] and baseline["walked"] and r["cost_of_transport"] and baseline["cost_of_transport"]
        r["cmt_change"] = (r["cost_of_transport"] / baseline["cost_of_transport"] - 1.0) if ok else None
    return baseline, rows


def _bar(iterable, enabled: bool, total: int | None = None):
    if not enabled:
        return iterable
    from tqdm import tqdm

    return tqdm(iterable, total=total, desc="windows", unit="episode")


def run_window_map(config: EpisodeConfig, out: Path, t1_step: float = 0.1, t2_step: float = 0.1,
                   workers: int = 2, t1_max: float = 0.6, t2_max: float = 0.9) -> dict:
    """Evaluate the grid, write window_map.json / .csv / .png into `out`, and return the record."""
    from analysis.figures import window_map_figure

    out.mkdir(parents=True, exist_ok=True)
    baseline, rows = evaluate_windows(config, window_grid(t1_max, t2_max, t1_step, t2_step), workers)
    record = {"config": config.to_dict(), "baseline": baseline, "windows": rows, "versions": versions()}
    (out / "window_map.json").write_text(json.dumps(record, indent=2) + "\n")
    with open(out / "window_map.csv", "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        writer.writeheader()
        writer.writerows(rows)
    window_map_figure(rows, baseline["cost_of_transport"] if baseline["walked"] else None, out / "window_map.png")
    walked = [r for r in rows if r["walked"]]
    best = min(walked, key=lambda r: r["cost_of_transport"], default=None)
    print(f"no window: walked={baseline['walked']} C_mt={baseline['cost_of_transport']}")
    print(f"{len(walked)}/{len(rows)} windows walk {config.sim.distance_m:g} m")
    if best is not None:
        print(f"lowest C_mt: window ({best['t1']:g}, {best['t2']:g}) C_mt={best['cost_of_transport']:.3f} "
              f"({100 * (best['cmt_change'] or 0):+.1f}% vs no window)")
    return record
