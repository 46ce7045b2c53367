"""Reproduce the paper in one command: every experiment, then one report beside the paper's numbers.

`drake-biped reproduce --out DIR [--quick]` runs, each into its own folder of DIR and through the same
functions as its own command:

    walk/            the story's gait, 10 m: record, figures, Meshcat HTML and GIF
    grid/            Table IV's grid (CPG ranges and the initiation), level ground; and Table III itself
    paper_gait/      the shipped gait `paper`: Table III with the hip as the paper drives it (ODE's motor)
    window_map/      the gait's torque-free windows against none
    learn/           Experiment 1 with the paper's settings (Table V, Figs. 4-6)
    learn_variant/   the same with exploration matched to the gait (the story's start; variance 0.01)
    energy/          where the energy goes with the learned window, and on the other shipped gait without and
                     with its own window (the walk's audit is walk/energy.json)
    time_step/       the time-step study: no window, the learned window and the story's second window
    stability/       pushes and return maps, none vs the learned window (Table VI, Fig. 7)
    push_margin/     the largest pushes survived, none vs the learned window
    floquet/         the periodic orbit's Floquet multipliers: none and the learned window
    grid_slope2deg/  the CPG and the torso's lean raised on 2.0 deg (our Table VII)
    slope/, slope2deg/  the slope story (Figs. 8-11) from the learned window: 0.02 rad, and 2.0 deg with the
                     grid's best
    compare_learners/  GARB, CMA-ES and PGPE side by side against the window map's best window

All of it on one gait, the paper's walker `paper` (the default) or `--gait fast_servo`, our own faster gait (STORIES: the choices each
gait's story makes beyond the paper's printed settings): "the learned window" is the best trial of `learn` (of
`learn_variant` when the paper's settings learned none; the window map's cheapest when neither did). The other
shipped gaits are named in the report's closing section, with why each exists. Then DIR/report.md and
DIR/report.html: every table and figure with the paper's value beside ours and a verdict for each. `--quick`
runs every experiment on small settings (minutes on 2 cores); the full run takes hours and says so up front.

Nothing lost: each experiment keeps its finished work as its own command does (episodes, trials, grid
points), and once done its summary in DIR/<name>/summary.json with the settings that made it; a rerun
reuses every finished experiment and resumes the unfinished one.
"""

from __future__ import annotations

import argparse
import dataclasses
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from drake_biped.analysis.basins_report import reading as basins_reading
from drake_biped.analysis.long_run import has_long_run
from drake_biped.common.options import (
    add_resumable_run_options,
    cluster,
)
from drake_biped.experiments.reproduce_plan import (
    DEFAULT_STORY,
    FULL,
    QUICK,
    STEPS,
    STORIES,
    Profile,
    Story,
    steps_of,
    story_of,
)
from drake_biped.legacy import config_of_record
from drake_biped.paper import SLOPE_RAD
from drake_biped.params import (
    PAPER_CPG,
    EpisodeConfig,
    Ground,
    InitialConditions,
    ParameterError,
    TorqueFreeWindow,
    check_settings,
)
from drake_biped.records import read_json, read_kept, write_atomic
from drake_biped.resources import gait_compare_window, load_gait
from drake_biped.versions import versions

__all__ = ["DEFAULT_STORY", "FULL", "QUICK", "STORIES", "Profile", "ReproduceSettings", "Reproduction", "Story",
           "check_out", "run", "steps_of", "story_of"]

SLOPE_2DEG_RAD_PRINTED = 0.0349  # 2.0 deg to 4 digits, as the slope runs record it
# The 2.0 deg grid's changes to the story's gait: Table VII's CPG parameters raised (the paper: +25 to +51 %)
# and the torso leaned further forward (rad), with a larger placement gain.
SLOPE_2DEG_CPG_SCALE = 1.25
SLOPE_2DEG_LEANS = (0.0, 0.04, 0.08, 0.12)
SLOPE_2DEG_PLACEMENT = 0.1


class Reproduction:
    """The output folder, the profile, the Dask client; runs each experiment once. `workers`/`scheduler`:
    what the run logs record of the cluster."""

    def __init__(self, out: Path, profile: Profile, client, workers: int | None = None,
                 scheduler: str | None = None, log: Callable[[str], None] = print, gait: str = DEFAULT_STORY):
        self.out, self.profile, self._client = out, profile, client
        self.workers, self.scheduler, self.log = workers, scheduler, log
        self.story = story_of(gait)

    @property
    def _gait_title(self) -> str:
        """The gait as the time-step study's table names it (its own command's words)."""
        return f"Gait {self.story.gait}"

    @property
    def base(self) -> EpisodeConfig:
        """The story's gait as shipped (its own plant step and distance)."""
        return load_gait(self.story.gait)

    def _walking_the_distance(self, base: EpisodeConfig) -> EpisodeConfig:
        return base.replace(sim=dataclasses.replace(base.sim, distance_m=self.profile.distance_m,
                                                    max_time_s=max(base.sim.max_time_s, 6 * self.profile.distance_m)))

    @property
    def level(self) -> EpisodeConfig:
        """The story's gait on level ground, walking the profile's distance."""
        return self._walking_the_distance(self.base)

    def learned_window(self) -> tuple[tuple[float, float], str, Path | None]:
        """The story gait's learned torque-free period (t1, t2), where it came from, and the learning record
        it came from: the best learned trial of `learn` (the paper's settings), else of `learn_variant`; else the
        window map's cheapest, else the window the gait's file declares (no record)."""
        from drake_biped.common.learning_record import best_learned_trial

        for source in ("learn", "learn_variant"):
            path = self.out / source / "learning.json"
            try:
                row = best_learned_trial(read_json(path, "reproduce"), source)
            except (OSError, ValueError):
                continue
            window = (round(max(0.0, float(row["t1"])), 4), round(float(row["t2"]), 4))
            return window, f"learned ({source}, trial {row['trial']})", path
        best = self.summary("window_map").get("best")
        if best is not None:
            return (round(best["t1"], 4), round(best["t2"], 4)), "the window map's cheapest (no trial learned one)", \
                None
        declared = gait_compare_window(self.story.gait)
        if declared is None:
            raise ParameterError(f"reproduce: no trial learned a window on {self.story.gait!r}, no window of its map "
                                 "walks, and its gait file declares none (compare_window): nothing to compare")
        return declared[0], f"no trial learned one and no window of the map walks: {declared[1]}", None

    def summary(self, step: str) -> dict[str, Any]:
        """A finished step's summary in this folder; empty when it has none."""
        saved = read_kept(self.out / step / "summary.json")
        return saved if isinstance(saved, dict) else {}

    def client(self):
        """The reproduction's one client, as a context (it is closed by whoever opened it)."""
        from drake_biped.common.executor import client_or_local

        return client_or_local(self._client)

    def experiment(self, name: str, settings: dict[str, Any], fn: Callable[[Path], dict[str, Any]]) -> dict:
        """fn(folder) -> summary, with the code that measured it, unless DIR/name/summary.json holds one made with
        these settings: that one is returned marked "reused"."""
        folder = self.out / name
        path = folder / "summary.json"
        saved = read_kept(path)
        if isinstance(saved, dict):
            if _as_walked(saved.get("settings")) == _as_walked(settings):
                self.log(f"[{name}] finished earlier: reused")
                return {**saved, "reused": True}  # the report says it was not measured by this run
        self.log(f"[{name}] running")
        t0 = time.perf_counter()
        folder.mkdir(parents=True, exist_ok=True)
        summary = {"settings": settings, **fn(folder)}
        summary["wall_s"] = time.perf_counter() - t0
        summary["measured_by"] = {k: versions().get(k) for k in ("drake_biped", "git_commit", "drake")}
        write_atomic(path, summary)
        self.log(f"[{name}] done in {summary['wall_s']:.0f} s")
        return summary

    # The experiments, in the order they run. Each returns its summary (what the report needs).

    def walk(self) -> dict:
        from drake_biped.experiments import walk

        def run(folder: Path) -> dict:
            r = walk.run(walk.WalkSettings(self.level), folder, progress=False)
            return {"distance_m": r.distance_m, "fell": r.fell, "cost_of_transport": r.cost_of_transport,
                    "mean_speed_mps": r.mean_speed_mps, "step_period_s": r.step_period_s,
                    "real_time_factor": r.real_time_factor, "energy": read_kept(folder / "energy.json")}

        return self.experiment("walk", {"distance_m": self.profile.distance_m}, run)

    def paper_gait(self) -> dict:
        from drake_biped.experiments import walk

        config = load_gait("paper")
        config = config.replace(sim=dataclasses.replace(config.sim, distance_m=self.profile.distance_m))

        def run(folder: Path) -> dict:
            r = walk.run(walk.WalkSettings(config, animation=False), folder, progress=False)
            return {"distance_m": r.distance_m, "fell": r.fell, "fall_reason": r.fall_reason, "steps": len(r.steps),
                    "cost_of_transport": r.cost_of_transport, "cpg": config.cpg.to_dict(),
                    "initial": config.initial.to_dict(), "gait": config.gait.to_dict(),
                    "time_step_s": config.sim.time_step_s}

        return self.experiment("paper_gait", {"config": config.to_dict()}, run)

    def table_iii(self) -> dict:
        """Table III's CPG with the story gait's other gains, from the paper's initiation (the grid runs it
        too; the quick run runs it alone)."""
        from drake_biped.common.executor import run_kept

        config = self.level.replace(cpg=PAPER_CPG, initial=InitialConditions())

        def run(folder: Path) -> dict:
            with self.client() as client:
                r = run_kept(client, {"t": (folder / "table_iii.json", config.to_dict())})["t"]
            return {"distance_m": r["distance_m"], "fell": r["fell"], "steps": len(r["steps"])}

        return self.experiment("table_iii", {"config": config.to_dict()}, run)

    def full_run(self) -> dict:
        """The shipped full run's learned windows (and no window) walked again, each against the C_mt the
        full run recorded (resources.full_run_digest)."""
        from drake_biped.common.executor import run_kept
        from drake_biped.common.walks import window_of
        from drake_biped.resources import full_run_digest
        from drake_biped.versions import compare_with_record

        digest = full_run_digest()

        def run(folder: Path) -> dict:
            jobs, wanted = {}, {}
            for key, check in digest["checks"].items():
                base = config_of_record(check["config"])
                rows = [(0.0, 0.0, check["no_window"])] + [(r["t1"], r["t2"], r["cost_of_transport"])
                                                           for r in check["learned"]]
                for t1, t2, recorded in rows:  # trials that ended on the same window are one walk
                    window = window_of((t1, t2))
                    name = f"{key}_{window.start_s:.6f}_{window.end_s:.6f}" if window.end_s > window.start_s \
                        else f"{key}_none"
                    if name not in jobs:
                        jobs[name] = (folder / f"{name}.json", base.replace(window=window).to_dict())
                        wanted.setdefault(key, []).append((name, t1, t2, recorded))
            with self.client() as client:
                results = run_kept(client, jobs)
            checks = {}
            for key, rows in wanted.items():
                out, rules = [], set()
                for name, t1, t2, recorded in rows:
                    measured = results[name]["cost_of_transport"]
                    diff = (None if recorded is None or measured is None else measured / recorded - 1.0)
                    # to the last digit on the record's machine, within a stated tolerance elsewhere
                    if recorded is None or measured is None:
                        agrees = recorded is None and measured is None
                    else:
                        comparison = compare_with_record(recorded, measured, digest["checks"][key].get("versions"))
                        agrees = comparison.agrees
                        rules.add("last digit" if comparison.exact else f"relative {comparison.rtol:g}")
                    out.append({"t1": t1, "t2": t2, "recorded": recorded, "measured": measured,
                                "relative_difference": diff, "agrees": agrees})
                diffs = [abs(r["relative_difference"]) for r in out if r["relative_difference"] is not None]
                checks[key] = {"source": digest["checks"][key]["source"], "walks": len(out),
                               "agree": sum(r["agrees"] for r in out),
                               "same_digits": sum(r["recorded"] == r["measured"] for r in out),
                               "rule": " and ".join(sorted(rules)) or "last digit",
                               "max_relative_difference": max(diffs, default=None), "rows": out}
            return {"checks": checks, "full_run_code": digest["code"]}

        return self.experiment("full_run", {"checks": digest["checks"]}, run)

    def compare_learners(self) -> dict:
        from drake_biped.experiments import compare_learners

        trials, episodes = self.profile.compare
        # GARB with the paper's settings is `learn`'s run: its first episodes are replayed, not walked again.
        settings = compare_learners.CompareSettings(self.level, str(self.out / "window_map"), trials=trials,
                                                    episodes=episodes, reuse={"garb": str(self.out / "learn")})

        def run(folder: Path) -> dict:
            record = compare_learners.run(settings, folder, self._client, progress=False)
            return {k: record[k] for k in ("best_window", "no_window_cost_of_transport", "learners")}

        return self.experiment("compare_learners", {"learners": list(settings.learners), "trials": trials,
                                                    "episodes": episodes, "distance_m": self.profile.distance_m},
                               run)

    def time_step(self) -> dict:
        from drake_biped.experiments import time_step

        p = self.profile
        window, source, _ = self.learned_window()
        windows = (window, self.story.study_window)
        settings = {"steps": list(p.time_steps), "distance_m": p.time_step_distance_m,
                    "windows": [list(w) for w in windows], "learned_window_source": source}

        def run(folder: Path) -> dict:
            # walks too short for a long-run mean (a small profile) compare the whole walk's C_mt, and say so
            measure = "long-run" if has_long_run(p.time_step_distance_m) else "episode"
            rec = time_step.run(time_step.TimeStepSettings(tuple(p.time_steps), min(p.time_steps),
                                                           p.time_step_distance_m, config=self.base,
                                                           gait=self._gait_title, windows=windows, measure=measure),
                                folder, self._client, progress=False)
            return {"chosen_step_s": rec["chosen_step_s"], "passing_steps": rec["passing_steps"]}

        return self.experiment("time_step", settings, run)

    def grid(self) -> dict:
        from drake_biped.common.executor import run_kept
        from drake_biped.experiments import grid

        p = self.profile
        settings = {"points": p.grid_points, "initiation_points": p.grid_initiation_points,
                    "distance_m": p.distance_m}

        def run(folder: Path) -> dict:
            axes = grid.table_iv_axes(p.grid_points, p.grid_initiation_points)
            table_iii = self.level.replace(cpg=PAPER_CPG, initial=InitialConditions())
            record = grid.run(grid.GridSettings(self.level, tuple(axes)), folder, self._client, progress=False,
                              workers=self.workers, scheduler=self.scheduler)
            with self.client() as client:
                paper = run_kept(client, {"t": (folder / "table_iii.json", table_iii.to_dict())})["t"]
            return {"points": record["points"], "walked": record["walked_the_distance"], "best": record["best"],
                    "table_iii": {"distance_m": paper["distance_m"], "fell": paper["fell"],
                                  "steps": len(paper["steps"])}}

        return self.experiment("grid", settings, run)

    def window_map(self) -> dict:
        from drake_biped.experiments import window_map

        step = self.profile.window_step_s

        def run(folder: Path) -> dict:
            rec = window_map.run(window_map.WindowMapSettings(self.level, t1_step_s=step, t2_step_s=step), folder,
                                 self._client, progress=False)
            return {"no_window_cost_of_transport": rec["baseline"]["cost_of_transport"], **_map_summary(rec)}

        return self.experiment("window_map", {"step_s": step, "distance_m": self.profile.distance_m}, run)

    def _learn(self, name: str, trials: int, episodes: int, mean, variance: float,
               config: EpisodeConfig | None = None) -> dict:
        from drake_biped.common import learning_runs

        settings = learning_runs.LearningSettings(config or self.level, trials, episodes, 0, mean=mean,
                                             variance=variance).record()
        distance = self.profile.rewalk_distance_m

        def run(folder: Path) -> dict:
            record = learning_runs.run(settings, folder, self._client, workers=self.workers, scheduler=self.scheduler,
                                  rewalk_distance_m=distance)
            ev = record["evaluation"]
            run_log = read_json(folder / "run.json", "reproduce")
            return {"evaluation": ev, "episodes_per_min": run_log["episodes_per_min"]}

        kept = {k: settings[k] for k in ("trials", "episodes", "learner", "config")}
        if distance != 10.0:  # the re-walks' length decides the evaluation (10 m: as before they were long)
            kept["rewalk_distance_m"] = distance
        return self.experiment(name, kept, run)

    def learn(self) -> dict:
        trials, episodes = self.profile.learn
        return self._learn("learn", trials, episodes, (0.5, 0.5), 0.04)

    def learn_variant(self) -> dict:
        trials, episodes = self.profile.learn_variant
        return self._learn("learn_variant", trials, episodes, self.story.variant_start, self.story.variant_variance)

    def energy(self) -> dict:
        """Where the energy goes with the story's window, and on the other shipped gait without and with its own
        window (the walk step audits the story walker without one): each walk recorded over the profile's
        distance, its audit in energy/NAME/ (energy.json, energy.png; the initiation left out)."""
        from drake_biped.analysis.series import window_text
        from drake_biped.common.walks import window_of
        from drake_biped.episode import run_episode
        from drake_biped.experiments.walk import write_energy

        window, source, _ = self.learned_window()
        other = "fast_servo" if self.story.gait == "paper" else "paper"
        other_window = gait_compare_window(other)[0]
        mine = self.level
        theirs = self._walking_the_distance(load_gait(other))
        walks = {"window": (mine.replace(window=window_of(window)),
                            f"{self.story.gait}, window {window_text(*window, 4)} (the story's window)"),
                 other: (theirs, f"{other}, no window"),
                 f"{other}_window": (theirs.replace(window=window_of(other_window)),
                                     f"{other}, window {window_text(*other_window, 4)} (its file's comparison window)")}

        def run(folder: Path) -> dict:
            rows = {}
            for name, (config, label) in walks.items():
                r = run_episode(config, record_trajectory=True)
                (folder / name).mkdir(exist_ok=True)
                rows[name] = {"label": label, "cost_of_transport": r.cost_of_transport, "fell": r.fell,
                              "distance_m": r.distance_m,
                              "energy": write_energy(r.trajectory, folder / name, label)}
            return {"gait": self.story.gait, "distance_m": self.profile.distance_m, "window_source": source,
                    "walks": rows}

        return self.experiment("energy", {name: c.to_dict() for name, (c, _) in walks.items()}, run)

    def stability(self) -> dict:
        from drake_biped.experiments import stability

        p = self.profile
        window, source, _ = self.learned_window()
        settings = stability.StabilitySettings(window=window, trials=p.stability_trials, config=self.level,
                                               jacobian_kicks=stability.JACOBIAN_KICKS_RAD if p.jacobian else ())

        def run(folder: Path) -> dict:
            record = stability.run(settings, folder, self._client, progress=False)
            return {"cells": _cells(record), "window_source": source}

        return self.experiment("stability", {**settings.to_dict(), "jacobian": p.jacobian,
                                             "distance_m": p.distance_m}, run)

    def push_margin(self) -> dict:
        from drake_biped.experiments import push_margin

        step = self.profile.margin_force_step_n
        window, source, _ = self.learned_window()
        config = self.level.override({"sim.distance_m": 12.0, "sim.max_time_s": 72.0})

        def run(folder: Path) -> dict:
            record = push_margin.run(push_margin.PushMarginSettings(config, window, 100.0, step), folder,
                                     self._client, progress=False)
            return {"margins": _margins(record), "window_source": source,
                    "method": {k: record[k] for k in ("phases", "settle_s", "max_force_n", "push_duration_s")}}

        return self.experiment("push_margin", {"force_step_n": step, "window": list(window),
                                               "distance_m": 12.0}, run)

    def floquet(self) -> dict:
        from drake_biped.common import floquet_runs as floquet

        windows = {"none": (0.0, 0.0)}
        if "learned" in self.profile.floquet_gaits:
            window, source, _ = self.learned_window()
            if source.startswith("learned"):
                windows["learned"] = window

        def run(folder: Path) -> dict:
            out = {}
            for name, (t1, t2) in windows.items():
                config = self.level.replace(window=TorqueFreeWindow(t1, t2))
                eps = {"epsilons": tuple(self.profile.floquet_epsilons)} if self.profile.floquet_epsilons else {}
                settings = floquet.FloquetSettings(config, newton_iterations=self.profile.floquet_newton_iterations,
                                                   **eps)
                record = floquet.run(settings, folder / name, self._client)
                out[name] = {"window": [t1, t2], **{k: record[k] for k in (
                    "spectral_radius", "converged_epsilon", "fixed_point_residual", "multipliers", "plateau",
                    "sampling_phase_drift")}, "newton_tolerance": record["settings"]["newton_tolerance"],
                    "evaluation_noise": record.get("evaluation_noise"),
                    "decay": {k: record["decay"][k] for k in ("predicted", "map_iterated", "continued")},
                    "wall_time_s": record["wall_time_s"]}
            return {"gaits": out}

        return self.experiment("floquet", {"windows": {k: list(v) for k, v in windows.items()},
                                           "distance_m": self.profile.distance_m}, run)

    def dynamics(self) -> dict:
        """The gait as a dynamical system (`bifurcation`, `basins`): what the walk settles on without a window
        and with the learned one (110 m); a bifurcation over t1 (the learned t2 kept, 60 m walks); the steepest
        slope climbed for 30 m after 2 m level without and with the learned window, and the paper's slope
        premise between them; the Table III walker under the entrained reading (`paper_entrained`) at the shipped
        step and half of it; and a slice of starts, without and with the learned window."""
        from drake_biped.experiments import basins, bifurcation

        n_t1, n_slopes, n_starts = self.profile.dynamics
        long_m, sweep_m, slope_m, basin_m = self.profile.dynamics_walks_m
        window, source, _ = self.learned_window()
        learned = TorqueFreeWindow(*window)
        settings = {"window": list(window), "dynamics": [n_t1, n_slopes, n_starts],
                    "walks_m": [long_m, sweep_m, slope_m, basin_m]}

        def sweep(folder: Path, config: EpisodeConfig, param: str, values, distance: float, **kw) -> dict:
            config = config.override({"sim.distance_m": distance, "sim.max_time_s": 6.0 * distance})
            kw.setdefault("transient_m", min(bifurcation.TRANSIENT_M, 0.4 * distance))
            return bifurcation.run(bifurcation.BifurcationSettings(config, param, tuple(values), **kw), folder,
                                   self._client, progress=False)

        def run(folder: Path) -> dict:
            import numpy as np

            level = self.base.replace(window=learned)
            walks = sweep(folder / "learned", level, "t2", (0.0, window[1]), long_m)  # t2 0: no window
            t1 = sweep(folder / "t1", level, "t1", self.story.t1_values(window, n_t1), sweep_m)
            up = self.base.replace(ground=Ground(slope_rad=0.0, level_length_m=2.0))
            slopes = np.round(np.linspace(0.005, 0.005 * n_slopes, n_slopes), 4)
            slope = {name: sweep(folder / f"slope_{name}", up.replace(window=w), "slope", slopes, slope_m,
                                 transient_m=2.0, lyapunov=False)
                     for name, w in (("without", TorqueFreeWindow()), ("with", learned))}
            entrained = load_gait("paper_entrained")
            paper = sweep(folder / "paper_entrained", entrained, "speed", (entrained.initial.speed_mps,), sweep_m,
                          second_time_step_s=0.5 * entrained.sim.time_step_s)
            slice_ = basins.run(basins.BasinSettings(
                self.base.override({"sim.distance_m": basin_m, "sim.max_time_s": 6.0 * basin_m}), window,
                tuple(np.round(np.linspace(0.10, 0.16, n_starts), 4)),
                tuple(np.round(np.linspace(0.14, 0.21, n_starts), 4)),
                transient_m=min(bifurcation.TRANSIENT_M, 0.4 * basin_m)), folder / "basins", self._client,
                progress=False)

            def brief(point: dict) -> dict:
                keys = ("value", "time_step_s", "fell", "attractor", "within_jitter", "lyapunov", "cost_of_transport",
                        "interval_95", "spread_s")
                return {k: point.get(k) for k in keys}

            return {"window_source": source, "learned": [brief(p) for p in walks["points"]],
                    "t1": [brief(p) for p in t1["points"]],
                    "slope": {name: {"walked_up_to": r["walked_up_to"], "fell": [p["value"] for p in r["points"]
                                                                                 if p["fell"]]}
                              for name, r in slope.items()},
                    "premise": bifurcation.premise(slope["without"]["points"], slope["with"]["points"]),
                    "paper_entrained": [brief(p) for p in paper["points"]],
                    "basins": {"hip_angles_rad": slice_["hip_angles_rad"], "speeds_mps": slice_["speeds_mps"],
                               **{c: [[basins_reading(cell) for cell in row] for row in g]
                                  for c, g in slice_["grids"].items()}}}

        return self.experiment("dynamics", settings, run)

    def slope_axes(self) -> list:
        """The 2.0 deg grid's axes around the story's gait (SLOPE_2DEG_*): its torso leaned further forward, a
        larger placement gain (where the gait reads one: not under the hip motor), and u_a, u_r, kappa raised as in
        Table VII; or the 2 x 2 corner of lean and u_a."""
        from drake_biped.experiments.grid import Axis

        g, c = self.level.gait, self.level.cpg
        lean = Axis("gait.torso_pitch_rad", tuple(round(g.torso_pitch_rad - d, 4) if d else g.torso_pitch_rad
                                                  for d in SLOPE_2DEG_LEANS))
        raised = [Axis(f"cpg.{k}", (getattr(c, k), round(SLOPE_2DEG_CPG_SCALE * getattr(c, k), 4)))
                  for k in ("u_a", "u_r", "kappa")]
        if not self.profile.slope_grid_full:
            return [Axis(lean.name, (lean.values[0], lean.values[2])), raised[0]]
        axes = [lean, Axis("gait.placement_gain", (g.placement_gain, round(g.placement_gain + SLOPE_2DEG_PLACEMENT, 4))),
                *raised]
        return [a for a in axes if a.name.removeprefix("gait.") not in g.unread()]  # an unread gain walks alike

    def grid_slope2deg(self) -> dict:
        """Table VII: the story gait's grid (slope_axes) on 2 m level then 2.0 deg."""
        from drake_biped.experiments import grid
        from drake_biped.experiments.slope import slope_ground

        axes = self.slope_axes()
        settings = {"axes": {a.name: list(a.values) for a in axes}, "slope_rad": SLOPE_2DEG_RAD_PRINTED}

        def run(folder: Path) -> dict:
            base = self.base.replace(ground=slope_ground(SLOPE_2DEG_RAD_PRINTED))
            record = grid.run(grid.GridSettings(base, tuple(axes)), folder, self._client, progress=False,
                              workers=self.workers, scheduler=self.scheduler)
            return {"points": record["points"], "walked": record["walked_the_distance"], "best": record["best"],
                    "base_cpg": base.cpg.to_dict()}

        return self.experiment("grid_slope2deg", settings, run)

    def _slope(self, name: str, slope: float, point: dict[str, float] | None = None) -> dict:
        """The slope story on the story's gait (with the grid's `point` put in) from the learned window: the
        learner starts from its learning record's state when a trial learned one, else from the window with
        the paper's variance."""
        from drake_biped.experiments import slope as slope_experiment
        from drake_biped.experiments.grid import point_config

        trials, episodes = self.profile.slope
        window, source, policy = self.learned_window()
        config = self.base if not point else point_config(self.base, point)
        settings = {"config": config.to_dict(), "slope_rad": slope, "start": list(window), "start_source": source,
                    "policy": None if policy is None else str(policy.relative_to(self.out)), "variance": 0.04,
                    "trials": trials, "episodes": episodes}

        def run(folder: Path) -> dict:
            record = slope_experiment.run(
                slope_experiment.SlopeSettings(config, slope, policy=None if policy is None else str(policy),
                                               window=window, variance=0.04, trials=trials, episodes=episodes),
                folder, self._client, progress=False, workers=self.workers, scheduler=self.scheduler)
            return {**{k: record[k] for k in ("checks", "verdicts", "trials", "start")}, "start_source": source,
                    "point": point or {}}

        return self.experiment(name, settings, run)

    def slope(self) -> dict:
        return self._slope("slope", SLOPE_RAD)

    def slope2deg(self) -> dict:
        """The slope story on 2.0 deg with the 2.0 deg grid's best point (the gait itself when none climbs)."""
        from drake_biped.analysis.verdicts import climbs_2deg

        grid = self.summary("grid_slope2deg")
        return self._slope("slope2deg", SLOPE_2DEG_RAD_PRINTED, grid["best"]["point"] if climbs_2deg(grid) else None)

    STEPS = STEPS  # each is a method of this class, run in this order

    def run_all(self) -> dict[str, dict]:
        self.out.mkdir(parents=True, exist_ok=True)
        code = versions()
        summaries = {}
        for step in steps_of(self.profile, self.story.gait):
            summaries[step] = getattr(self, step)()
        from drake_biped.analysis.reproduce_report import write_report

        full_run = None
        if self.profile.name == "quick":
            from drake_biped.resources import full_run_digest

            full_run = full_run_digest()
        write_report(self.out, summaries, self.profile, code, full_run, gait=self.story.gait,
                     choices=self.story.why)
        return summaries


def _as_walked(value: Any) -> Any:
    """Settings as they walk: every configuration in them (a mapping with "cpg" and "gait" sections) with its gait's
    unread fields at their defaults (`GaitParams.as_walked`), so that a gait file that drops a value its readings
    never read still reuses the records walked with it."""
    from drake_biped.params import GaitParams

    if isinstance(value, dict):
        out = {k: _as_walked(v) for k, v in value.items()}
        if isinstance(value.get("cpg"), dict) and isinstance(value.get("gait"), dict):
            try:
                out["gait"] = GaitParams.from_dict(value["gait"]).as_walked().to_dict()
            except ValueError:
                pass  # not a gait's section after all: compared as written
        return out
    if isinstance(value, list):
        return [_as_walked(v) for v in value]
    return value


def _map_summary(record: dict) -> dict:
    """A window map's count of windows, of those that walk, and its cheapest walking window."""
    walked = [w for w in record["windows"] if w["walked"]]
    best = min(walked, key=lambda w: w["cost_of_transport"], default=None)
    return {"windows": len(record["windows"]), "walked": len(walked),
            "best": None if best is None else {k: best[k] for k in ("t1", "t2", "cost_of_transport", "cmt_change")}}


def _cells(record: dict) -> dict:
    """What the report needs of a stability record's six cells."""
    keys = ("spectral_radius", "spectral_radius_ci", "eigenvalues", "falls", "trials", "stable",
            "paper_spectral_radius", "paper_eigenvalues")
    return {c: {k: {key: record["cells"][c][k].get(key) for key in keys} for k in ("undisturbed", "forward", "backward")}
            for c in ("without", "with")}


def _margins(record: dict) -> dict:
    """A push-margin record's survived forces, without and with the window, forward and backward."""
    return {c: {d: record["margins"][c].get(d, {}).get("margin_n") for d in ("forward", "backward")}
            | {f"{d}_at_grid_top": record["margins"][c].get(d, {}).get("at_grid_top", False)
               for d in ("forward", "backward")}
            for c in ("without", "with")}


@dataclass(frozen=True)
class ReproduceSettings:
    """Which profile, QUICK (minutes) or FULL (hours), on which gait's story (STORIES)."""

    profile: Profile = QUICK
    gait: str = DEFAULT_STORY

    def __post_init__(self) -> None:
        story_of(self.gait)


def run(settings: ReproduceSettings, out: Path, client=None, progress: bool = True,
        workers: int | None = None, scheduler: str | None = None) -> dict[str, dict]:
    """Every experiment into its folder of `out` on `client` (a LocalCluster when None), then report.md,
    report.html and report_summary.png; reuses finished experiments and resumes the unfinished one. The
    experiments' summaries."""
    check_settings(settings, ReproduceSettings, "reproduce.run")
    from drake_biped.common.executor import client_or_local

    out = Path(out)
    check_out(out, settings.profile, settings.gait)
    with client_or_local(client) as c:
        return Reproduction(out, settings.profile, c, workers, scheduler,
                            log=print if progress else (lambda _: None), gait=settings.gait).run_all()


def check_out(out: Path, profile: Profile, gait: str = DEFAULT_STORY) -> None:
    """Refuse an output folder that holds another profile's run, or a run on another gait (its records would
    be reused for the wrong walker); a folder without a gait recorded holds a run on `fast_servo`, the default
    story when it was made."""
    marker = out / "profile.json"
    kept = read_kept(marker)
    if isinstance(kept, dict):
        saved = kept.get("name")
        if saved != profile.name:
            raise ParameterError(f"--out {out} holds a {saved!r} run; use another folder for a {profile.name!r} run")
        saved_gait = kept.get("gait", "fast_servo")
        if saved_gait != gait:
            raise ParameterError(f"--out {out} holds a run on the {saved_gait!r} gait; use another folder for "
                                 f"--gait {gait}")
    out.mkdir(parents=True, exist_ok=True)
    write_atomic(marker, profile.to_dict() | {"gait": gait})


COMMAND = "reproduce"
# Rerunning the command on the same --out resumes it from its records.
RESUMABLE = True
PARSER = dict(help="every experiment of the paper and one report beside its numbers "
              "(--quick: small settings, minutes)")


def add_arguments(p: argparse.ArgumentParser) -> None:
    """`drake-biped reproduce`'s options."""
    p.add_argument("--quick", action="store_true", help="small settings: the same report in minutes")
    p.add_argument("--params", "--gait", dest="gait", default=DEFAULT_STORY, choices=sorted(STORIES),
                   help="the shipped gait whose story to tell, as --params names it elsewhere (--gait is the same "
                        "option): `paper` (the default: Table III's CPG, the hip as ODE's motor), or `fast_servo` "
                        "(our own faster gait, 0.42 s steps)")
    add_resumable_run_options(p)


def settings_from_args(args: argparse.Namespace) -> ReproduceSettings:
    """The reproduction's settings from the command's options: the quick or the full profile."""
    return ReproduceSettings(QUICK if args.quick else FULL, args.gait)


def command(args: argparse.Namespace) -> int:
    """Run the command of `args` (its options parsed by add_arguments); the exit code."""
    from drake_biped.common.executor import check_cluster_options

    settings = settings_from_args(args)
    profile = settings.profile
    out = Path(args.out)
    check_cluster_options(args.workers, args.scheduler, args.force)  # before the folder is claimed for this profile
    check_out(out, profile, settings.gait)
    minutes = profile.expected_minutes * story_of(settings.gait).cost
    hours = minutes / 60
    print(f"reproduce ({profile.name}, {settings.gait} gait): {len(steps_of(profile, settings.gait))} experiments into {out}/, expected "
          "about " + (f"{minutes:.0f} min" if hours < 1.5 else f"{hours:.1f} h")
          + " on 2 cores; interrupt at any time and rerun the same command to resume", flush=True)
    with cluster(args) as client:
        run(settings, out, client, workers=args.workers, scheduler=args.scheduler)
    print("\n".join(line for line in (out / "report.md").read_text().splitlines()[:40] if line.startswith("|")))
    print(f"wrote {out}/report.md, report.html")
    return 0
