"""Slope adaptation (the paper's Experiment 3, Figs. 8-11), on Dask.

The ground is level for `level_length_m` (2 m), then ascends at `slope_rad`. An episode *climbs* when it
reaches the episode's distance (10 m: 2 m level, 8 m up) without falling. Three questions, each answered by
episodes on that ground:

1. Does the torque-free period learned on level ground climb? (the starting policy's mean)
2. Does the gait without a torque-free period climb?
3. Online GARB learning on the slope, starting from the learned policy: does it shrink the period until it
   climbs? (`trials` independent runs of `episodes` each; then each final policy mean)

Each answer is walked four times: as learned, with the plant step halved, and from 0.95 and 1.05 x the
initiation speed (`drake_biped.common.walks.rewalk`); a claim holds only when it holds in all four (a walk that
climbs only in one simulation, from one start, does not climb).

The learner starts from the learned policy's state: its mean, variance and eligibility trace. The paper
says "the learning algorithm and α_p were not changed"; here the episode count starts again at 1 on the new
ground, so α_p follows Table II from its first band (carrying the count over would leave α_p at 0.001 after
a 500-episode level run, and the period could not move in tens of episodes), and the baseline becomes the
running mean of the slope's rewards. Reward and fall rule are the level run's (`analysis.reward`).

Nothing lost: the learning runs through `common.learning_runs.run_learning` (each trial's record rewritten after every
episode, resumed on rerun) and the check episodes are kept in OUT/checks/ and reused.
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from drake_biped.analysis.cost_of_transport import format_cost
from drake_biped.analysis.rewalks import CHANGE_WORDS, CHANGES
from drake_biped.analysis.series import moving_average, period
from drake_biped.common.learning_runs import check_policy_spread, make_settings, run_learning, trial_seed
from drake_biped.common.options import (
    add_episode_options,
    add_resumable_run_options,
    add_window_options,
    check_learning_size,
    chosen_window,
    cluster,
    count,
    episode_config,
    number,
)
from drake_biped.common.walks import changed, window_of
from drake_biped.learners.garb import GarbLearner
from drake_biped.paper import GARB_VARIANCE_S2, SLOPE_LEVEL_LENGTH_M, SLOPE_MOVING_AVERAGE, SLOPE_RAD
from drake_biped.params import (
    DEFAULT_WINDOW_S,
    EpisodeConfig,
    Ground,
    ParameterError,
    TorqueFreeWindow,
    check_settings,
    walked_the_distance,
)
from drake_biped.records import write_atomic, write_text_atomic
from drake_biped.versions import versions

MOVING_AVERAGE = SLOPE_MOVING_AVERAGE  # episodes, as in the paper's Figs. 8-11


def slope_ground(slope_rad: float, level_length_m: float = 2.0, friction: float = 1.0) -> Ground:
    if not (math.isfinite(slope_rad) and slope_rad > 0):
        raise ParameterError(f"--slope {slope_rad!r}: must be > 0 (an ascending slope, rad)")
    return Ground(slope_rad=slope_rad, level_length_m=level_length_m, friction=friction)


def check_reaches_slope(config: EpisodeConfig, where: str = "") -> None:
    """ParameterError naming --distance and --level-length when `config`'s walks end on its level stretch, before
    the slope begins: a walk that never reaches the slope cannot be judged as climbing (or as failing to), so
    every climb verdict is refused such settings up front. `where` prefixes the message."""
    g, distance = config.ground, config.sim.distance_m
    if g.level_length_m is not None and g.slope_rad != 0.0 and distance <= g.level_length_m:
        raise ParameterError(f"{where}--distance {distance:g} --level-length {g.level_length_m:g}: every walk ends "
                             f"on the level, before the slope begins at {g.level_length_m:g} m, so none can be "
                             "judged as climbing; give a --distance above --level-length")


def start_from_learning(path: Path) -> tuple[dict[str, Any], dict[str, Any]]:
    """The learner state of a level-ground run's best learned trial (`learning_record.best_learned_trial`), read
    from its record OUT/trials/trial_K.json beside the learning.json; and a description of where it came
    from."""
    from drake_biped.common.learning_record import best_learned_trial
    from drake_biped.records import read_json

    row = best_learned_trial(read_json(path, "--policy"), f"--policy {path}")
    trial_path = path.parent / "trials" / f"trial_{row['trial']}.json"
    try:
        state = read_json(trial_path, f"--policy {path}: trial {row['trial']}'s learner state")["learner"]
        GarbLearner.from_state(state)
    except ParameterError:
        raise
    except (KeyError, TypeError, ValueError) as exc:
        raise ParameterError(f"--policy {path}: cannot read trial {row['trial']}'s learner state from "
                             f"{trial_path} ({exc})") from None
    source = {"learning": str(path), "trial": row["trial"], "level_cost_of_transport": row["cost_of_transport"],
              "level_episodes": state["episodes"]}
    return state, source


def start_from_window(t1: float, t2: float, variance: float) -> tuple[dict[str, Any], dict[str, Any]]:
    """A fresh learner state with mean (t1, t2): for a slope run without a level-ground learning record.
    (Its generator is never drawn from: each slope trial gets its own; seed 0 keeps the state reproducible.)"""
    return GarbLearner((t1, t2), variance, seed=0).state(), {"window": [t1, t2], "variance": variance}


def _run_checks(out: Path, configs: dict[str, EpisodeConfig], client) -> dict[str, dict[str, dict[str, Any]]]:
    """Each named configuration walked as learned and under every re-walk change, kept in OUT/checks/
    (NAME.json as learned, NAME.CHANGE.json) and reused when its configuration matches: {name: {change:
    result}}."""
    from drake_biped.common.executor import run_kept

    files = {}
    for name, c in configs.items():
        for change in CHANGES:
            stem = name if change == "as_learned" else f"{name}.{change}"
            files[name, change] = (out / "checks" / f"{stem}.json", changed(c, change).to_dict())
    results = run_kept(client, files)
    return {name: {change: results[name, change] for change in CHANGES} for name in configs}


def reached_slope(result: dict[str, Any]) -> bool:
    """The episode went past its ground's level stretch, onto the slope."""
    level = result["config"]["ground"].get("level_length_m")
    return level is None or result["distance_m"] > level


def climbs(result: dict[str, Any]) -> bool:
    """The episode reached the slope and its distance without falling."""
    return reached_slope(result) and walked_the_distance(result["fell"], result["distance_m"],
                                                         result["config"]["sim"]["distance_m"])


def _summary(result: dict[str, Any]) -> dict[str, Any]:
    keep = ("distance_m", "fell", "fall_reason", "duration_s", "cost_of_transport", "mean_speed_mps")
    return {**{k: result[k] for k in keep}, "climbs": climbs(result), "reached_slope": reached_slope(result)}


def _rewalks(walks: dict[str, dict[str, Any]]) -> dict[str, Any]:
    """A check's re-walks (besides the walk as learned): each change's summary, and whether all four climb or
    none does."""
    rows = {change: _summary(walks[change]) for change in CHANGES[1:]}
    summaries = [_summary(walks["as_learned"]), *rows.values()]
    every = [r["climbs"] for r in summaries]
    return {**rows, "all_climb": all(every), "none_climbs": not any(every),
            "all_reached_slope": all(r["reached_slope"] for r in summaries)}


def trial_summary(episodes: list[dict[str, Any]], distance_m: float) -> dict[str, Any]:
    """How one trial's sampled periods and distances developed: first and last 20-episode averages, the
    share of climbing episodes among the last 20, and the first episode whose 20-episode average distance
    is the full distance (None if never)."""
    d = np.array([e["distance_m"] for e in episodes])
    p = np.array([period(e["t1"], e["t2"]) for e in episodes])
    mean_p = np.array([period(e["mean_t1"], e["mean_t2"]) for e in episodes])
    up = np.array([walked_the_distance(e["fell"], e["distance_m"], distance_m) for e in episodes])
    n = min(MOVING_AVERAGE, len(episodes))
    ma = moving_average(d, MOVING_AVERAGE)
    # only a full window of MOVING_AVERAGE episodes counts: the first averages hold fewer
    reached = np.flatnonzero(ma[MOVING_AVERAGE - 1:] >= distance_m - 1e-6) + (MOVING_AVERAGE - 1)
    return {
        "episodes": len(episodes),
        "period_first_s": float(p[:n].mean()),
        "period_last_s": float(p[-n:].mean()),
        "mean_period_end_s": float(mean_p[-1]),
        "distance_first_m": float(d[:n].mean()),
        "distance_last_m": float(d[-n:].mean()),
        "climb_share_last": float(up[-n:].mean()),
        "first_full_average_episode": int(reached[0]) + 1 if reached.size else None,
    }


def run_slope(out: Path, base: EpisodeConfig, ground: Ground, start_state: dict[str, Any],
              start_source: dict[str, Any], trials: int, episodes: int, seed: int, client,
              progress: Callable[[int, int, float | None], None] | None = None) -> dict[str, Any]:
    """Run (or finish) the checks and the online learning on the slope; write slope.json and the figures;
    return the record."""
    from drake_biped.analysis.figures import slope_figures

    code = versions()
    out.mkdir(parents=True, exist_ok=True)
    config = base.replace(ground=ground, window=TorqueFreeWindow(0.0, 0.0), seed=seed)
    start = GarbLearner.from_state(start_state)
    settings = make_settings(config, trials, episodes, seed, mean=tuple(start.mean), variance=start.variance,
                             beta=start.beta, schedule=start.schedule)
    settings["learner"]["start_state"] = start_state
    checks = _run_checks(out, {"start_window": config.replace(window=window_of(start.mean)),
                               "no_window": config}, client)
    runs, _ = run_learning(out, settings, client, progress)
    finals = _run_checks(out, {f"final_trial_{t.index}": config.replace(window=window_of(t.learner.mean))
                               for t in runs}, client)
    start_period = period(*start.mean)
    trial_rows = []
    for t in runs:
        final = finals[f"final_trial_{t.index}"]
        row = {"trial": t.index, "learner_seed": trial_seed(seed, t.index), "final_mean": t.learner.mean.tolist(),
               **trial_summary(t.episodes, config.sim.distance_m),
               "final_policy": _summary(final["as_learned"]), "final_policy_rewalks": _rewalks(final)}
        trial_rows.append(row)
    rewalks = {name: _rewalks(r) for name, r in checks.items()}
    record = {
        "settings": settings,
        "ground": ground.to_dict(),
        "start": {**start_source, "mean": start.mean.tolist(), "period_s": start_period,
                  "variance": start.variance},
        "checks": {name: _summary(r["as_learned"]) for name, r in checks.items()},
        "rewalks": rewalks,
        "trials": trial_rows,
        "episodes": [{"trial": t.index, "episodes": t.episodes} for t in runs],
        "verdicts": verdicts(rewalks, trial_rows, start_period),
        "versions": code,
    }
    write_atomic(out / "slope.json", record)
    write_text_atomic(out / "report.md", report_markdown(record))
    slope_figures(record, out)
    return record


def verdicts(rewalks: dict[str, dict[str, Any]], trials: list[dict[str, Any]],
             start_period: float) -> dict[str, Any]:
    """The paper's three claims about the slope as measured here, each over the four walks of its check
    (`_rewalks`): the learned period reaches the slope and fails on it in all four (a walk that falls on the
    level never meets the slope), no period climbs in all four, and how many trials end with a shorter period
    that climbs in all four."""
    adapted = [t for t in trials if t["final_policy_rewalks"]["all_climb"] and t["mean_period_end_s"] < start_period]
    start = rewalks["start_window"]
    return {
        "learned_period_fails_to_climb": (start["none_climbs"] and start.get("all_reached_slope", True)
                                          and start_period > 0),
        "no_period_climbs": rewalks["no_window"]["all_climb"],
        "learning_shrinks_the_period_until_it_climbs": len(adapted),
        "trials": len(trials),
        "judged_over": list(CHANGES),
    }


def report_markdown(record: dict[str, Any]) -> str:
    """The slope run in words and numbers: the two checks, each trial's development, the verdicts."""
    g, start, checks, v = record["ground"], record["start"], record["checks"], record["verdicts"]

    def ended(r: dict[str, Any]) -> str:
        how = "falls" if r["fell"] else "stops"
        return how if r.get("reached_slope", True) else f"{how} on the level (never reached the slope)"

    def episode(r: dict[str, Any]) -> str:
        how = "climbs" if r["climbs"] else (f"{ended(r)} ({r['fall_reason']})" if r["fell"] else ended(r))
        cmt = "" if r["cost_of_transport"] is None else f", C_mt {format_cost(r['cost_of_transport'])}"
        return f"{how}: {r['distance_m']:.2f} m in {r['duration_s']:.1f} s{cmt}"

    def again(rows: dict[str, Any]) -> str:
        return ", ".join("climbs" if rows[c]["climbs"] else f"{ended(rows[c])} at {rows[c]['distance_m']:.2f} m"
                         for c in CHANGES[1:])

    rewalked_words = ", ".join(CHANGE_WORDS[c] for c in CHANGES[1:])
    t1, t2 = start["mean"]
    origin = (f"trial {start['trial']} of {start['learning']} (after {start['level_episodes']} level-ground "
              f"episodes)" if "learning" in start else "the given window (no level-ground learning record)")
    lines = [
        f"# Slope adaptation: {g['level_length_m']:g} m level, then {g['slope_rad']:g} rad "
        f"({math.degrees(g['slope_rad']):.2f}°)",
        "",
        f"Starting policy: mean t1 = {t1:.3f} s, t2 = {t2:.3f} s (period {start['period_s']:.3f} s), variance "
        f"{start['variance']:g} s², from {origin}.",
        "",
        f"Each check is walked as learned and re-walked ({rewalked_words}); a claim holds when it holds in all "
        "four walks.",
        "",
        f"| claim (paper) | measured here | re-walked ({rewalked_words}) | holds |",
        "|---|---|---|---|",
        f"| the learned torque-free period fails to climb | {episode(checks['start_window'])} | "
        f"{again(record['rewalks']['start_window'])} | {'yes' if v['learned_period_fails_to_climb'] else 'no'} |",
        f"| without a torque-free period the robot climbs | {episode(checks['no_window'])} | "
        f"{again(record['rewalks']['no_window'])} | {'yes' if v['no_period_climbs'] else 'no'} |",
        f"| online learning shrinks the period until it climbs | {v['learning_shrinks_the_period_until_it_climbs']}"
        f" of {v['trials']} trials end with a shorter period that climbs | "
        + "; ".join(f"trial {t['trial']}: {again(t['final_policy_rewalks'])}" for t in record["trials"])
        + f" | {'yes' if v['learning_shrinks_the_period_until_it_climbs'] else 'no'} |",
        "",
        f"| trial | episodes | period, first / last {MOVING_AVERAGE} (s) | policy period end (s) | distance, first "
        f"/ last {MOVING_AVERAGE} (m) | climbs in last {MOVING_AVERAGE} | first full {MOVING_AVERAGE}-average | "
        "final policy |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for t in record["trials"]:
        first = t["first_full_average_episode"]
        lines.append(
            f"| {t['trial']} | {t['episodes']} | {t['period_first_s']:.3f} / {t['period_last_s']:.3f} | "
            f"{t['mean_period_end_s']:.3f} | {t['distance_first_m']:.2f} / {t['distance_last_m']:.2f} | "
            f"{100 * t['climb_share_last']:.0f} % | {_first_full(first, t['episodes'])} | "
            f"({t['final_mean'][0]:.3f}, {t['final_mean'][1]:.3f}): {episode(t['final_policy'])} |")
    lines += ["", "Figures: fig8_period.png (the paper's Fig. 8, or Fig. 10 at 2.0°), fig9_distance.png "
              "(Fig. 9 / Fig. 11).", ""]
    return "\n".join(lines)


def _first_full(first: int | None, episodes: int) -> str:
    if episodes < MOVING_AVERAGE:
        return f"— (fewer than {MOVING_AVERAGE} episodes)"
    return "never" if first is None else f"episode {first}"


@dataclass(frozen=True)
class SlopeSettings:
    """A slope run: the gait `config` on `level_length_m` of level ground then `slope_rad` up; the learner
    starts from the best learned trial of the learning record `policy`, or else from the window (t1, t2)
    with `variance`; `trials` x `episodes` of online learning. `gait` names the shipped gait for the record."""

    config: EpisodeConfig = field(default_factory=EpisodeConfig)
    slope_rad: float = SLOPE_RAD
    level_length_m: float = SLOPE_LEVEL_LENGTH_M
    policy: str | None = None
    window: tuple[float, float] = DEFAULT_WINDOW_S
    variance: float = GARB_VARIANCE_S2
    trials: int = 2
    episodes: int = 100
    seed: int = 0
    gait: str | None = None
    force: bool = False  # run more than MAX_EPISODES episodes

    def __post_init__(self) -> None:
        for name, value in (("--trials", self.trials), ("--episodes", self.episodes)):
            if not isinstance(value, int) or isinstance(value, bool) or value < 1:
                raise ParameterError(f"{name} {value!r}: must be an integer >= 1")
        check_learning_size(f"--trials {self.trials} x --episodes {self.episodes}", self.trials * self.episodes,
                            self.force)
        check_reaches_slope(self.config.replace(ground=self.ground()))
        check_policy_spread(self.variance)

    def ground(self) -> Ground:
        return slope_ground(self.slope_rad, self.level_length_m, self.config.ground.friction)

    def start(self) -> tuple[dict[str, Any], dict[str, Any]]:
        """The learner state to start from and where it came from."""
        if self.policy is not None:
            state, source = start_from_learning(Path(self.policy))
        else:
            state, source = start_from_window(*self.window, self.variance)
        if self.gait is not None:
            source["params"] = self.gait
        return state, source


def run(settings: SlopeSettings, out: Path, client=None, progress: bool = True,
        workers: int | None = None, scheduler: str | None = None) -> dict[str, Any]:
    """The checks and the online learning on `client` (a LocalCluster when None), with a progress bar and
    OUT/run.json; writes slope.json, report.md, fig8_period.png, fig9_distance.png, checks/, trials/."""
    check_settings(settings, SlopeSettings, "slope.run")
    from drake_biped.common.executor import client_or_local
    from drake_biped.common.progress import RunProgress

    out = Path(out)
    ground = settings.ground()
    state, source = settings.start()
    report = RunProgress(out, workers, scheduler, "slope learning", "episode", bar=progress, command="slope")
    try:
        with client_or_local(client) as c:
            record = run_slope(out, settings.config, ground, state, source, settings.trials, settings.episodes,
                               settings.seed, c, report)
    finally:
        report.close()
    report.log.update(report.new, finished=True)
    return record


COMMAND = "slope"
# Rerunning the command on the same --out resumes it from its records, and these counts may be given larger to extend the run (never smaller).
RESUMABLE = True
GROWABLE = ("episodes", "trials")
PARSER = dict(help="slope adaptation: does the learned torque-free period climb, does none, "
              "and does online GARB learning adapt it (Figs. 8-11), on Dask")


def add_arguments(p: argparse.ArgumentParser) -> None:
    """`drake-biped slope`'s options."""
    add_episode_options(p, slope_command=True)
    add_window_options(p)
    p.add_argument("--variance", type=number("positive"), default=0.04,
                   help="the policy's variance (s^2) when starting from --t1/--t2; default 0.04 as in the paper "
                   "(--policy carries its own)")
    p.add_argument("--episodes", type=count, default=100, help="learning episodes per trial")
    p.add_argument("--trials", type=count, default=2, help="independent learning trials")
    add_resumable_run_options(p)


def settings_from_args(args: argparse.Namespace) -> SlopeSettings:
    """The slope story's settings from the command's options; a --policy that cannot be read is refused
    here, before a cluster starts."""
    level = args.level_length
    args.level_length = None  # the slope ground is built by the slope settings, not by the episode options
    slope_rad, args.slope = args.slope, None
    config = episode_config(args)
    slope_ground(slope_rad, level, config.ground.friction)  # refuse a bad slope before anything runs
    if args.policy is not None:
        if args.t1 is not None or args.t2 is not None:
            raise ParameterError("give either --policy or --t1/--t2, not both")
        settings = SlopeSettings(config, slope_rad, level, policy=str(args.policy), trials=args.trials,
                                       episodes=args.episodes, seed=config.seed, force=args.force)
    else:
        settings = SlopeSettings(config, slope_rad, level, window=chosen_window(args, config),
                                       variance=args.variance, trials=args.trials, episodes=args.episodes,
                                       seed=config.seed, force=args.force)
    settings.start()
    return settings


def command(args: argparse.Namespace) -> int:
    """Run the command of `args` (its options parsed by add_arguments); the exit code."""
    from drake_biped.common.progress import check_run_log

    settings = settings_from_args(args)
    out = Path(args.out)
    check_run_log(out, "slope")
    with cluster(args) as client:
        run(settings, out, client, workers=args.workers, scheduler=args.scheduler)
    print((out / "report.md").read_text())
    print(f"wrote {out}/slope.json, report.md, fig8_period.png, fig9_distance.png")
    return 0
