"""Experiment 1, `drake-biped learn`: trials x episodes of a learner (GARB by default) learning the torque-free
period, then Table V and its figures. The learning run itself (its trials, their records, the resumption, the
evaluation of the final policies) is `drake_biped.common.learning_runs`, which the slope and learner-comparison
experiments share."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from drake_biped.analysis.cost_of_transport import format_cost
from drake_biped.common.learning_runs import (
    LearningSettings,
    check_resume,
    check_rewalk_distance,
    run,
)
from drake_biped.common.options import (
    add_episode_options,
    add_resumable_run_options,
    cluster,
    count,
    episode_config,
    number,
    print_lines,
)
from drake_biped.records import read_json


def saving_words(reduction: float) -> str:
    """A fractional saving in words, to 0.1 %: "12.3 % lower", "0.1 % higher" (a negative saving costs more),
    "the same (to 0.1 %)"."""
    percent = round(100.0 * reduction, 1)
    if percent > 0:
        return f"{percent:.1f} % lower"
    if percent < 0:
        return f"{-percent:.1f} % higher"
    return "the same (to 0.1 %)"


def summary_lines(record: dict[str, Any], out: Path) -> list[str]:
    """What `drake-biped learn` prints after a run: Table V, the reduction, the run's speed."""
    ev = record["evaluation"]
    lines = [(out / "table_v.md").read_text()]
    base = ev["no_window"]["cost_of_transport"]
    if ev.get("reduction") is not None:
        lines.append(f"C_mt without a torque-free period {format_cost(base)}, with the learned ones "
                     f"{format_cost(ev['learned_mean_cost_of_transport'])}: {saving_words(ev['reduction'])}")
    run_log = read_json(out / "run.json", "learn")
    this = run_log["sessions"][-1]
    if this["episodes_per_min"]:
        lines.append(f"{this['episodes']} episodes in {this['learning_wall_s']:.0f} s "
                     f"({this['episodes_per_min']:.1f} episodes/min); the whole run so far: {run_log['episodes']} "
                     f"episodes, {run_log['learning_wall_s'] / 60:.1f} min of learning over "
                     f"{len(run_log['sessions'])} session(s)")
    lines.append(f"wrote {out}/learning.json, fig4_reward.png, fig5_cmt.png, fig6_times.png, table_v.md")
    return lines


COMMAND = "learn"
# Rerunning the command on the same --out resumes it from its records, and these counts may be given larger to extend the run (never smaller).
RESUMABLE = True
GROWABLE = ("episodes", "trials")


PARSER = dict(help="learning of the torque-free period (Experiment 1: GARB), on Dask")


def add_arguments(p: argparse.ArgumentParser) -> None:
    """`drake-biped learn`'s options."""
    add_episode_options(p)
    from drake_biped.learners.registry import DEFAULT_LEARNER, LEARNERS

    p.add_argument("--learner", choices=sorted(LEARNERS), default=DEFAULT_LEARNER,
                   help="'garb' (the paper's, Table II), 'cmaes' (CMA-ES, pycma), 'pgpe' (symmetric PGPE)")
    p.add_argument("--trials", type=count, default=5, help="independent trials")
    p.add_argument("--episodes", type=count, default=500, help="episodes per trial")
    p.add_argument("--initial-mean", type=number("nonnegative"), nargs=2, default=[0.5, 0.5],
                   metavar=("T1", "T2"), help="the policy's starting mean (s); default 0.5 0.5 as in the paper")
    p.add_argument("--variance", type=number("positive"), default=0.04,
                   help="the policy's variance per time (s^2); default 0.04 as in the paper")
    p.add_argument("--rewalk-distance", type=number("positive"), default=None,
                   help="how far each final policy mean (and no window) is re-walked, as learned, at half the "
                   "step and from 0.95 / 1.05 x the initiation speed (m); from 110 m on, each walk's C_mt is "
                   "its long-run mean after the first 10 m (default: 110, or --distance when under 10 m)")
    add_resumable_run_options(p)


def settings_from_args(args: argparse.Namespace) -> LearningSettings:
    """The learning run's settings from the command's options."""
    return LearningSettings(episode_config(args), args.trials, args.episodes, args.seed if args.seed is not None else 0,
                            mean=tuple(args.initial_mean), variance=args.variance, learner=args.learner,
                            force=args.force)


def command(args: argparse.Namespace) -> int:
    """Run the command of `args` (its options parsed by add_arguments); the exit code."""
    from drake_biped.common.progress import check_run_log

    record_settings = settings_from_args(args).record()  # validated before a cluster starts
    if args.rewalk_distance is not None:
        check_rewalk_distance(record_settings, args.rewalk_distance)
    out = Path(args.out)
    check_resume(record_settings, out)
    check_run_log(out, "learn")  # before a cluster starts
    with cluster(args) as client:
        record = run(record_settings, out, client, workers=args.workers, scheduler=args.scheduler,
                              rewalk_distance_m=args.rewalk_distance)
    print_lines(summary_lines(record, out))
    return 0
