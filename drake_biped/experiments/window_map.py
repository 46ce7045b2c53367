"""Map a grid of torque-free windows (t1, t2) for one gait: which walk the distance, and their C_mt
against the same gait with no window. Episodes run on Dask (`executor`); each worker receives an
EpisodeConfig (numbers only) and builds its own diagram.

The grid is the gait's own unless given: from its step period T (its walk without a window, the map's
baseline), t1 from 0 to T and t2 up to PAST_TOUCHDOWN x T (a window whose t2 is past the step's end frees the hip
until the swing foot lands, however long the freed swing makes the step), both in steps of T / STEPS_PER_PERIOD.
"""

from __future__ import annotations

import argparse
import csv
import dataclasses
import io
import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from drake_biped.analysis.cost_of_transport import format_cost
from drake_biped.analysis.series import signed_percent
from drake_biped.common.options import (
    add_cluster_options,
    add_episode_options,
    episode_config,
    number,
    out_folder,
    print_lines,
    run_command,
)
from drake_biped.legacy import config_of_record
from drake_biped.params import (
    EpisodeConfig,
    ParameterError,
    TorqueFreeWindow,
    check_settings,
    walked_the_distance,
)
from drake_biped.records import read_kept_lines, write_text_atomic
from drake_biped.versions import versions

# The most windows a map runs without force=True (--force): every one an episode held in memory before the first.
MAX_WINDOWS = 20_000
# The grid a gait's step period T gives (what WindowMapSettings leaves None): t1 up to T, t2 up to this times T,
# steps of T / STEPS_PER_PERIOD.
PAST_TOUCHDOWN, STEPS_PER_PERIOD = 1.5, 10

__all__ = ["MAX_WINDOWS", "WindowMapSettings", "evaluate_windows", "run", "summary_lines", "window_grid"]


@dataclass(frozen=True)
class WindowMapSettings:
    """The gait and the grid: t1 from 0 to t1_max, t2 from t1 + min_length to t2_max, both in steps. A bound or
    step left None is the gait's (`for_step_period`: the module's docstring), known once its walk without a
    window has been walked; min_length None is the t2 step."""

    config: EpisodeConfig = field(default_factory=EpisodeConfig)
    t1_max_s: float | None = None
    t2_max_s: float | None = None
    t1_step_s: float | None = None
    t2_step_s: float | None = None
    min_length_s: float | None = None
    force: bool = False  # run a map over MAX_WINDOWS windows

    @property
    def resolved(self) -> bool:
        """Whether every bound and step is a number (none is left to the gait's step period)."""
        return None not in (self.t1_max_s, self.t2_max_s, self.t1_step_s, self.t2_step_s)

    def for_step_period(self, period_s: float | None) -> WindowMapSettings:
        """These settings with what was left None taken from the step period `period_s` (ParameterError when it
        is needed and the walk without a window made none: a gait that falls in its first steps)."""
        if self.resolved:
            return self
        if period_s is None or not (math.isfinite(period_s) and period_s > 0):
            raise ParameterError(f"window map: the gait's walk without a window gives no step period ({period_s!r}) "
                                 "to place the grid by; give --t1-max, --t2-max and --step")
        step = period_s / STEPS_PER_PERIOD

        def given(value, default):
            return default if value is None else value

        return dataclasses.replace(
            self, t1_max_s=given(self.t1_max_s, round(period_s, 6)),
            t2_max_s=given(self.t2_max_s, round(PAST_TOUCHDOWN * period_s, 6)),
            t1_step_s=given(self.t1_step_s, round(step, 6)), t2_step_s=given(self.t2_step_s, round(step, 6)))

    def __post_init__(self) -> None:
        for name in ("t1_max_s", "t2_max_s", "t1_step_s", "t2_step_s", "min_length_s"):
            value = getattr(self, name)
            if value is not None and not (isinstance(value, (int, float)) and math.isfinite(value) and value >= 0):
                raise ParameterError(f"window map: {name} must be a finite number >= 0 or None, got {value!r}")
        if not self.resolved:
            return
        n = self.window_count()
        if n > MAX_WINDOWS and not self.force:
            raise ParameterError(f"window map: --t1-max {self.t1_max_s:g} --t2-max {self.t2_max_s:g} --step "
                                 f"{self.t1_step_s:g} gives {n:,} windows, more than the limit of {MAX_WINDOWS:,} "
                                 "(each an episode); give a coarser --step, or --force to run it anyway")
        if not self.windows():
            raise ParameterError(f"--t1-max {self.t1_max_s:g} --t2-max {self.t2_max_s:g} --step {self.t1_step_s:g}: "
                                 f"no window fits (t2 runs from t1 + {self.min_length:g} s up to --t2-max)")

    @property
    def min_length(self) -> float:
        """The shortest window: min_length_s, or the t2 step when it is None."""
        return self.t2_step_s if self.min_length_s is None else self.min_length_s

    def window_count(self) -> int:
        """How many windows the grid holds, counted without building it."""
        if not self.resolved:
            raise ParameterError("window map: the grid is placed by the gait's step period; count it once known "
                                 "(WindowMapSettings.for_step_period)")
        if not all(math.isfinite(x) and x > 0 for x in (self.t1_step_s, self.t2_step_s)):
            raise ParameterError(f"window map: the steps must be positive, got {self.t1_step_s!r}, {self.t2_step_s!r}")
        count = 0
        for k in range(int(math.floor(self.t1_max_s / self.t1_step_s + 1e-9)) + 1):
            span = self.t2_max_s - k * self.t1_step_s - self.min_length
            if span >= -1e-9:
                count += int(math.floor(span / self.t2_step_s + 1e-9)) + 1
        return count

    def windows(self) -> list[tuple[float, float]]:
        self.window_count()  # a grid not yet placed is refused there
        return window_grid(self.t1_max_s, self.t2_max_s, self.t1_step_s, self.t2_step_s, self.min_length)


def window_grid(t1_max: float = 0.6, t2_max: float = 0.9, t1_step: float = 0.1, t2_step: float = 0.1,
                min_length: float = 0.1) -> list[tuple[float, float]]:
    """(t1, t2) pairs: t1 from 0 to t1_max, t2 from t1 + min_length to t2_max, rounded to 1e-6 s."""
    out = []
    for t1 in np.arange(0.0, t1_max + 1e-9, t1_step):
        for t2 in np.arange(t1 + min_length, t2_max + 1e-9, t2_step):
            out.append((round(float(t1), 6), round(float(t2), 6)))
    return out


def window_row(config: dict[str, Any]) -> dict[str, Any]:
    """One episode of an EpisodeConfig dictionary, summarised as a row of the map (runs on a worker)."""
    from drake_biped.episode import run_episode

    c = config_of_record(config)
    r = run_episode(c)
    hip = sum(v for k, v in r.positive_work_j.items() if k.endswith("hip"))
    return {
        "t1": c.window.start_s,
        "t2": c.window.end_s,
        "walked": walked_the_distance(r.fell, r.distance_m, c.sim.distance_m),
        "distance_m": r.distance_m,
        "fall_reason": r.fall_reason,
        "cost_of_transport": r.cost_of_transport,
        "positive_work_j": r.total_positive_work_j,
        "hip_positive_work_j": hip,
        "step_period_s": r.step_period_s,
        "step_length_m": r.step_length_m,
        "mean_speed_mps": r.mean_speed_mps,
    }


def evaluate_windows(config: EpisodeConfig, windows: list[tuple[float, float]], client,
                     progress: bool = True, keep: Path | None = None) -> tuple[dict, list[dict]]:
    """The no-window baseline and one row per window, on the Dask `client`. `keep`: a JSON-lines file each
    finished row is appended to as it comes (an interrupted map loses no finished episode) and read back from
    when the same map runs again."""
    from distributed import as_completed

    from drake_biped.common.executor import DrakeGuarded

    configs = [config.replace(window=TorqueFreeWindow(0.0, 0.0))]
    configs += [config.replace(window=TorqueFreeWindow(t1, t2)) for t1, t2 in windows]
    dicts = [c.to_dict() for c in configs]
    rows: list[dict | None] = [None] * len(configs)
    kept = _read_kept_rows(keep)
    for i, c in enumerate(dicts):
        rows[i] = kept.get(json.dumps(c, sort_keys=True))
    todo = [i for i, r in enumerate(rows) if r is None]
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=len(configs), initial=len(configs) - len(todo), desc="windows", unit="episode")
    sink = open(keep, "a") if keep is not None else None
    if sink is not None and sink.tell() > 0 and not Path(keep).read_text().endswith("\n"):
        sink.write("\n")  # a line torn by a kill ends here; the rows after it start on their own line
    try:
        futures = {client.submit(DrakeGuarded(window_row), dicts[i], pure=False): i for i in todo}
        for future in as_completed(list(futures)):
            i = futures[future]
            rows[i] = future.result()
            if sink is not None:
                sink.write(json.dumps({"config": dicts[i], "row": rows[i]}, sort_keys=True) + "\n")
                sink.flush()
            if bar is not None:
                bar.update(1)
    finally:
        if sink is not None:
            sink.close()
        if bar is not None:
            bar.close()
    baseline, rows = rows[0], rows[1:]
    for r in rows:
        ok = r["walked"] and baseline["walked"] and r["cost_of_transport"] and baseline["cost_of_transport"]
        r["cmt_change"] = (r["cost_of_transport"] / baseline["cost_of_transport"] - 1.0) if ok else None
    return baseline, rows


def _read_kept_rows(path: Path | None) -> dict[str, dict]:
    """The rows kept in `path` by configuration (its sorted JSON). A line that does not read (a torn last line
    of a kill mid-write, or damage) sets the file aside as episodes.jsonl.broken with a warning, and its episode
    is run again (records.read_kept_lines)."""
    if path is None:
        return {}
    entries = read_kept_lines(path, "a window-map episode",
                              lambda e: isinstance(e["config"], dict) and isinstance(e["row"], dict))
    return {json.dumps(e["config"], sort_keys=True): e["row"] for e in entries}


def run(settings: WindowMapSettings, out: Path, client=None, progress: bool = True) -> dict[str, Any]:
    """Evaluate the grid on `client` (a LocalCluster when None); write window_map.json, window_map.csv and
    window_map.png into `out`; return the record."""
    check_settings(settings, WindowMapSettings, "window_map.run")
    from drake_biped.analysis.figures import window_map_figure
    from drake_biped.common.executor import client_or_local

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    config = settings.config
    keep = out / "episodes.jsonl"
    with client_or_local(client) as c:
        if not settings.resolved:  # the grid is the gait's: walk it without a window first (kept, not walked twice)
            baseline, _ = evaluate_windows(config, [], c, progress=False, keep=keep)
            settings = settings.for_step_period(baseline["step_period_s"])  # checked as a given grid is
        baseline, rows = evaluate_windows(config, settings.windows(), c, progress, keep=keep)
    grid = {"t1_max_s": settings.t1_max_s, "t2_max_s": settings.t2_max_s, "t1_step_s": settings.t1_step_s,
            "t2_step_s": settings.t2_step_s, "min_length_s": settings.min_length,
            "step_period_s": baseline["step_period_s"]}
    record = {"config": config.to_dict(), "grid": grid, "baseline": baseline, "windows": rows, "versions": versions()}
    write_text_atomic(out / "window_map.json", json.dumps(record, indent=2) + "\n")
    text = io.StringIO(newline="")
    writer = csv.DictWriter(text, fieldnames=list(rows[0].keys()))
    writer.writeheader()
    writer.writerows(rows)
    write_text_atomic(out / "window_map.csv", text.getvalue())
    window_map_figure(rows, baseline["cost_of_transport"] if baseline["walked"] else None, out / "window_map.png")
    return record


def summary_lines(record: dict[str, Any]) -> list[str]:
    """The map in a few lines: the baseline, the grid, how many windows walk, the cheapest."""
    baseline, rows = record["baseline"], record["windows"]
    walked = [r for r in rows if r["walked"]]
    best = min(walked, key=lambda r: r["cost_of_transport"], default=None)
    grid = record.get("grid")
    lines = [f"no window: walked={baseline['walked']} C_mt={format_cost(baseline['cost_of_transport'])}"]
    if grid is not None:
        lines.append(f"grid: t1 0-{grid['t1_max_s']:g} s, t2 up to {grid['t2_max_s']:g} s, steps {grid['t1_step_s']:g} s"
                     + (f" (the step period {grid['step_period_s']:g} s)" if grid.get("step_period_s") else ""))
    lines.append(f"{len(walked)}/{len(rows)} windows walk {record['config']['sim']['distance_m']:g} m")
    if best is not None:
        lines.append(f"lowest C_mt: window ({best['t1']:g}, {best['t2']:g}) C_mt={format_cost(best['cost_of_transport'])} "
                     f"(C_mt change {signed_percent(best['cmt_change'])} vs no window)")
    return lines


COMMAND = "window-map"
PARSER = dict(help="C_mt of a grid of torque-free windows against no window")


def add_arguments(p: argparse.ArgumentParser) -> None:
    """`drake-biped window-map`'s options."""
    add_episode_options(p)
    p.add_argument("--step", type=number("positive"), default=None,
                   help=f"grid spacing of t1 and t2 (s) (default: the gait's step period / {STEPS_PER_PERIOD})")
    p.add_argument("--t1-max", type=number("nonnegative"), default=None,
                   help="largest start t1 (s) (default: the gait's step period, from its walk without a window)")
    p.add_argument("--t2-max", type=number("positive"), default=None,
                   help=f"largest end t2 (s) (default: {PAST_TOUCHDOWN:g} x the gait's step period: windows past "
                        "touchdown, the hip off until the foot lands)")
    add_cluster_options(p)
    p.add_argument("--out", required=True, type=out_folder, help="output folder")


def settings_from_args(args: argparse.Namespace) -> WindowMapSettings:
    """The map's settings from the command's options."""
    return WindowMapSettings(episode_config(args), t1_max_s=args.t1_max, t2_max_s=args.t2_max,
                             t1_step_s=args.step, t2_step_s=args.step, force=args.force)


def command(args: argparse.Namespace) -> int:
    """Run the command of `args` (its options parsed by add_arguments); the exit code."""
    record = run_command(args, settings_from_args, run)
    print_lines(summary_lines(record))
    print(f"wrote {args.out}/window_map.json, window_map.csv, window_map.png")
    return 0
