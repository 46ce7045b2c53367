"""Command-line interface: `drake-biped walk | window-map | gait-search | time-step-study | learn | compare-learners | figures | landscape | stability | rewalk | floquet | push-margin | grid | slope | reproduce`.

Parsing only: each command turns its options into its experiment's settings and calls the experiment's
`run(settings, out, client)` (drake_biped.experiments), which writes every file. Every numeric option is
validated here, at the boundary, with a message that names the option and value; every parallel command
takes the same `--workers N | --scheduler ADDR`.
"""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

from drake_biped.experiments import time_step as time_step_defaults
from drake_biped.experiments.gait_search import OBJECTIVES
from drake_biped.experiments.options import (  # noqa: F401  (number, integer, windows: the examples' option types)
    MADE,
    add_cluster_options,
    add_episode_options,
    add_model_option,
    add_resumable_run_options,
    add_window_options,
    chosen_window,
    cluster,
    count,
    episode_config,
    integer,
    learner_names,
    number,
    out_folder,
    positive_list,
    print_lines,
    seed_type,
    steps,
    windows,
    with_model,
)
from drake_biped.model import ModelError
from drake_biped.params import EpisodeConfig, ParameterError, Push, TorqueFreeWindow
from drake_biped.resources import load_gait


def cmd_walk(args: argparse.Namespace) -> int:
    from drake_biped.experiments import walk

    config = episode_config(args)
    if (args.t1 is None) != (args.t2 is None):
        raise ParameterError("--t1 and --t2 go together: give both or neither")
    if args.t1 is not None:
        if args.t2 <= args.t1:
            raise ParameterError(f"--t1 {args.t1:g} --t2 {args.t2:g}: t2 <= t1 is no torque-free window; "
                                 "give t1 < t2, or neither to walk without one")
        config = config.replace(window=TorqueFreeWindow(args.t1, args.t2))
    if args.push is not None:
        config = config.replace(push=Push(args.push, args.push_start, args.push_duration))
    elif args.push_start != 0.4 or args.push_duration != 0.1:
        raise ParameterError("--push-start and --push-duration shape a push: give --push N too")
    out = Path(args.out)
    result = walk.run(walk.WalkSettings(config, animation=not args.no_animation,
                                        save_trajectory=args.save_trajectory), out)
    print_lines(walk.summary_lines(result))
    if not args.no_animation:
        print_lines(walk.animation_lines(out))
    if config.push is not None and result.duration_s <= config.push.start_s:
        print(f"note: the episode ended at {result.duration_s:.2f} s, before the push at {config.push.start_s:g} s "
              "started: it walked unpushed", file=sys.stderr)
    print(f"wrote {out}/")
    return 0


def cmd_window_map(args: argparse.Namespace) -> int:
    from drake_biped.experiments import window_map

    settings = window_map.WindowMapSettings(episode_config(args), t1_max_s=args.t1_max, t2_max_s=args.t2_max,
                                            t1_step_s=args.step, t2_step_s=args.step, force=args.force)
    with cluster(args) as client:
        record = window_map.run(settings, Path(args.out), client)
    print_lines(window_map.summary_lines(record))
    print(f"wrote {args.out}/window_map.json, window_map.csv, window_map.png")
    return 0


def cmd_gait_search(args: argparse.Namespace) -> int:
    from drake_biped.experiments import gait_search

    config = episode_config(args)
    settings = gait_search.GaitSearchSettings(
        config, generations=args.generations, offspring=args.offspring, sigma=args.sigma, seed=config.seed,
        distance_m=config.sim.distance_m if args.distance is not None else 6.0, mutations=args.mutations,
        objective=args.objective, policy_draws=args.policy_draws)
    search = gait_search.run_cmaes if args.method == "cmaes" else gait_search.run
    with cluster(args) as client:
        result = search(settings, Path(args.out), client)
    print(f"best score {result['score']:+.3f}; parameters in {args.out}/best_config.json (use --params)")
    return 0


def cmd_time_step_study(args: argparse.Namespace) -> int:
    from drake_biped.experiments import time_step

    out = Path(args.out)
    if args.replot:
        rec = time_step.replot(out)
    else:
        config = None if args.params is None else load_gait(args.params)
        if args.model is not None:
            config = with_model(config or EpisodeConfig(), args.model)
        reference = min(args.steps) if args.reference is None else args.reference
        settings = time_step.TimeStepSettings(tuple(args.steps), reference, args.distance, config,
                                              "Default gait" if args.params is None else f"Gait {args.params}",
                                              None if args.windows is None else tuple(args.windows))
        with cluster(args) as client:
            rec = time_step.run(settings, out, client)
    print((out / "time_step_study.md").read_text())
    chosen = rec["chosen_step_s"]
    print(f"chosen step: {chosen * 1e3:g} ms" if chosen else "no step passes", f"; wrote {out}/")
    return 0


def cmd_compare_learners(args: argparse.Namespace) -> int:
    from drake_biped.experiments import compare_learners

    settings = compare_learners.CompareSettings(
        episode_config(args), args.window_map, learners=tuple(args.learners), trials=args.trials,
        episodes=args.episodes, seed=args.seed if args.seed is not None else 0)
    out = Path(args.out)
    compare_learners.check(settings, out)  # before a cluster starts
    with cluster(args) as client:
        record = compare_learners.run(settings, out, client)
    print_lines(compare_learners.summary_lines(record, out))
    return 0


def cmd_learn(args: argparse.Namespace) -> int:
    from drake_biped.experiments import learning
    from drake_biped.experiments.progress import check_run_log

    config = episode_config(args)
    settings = learning.LearningSettings(config, args.trials, args.episodes,
                                         args.seed if args.seed is not None else 0,
                                         mean=tuple(args.initial_mean), variance=args.variance,
                                         learner=args.learner)
    record_settings = settings.record()  # validated before a cluster starts
    out = Path(args.out)
    learning.check_resume(record_settings, out)
    check_run_log(out, "learn")  # before a cluster starts
    with cluster(args) as client:
        record = learning.run(record_settings, out, client, workers=args.workers, scheduler=args.scheduler,
                              rewalk_distance_m=args.rewalk_distance)
    print_lines(learning.summary_lines(record, out))
    return 0


def cmd_figures(args: argparse.Namespace) -> int:
    from drake_biped.analysis.figures import learning_figures
    from drake_biped.experiments.learning import check_learning_record
    from drake_biped.records import read_json

    out = Path(args.dir)
    path = out / "learning.json"
    record = check_learning_record(read_json(path, "figures DIR"), f"figures DIR: {path}")
    for p in learning_figures(record, out):
        print(f"wrote {p}")
    return 0


def cmd_landscape(args: argparse.Namespace) -> int:
    from drake_biped.experiments import landscape

    settings = landscape.LandscapeSettings(args.window_map, tuple(args.variance),
                                           (tuple(args.start),) if args.start else ((0.5, 0.5),),
                                           samples=args.samples, seed=args.seed)
    record = landscape.run(settings, Path(args.out) if args.out else None)
    print_lines(landscape.summary_lines(record))
    out = Path(args.out) if args.out else settings.path().parent
    print(f"wrote {out}/landscape.json, landscape.png")
    return 0


def cmd_stability(args: argparse.Namespace) -> int:
    from drake_biped.experiments import stability

    config = episode_config(args)
    settings = stability.StabilitySettings(window=chosen_window(args), trials=args.trials,
                                           push_force_n=args.push, spread=args.spread, seed=config.seed)
    out = Path(args.out)
    with cluster(args) as client:
        stability.run(settings, out, client, config=config, floquet=args.floquet)
    print("\n".join(line for line in (out / "report.md").read_text().splitlines() if line.startswith("|")))
    print(f"wrote {out}/stability.json, fig7_return_map.png, report.md, report.html")
    return 0


def cmd_floquet(args: argparse.Namespace) -> int:
    from drake_biped.experiments import floquet
    from drake_biped.params import TorqueFreeWindow

    config = episode_config(args)
    if args.policy is not None or args.t1 is not None or args.t2 is not None:
        config = config.replace(window=TorqueFreeWindow(*chosen_window(args)))
    settings = floquet.FloquetSettings(config, settle_steps=args.settle_steps,
                                       **({"epsilons": tuple(args.epsilons)} if args.epsilons else {}))
    out = Path(args.out)
    with cluster(args) as client:
        record = floquet.run(settings, out, client)
    from drake_biped.analysis.floquet import record_verdict

    epsilon = record["converged_epsilon"]
    print(f"spectral radius {record['spectral_radius']:.4f}, fixed-point residual "
          f"{record['fixed_point_residual']:.1e}, "
          + ("no perturbation converged" if epsilon is None else f"converged at epsilon {epsilon:g}")
          + f": {record_verdict(record)}")
    print(f"wrote {out}/floquet.json, floquet.md, floquet.png")
    return 0


def cmd_rewalk(args: argparse.Namespace) -> int:
    from drake_biped.analysis.rewalks import markdown
    from drake_biped.experiments.learning import check_learning_record, rewalk_record
    from drake_biped.records import read_json, write_atomic, write_text_atomic

    # What is not a learning record is refused before a cluster starts.
    check_learning_record(read_json(Path(args.policy), "--policy"), f"--policy {args.policy}")
    out = Path(args.out)
    with cluster(args) as client:
        record = rewalk_record(Path(args.policy), client)
    out.mkdir(parents=True, exist_ok=True)
    write_atomic(out / "rewalk.json", record)
    write_text_atomic(out / "rewalk.md", markdown(record))
    print(markdown(record))
    print(f"wrote {out}/rewalk.json, rewalk.md")
    return 0


def cmd_push_margin(args: argparse.Namespace) -> int:
    from drake_biped.experiments import push_margin

    config = episode_config(args)
    if args.distance is None:  # a push at --settle s (about 6 m), then room to recover or fall
        config = config.override({"sim.distance_m": 12.0, "sim.max_time_s": max(config.sim.max_time_s, 72.0)})
    settings = push_margin.PushMarginSettings(config, chosen_window(args), max_force_n=args.max_force,
                                              force_step_n=args.force_step, phases=args.phases,
                                              settle_s=args.settle, force=args.force)
    out = Path(args.out)
    with cluster(args) as client:
        push_margin.run(settings, out, client)
    print((out / "push_margin.md").read_text())
    print(f"wrote {out}/push_margin.json, push_margin.md, push_margin.png")
    return 0


def cmd_grid(args: argparse.Namespace) -> int:
    from drake_biped.experiments import grid
    from drake_biped.experiments.progress import check_run_log

    config = episode_config(args)
    if args.spec is not None and args.points_per_axis is not None:
        raise ParameterError("give either --spec or --points-per-axis, not both")
    axes = grid.load_spec(args.spec) if args.spec is not None else grid.table_iv_axes(args.points_per_axis or 2)
    source = f"--spec {args.spec}" if args.spec is not None else f"--points-per-axis {args.points_per_axis or 2}"
    grid.check_size(axes, args.force, source, "--force")  # before anything is built or started
    settings = grid.GridSettings(config, tuple(axes), force=args.force)
    out = Path(args.out)
    check_run_log(out, "grid")  # before a cluster starts
    with cluster(args) as client:
        record = grid.run(settings, out, client, workers=args.workers, scheduler=args.scheduler)
    print_lines(grid.summary_lines(record, out))
    return 0


def cmd_slope(args: argparse.Namespace) -> int:
    from drake_biped.experiments import slope
    from drake_biped.experiments.progress import check_run_log

    level = args.level_length
    args.level_length = None  # the slope ground is built by the slope settings, not by the episode options
    slope_rad, args.slope = args.slope, None
    config = episode_config(args)
    slope.slope_ground(slope_rad, level, config.ground.friction)  # refuse a bad slope before anything runs
    if args.policy is not None:
        if args.t1 is not None or args.t2 is not None:
            raise ParameterError("give either --policy or --t1/--t2, not both")
        settings = slope.SlopeSettings(config, slope_rad, level, policy=str(args.policy), trials=args.trials,
                                       episodes=args.episodes, seed=config.seed)
    else:
        settings = slope.SlopeSettings(config, slope_rad, level, window=chosen_window(args),
                                       variance=args.variance, trials=args.trials, episodes=args.episodes,
                                       seed=config.seed)
    settings.start()  # a --policy that cannot be read is refused before a cluster starts
    out = Path(args.out)
    check_run_log(out, "slope")
    with cluster(args) as client:
        slope.run(settings, out, client, workers=args.workers, scheduler=args.scheduler)
    print((out / "report.md").read_text())
    print(f"wrote {out}/slope.json, report.md, fig8_period.png, fig9_distance.png")
    return 0


def cmd_reproduce(args: argparse.Namespace) -> int:
    from drake_biped.experiments import reproduce
    from drake_biped.experiments.executor import check_cluster_options

    profile = reproduce.QUICK if args.quick else reproduce.FULL
    out = Path(args.out)
    check_cluster_options(args.workers, args.scheduler, args.force)  # before the folder is claimed for this profile
    reproduce.check_out(out, profile)
    hours = profile.expected_minutes / 60
    print(f"reproduce ({profile.name}): {len(reproduce.steps_of(profile))} experiments into {out}/, expected "
          "about " + (f"{profile.expected_minutes:.0f} min" if hours < 1.5 else f"{hours:.1f} h")
          + " on 2 cores; interrupt at any time and rerun the same command to resume", flush=True)
    with cluster(args) as client:
        reproduce.run(reproduce.ReproduceSettings(profile), out, client, workers=args.workers,
                      scheduler=args.scheduler)
    print("\n".join(line for line in (out / "report.md").read_text().splitlines()[:40] if line.startswith("|")))
    print(f"wrote {out}/report.md, report.html")
    return 0


class _HelpFormatter(argparse.HelpFormatter):
    """Every option's default in its help, unless the help already says it or there is none."""

    def _get_help_string(self, action: argparse.Action) -> str:
        text = action.help or ""
        default = action.default
        if "default" in text or action.required or default in (None, False, argparse.SUPPRESS):
            return text
        if isinstance(default, (list, tuple)):
            default = " ".join(f"{v:g}" if isinstance(v, float) else str(v) for v in default)
        return f"{text} (default: {default})"


class _Parser(argparse.ArgumentParser):
    """Option errors as one line naming the option and the value (exit code 2), without the usage block."""

    def exit(self, status: int = 0, message: str | None = None):
        _remove_empty_made_folders()  # --help or an option error: the command never ran
        super().exit(status, message)

    def error(self, message: str):
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def script_parser(description: str | None) -> argparse.ArgumentParser:
    """An argument parser for a script of the toolkit (examples/) with the commands' contract: an option error
    is one line naming the option and the value, exit code 2; every default in the help. Give its options
    this module's types (`number("positive")`, `integer(1)`, `windows`) and run the script with `run_script`."""
    first_line = description.strip().splitlines()[0] if description and description.strip() else None
    return _Parser(description=first_line, formatter_class=_HelpFormatter)


def run_script(main: Callable[[], object], prog: str | None = None) -> None:
    """Run a script's `main()` under the commands' contract: bad input (ParameterError, ModelError) one line
    and exit 2, a failed run one line and exit 1, Ctrl-C exit 130; the traceback with DRAKE_BIPED_DEBUG=1."""
    prog = prog or Path(sys.argv[0]).name
    with _failures_as_one_line(prog, os.environ.get(DEBUG_ENV, "") not in ("", "0"), "run it again",
                               f"set {DEBUG_ENV}=1 for the traceback"):
        main()


class _VersionAction(argparse.Action):
    """--version: the package's version, the git commit of a source checkout and Drake's version
    (`versions.versions()`, as every record holds them); then exit 0."""

    def __init__(self, option_strings, dest, **kwargs):
        kwargs.update(nargs=0, default=argparse.SUPPRESS)
        super().__init__(option_strings, dest, **kwargs)

    def __call__(self, parser, namespace, values, option_string=None):
        from drake_biped.versions import versions

        v = versions()
        print(f"drake-biped {v['drake_biped']}, git commit {v['git_commit'] or 'unknown (not a source checkout)'}, "
              f"Drake {v['drake'] or 'unknown (no drake distribution found)'}")
        parser.exit()


RESUMABLE = ("gait-search", "learn", "compare-learners", "stability", "grid", "slope", "reproduce")


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="drake-biped", description=__doc__.splitlines()[0],
                     epilog=f"Exit codes: 0 done, 1 a run failed, 2 bad input, 130 interrupted. --debug (or "
                     f"{DEBUG_ENV}=1) shows the traceback of a failure.")
    parser.add_argument("--version", action=_VersionAction,
                        help="print the package's version, its git commit and Drake's version, and exit")
    common = argparse.ArgumentParser(add_help=False)
    common.add_argument("--debug", action="store_true", help=f"on a failure, show the traceback (also {DEBUG_ENV}=1)")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    _add = sub.add_parser

    def add_parser(name, **kwargs):
        kwargs.setdefault("formatter_class", _HelpFormatter)
        return _add(name, parents=[common], **kwargs)

    sub.add_parser = add_parser

    walk = sub.add_parser("walk", help="walk one episode and write its record, figures and animation")
    add_episode_options(walk)
    walk.add_argument("--t1", type=number("nonnegative"),
                      help="torque-free start after each step start (s); with --t2 (default: no window)")
    walk.add_argument("--t2", type=number("nonnegative"), help="torque-free end (s), after --t1 (default: no window)")
    walk.add_argument("--push", type=number("finite"), help="horizontal push on the torso (N, + forward) "
                      "(default: none)")
    walk.add_argument("--push-start", type=number("nonnegative"), default=0.4, help="push start (s)")
    walk.add_argument("--push-duration", type=number("positive"), default=0.1, help="push duration (s)")
    walk.add_argument("--save-trajectory", action="store_true", help="also write trajectory.npz")
    walk.add_argument("--no-animation", action="store_true", help="skip walk.html and walk.gif")
    walk.add_argument("--out", required=True, type=out_folder, help="output folder")
    walk.set_defaults(func=cmd_walk)

    wmap = sub.add_parser("window-map", help="C_mt of a grid of torque-free windows against no window")
    add_episode_options(wmap)
    wmap.add_argument("--step", type=number("positive"), default=0.1, help="grid spacing of t1 and t2 (s)")
    wmap.add_argument("--t1-max", type=number("nonnegative"), default=0.6, help="largest start t1 (s)")
    wmap.add_argument("--t2-max", type=number("positive"), default=0.9, help="largest end t2 (s)")
    add_cluster_options(wmap)
    wmap.add_argument("--out", required=True, type=out_folder, help="output folder")
    wmap.set_defaults(func=cmd_window_map)

    search = sub.add_parser("gait-search", help="evolve gait parameters for walking and torque-free savings",
                            epilog="objectives: " + "  ".join(f"'{name}': {o.about}" for name, o in OBJECTIVES.items()))
    add_episode_options(search)
    search.add_argument("--generations", type=count, default=50, help="generations (default 50)")
    search.add_argument("--offspring", type=count, default=4, help="children per generation (default 4)")
    search.add_argument("--sigma", type=number("positive"), default=0.1, help="mutation scale (default 0.1)")
    search.add_argument("--mutations", choices=["default", "paper", "near_paper", "coast"], default="default",
                        help="what mutates: 'default' (CPG u_a, u_r, kappa and the gains), 'paper' (only what "
                             "the paper does not print: the CPG and the initiation held), 'near_paper' (those "
                             "and u_a, u_r, kappa) or 'coast' (default, the knee's hold torque, the torso's "
                             "gains and the stance knee)")
    search.add_argument("--method", choices=["es", "cmaes"], default="es",
                        help="'es': the (1 + offspring) evolution strategy; 'cmaes': CMA-ES (pycma), "
                             "offspring candidates a generation")
    search.add_argument("--objective", default="windows", choices=list(OBJECTIVES),
                        help="what a walker scores (each objective's definition below)")
    search.add_argument("--policy-draws", type=count, default=12,
                        help="draws of the paper's start policy the 'policy', 'expected' and 'story' objectives walk "
                             "(default 12; a draw with t2 <= t1 is no window and costs no episode)")
    add_resumable_run_options(search)
    search.set_defaults(func=cmd_gait_search)

    ts = sub.add_parser("time-step-study", help="the long-run C_mt against the plant step (control period kept), "
                        "Richardson's limit, and the step they choose")
    ts.add_argument("--steps", type=steps, default=list(time_step_defaults.STEPS),
                    help="plant steps (s), comma-separated (default 0.002,0.001,0.0005,0.00025,0.000125)")
    ts.add_argument("--reference", type=number("positive"), default=None,
                    help="reference step (s), one of --steps (default: the finest)")
    ts.add_argument("--distance", type=number("positive"), default=time_step_defaults.LONG_WALK_M,
                    help="walk this far (m); default 110: the first 10 m are the transient, the long-run C_mt is "
                         "over the rest")
    ts.add_argument("--params", help="the gait (a shipped gait's name or a JSON file, as elsewhere); default: the "
                    "default gait. Its own time step is replaced by each of --steps")
    add_model_option(ts)
    ts.add_argument("--windows", type=windows,
                    help="the windows compared with none, T1-T2 in s, comma-separated (default "
                         "0.405096-0.944455,0.3-0.6: the default gait's learned window and one early in the swing)")
    add_cluster_options(ts)
    ts.add_argument("--replot", action="store_true", help="redraw the table and figure from OUT's JSON")
    ts.add_argument("--out", required=True, type=out_folder, help="output folder")
    ts.set_defaults(func=cmd_time_step_study)

    learn = sub.add_parser("learn", help="learning of the torque-free period (Experiment 1: GARB), on Dask")
    add_episode_options(learn)
    from drake_biped.learners.registry import LEARNERS

    learn.add_argument("--learner", choices=sorted(LEARNERS), default="garb",
                       help="'garb' (the paper's, Table II), 'cmaes' (CMA-ES, pycma), 'pgpe' (symmetric PGPE)")
    learn.add_argument("--trials", type=count, default=5, help="independent trials (default 5)")
    learn.add_argument("--episodes", type=count, default=500, help="episodes per trial (default 500)")
    learn.add_argument("--initial-mean", type=number("nonnegative"), nargs=2, default=[0.5, 0.5],
                       metavar=("T1", "T2"), help="the policy's starting mean (s); default 0.5 0.5 as in the paper")
    learn.add_argument("--variance", type=number("positive"), default=0.04,
                       help="the policy's variance per time (s^2); default 0.04 as in the paper")
    learn.add_argument("--rewalk-distance", type=number("positive"), default=None,
                       help="how far each final policy mean (and no window) is re-walked, as learned, at half the "
                            "step and from 0.95 / 1.05 x the initiation speed (m); from 110 m on, each walk's C_mt is "
                            "its long-run mean after the first 10 m (default: 110, or --distance when under 10 m)")
    add_resumable_run_options(learn)
    learn.set_defaults(func=cmd_learn)

    comp = sub.add_parser("compare-learners", help="learners side by side against the window map's best window")
    add_episode_options(comp)
    comp.add_argument("--window-map", required=True,
                      help="the gait's window map (a window-map folder or its window_map.json): the known optimum")
    comp.add_argument("--learners", type=learner_names, default=["garb", "cmaes", "pgpe"],
                      help="comma-separated (default garb,cmaes,pgpe)")
    comp.add_argument("--trials", type=count, default=5, help="trials per learner (default 5)")
    comp.add_argument("--episodes", type=count, default=300, help="episodes per trial (default 300)")
    add_resumable_run_options(comp)
    comp.set_defaults(func=cmd_compare_learners)

    land = sub.add_parser("landscape", help="the expected reward GARB climbs, from a window map, for given variances")
    land.add_argument("window_map", help="a window-map output folder or its window_map.json")
    land.add_argument("--variance", type=steps, default=[0.04, 0.01, 0.0025],
                      help="policy variances (s^2), comma-separated; default 0.04,0.01,0.0025")
    land.add_argument("--start", type=number("nonnegative"), nargs=2, metavar=("T1", "T2"),
                      help="a policy start to evaluate (default 0.5 0.5)")
    land.add_argument("--samples", type=count, default=2000, help="Monte Carlo samples per mean (default 2000)")
    land.add_argument("--seed", type=seed_type, default=0, help="random seed (default 0)")
    land.add_argument("--out", default=None, type=out_folder, help="output folder (default: the window map's)")
    land.set_defaults(func=cmd_landscape)

    stab = sub.add_parser("stability", help="pushes and Poincare return maps with and without a torque-free "
                          "period (Table VI, Fig. 7), on Dask")
    add_episode_options(stab)
    add_window_options(stab)
    stab.add_argument("--trials", type=count, default=8, help="trials per cell (default 8)")
    stab.add_argument("--push", type=number("positive"), default=20.0, help="push force (N); default 20")
    stab.add_argument("--floquet", action="store_true",
                      help="also the periodic orbit's Floquet multipliers without and with the window (about a "
                      "minute each on 2 cores), in the report beside the regression")
    stab.add_argument("--spread", type=number("nonnegative"), default=0.15,
                      help="trials' initial hip angle and speed within +-this fraction (default 0.15)")
    add_resumable_run_options(stab)
    stab.set_defaults(func=cmd_stability)

    pm = sub.add_parser("push-margin", help="pushes in steady state over a grid of forces and phases of the step, "
                        "with and without a torque-free period: the survival map and the margins (on Dask)")
    add_episode_options(pm)
    add_window_options(pm)
    pm.add_argument("--max-force", type=number("positive"), default=100.0, help="largest push tried (N); default 100")
    pm.add_argument("--force-step", type=number("positive"), default=5.0,
                    help="spacing of the force grid (N); default 5")
    pm.add_argument("--phases", type=count, default=12, help="phases of the step pushed; default 12")
    pm.add_argument("--settle", type=number("positive"), default=5.0,
                    help="the step pushed is the first to start at or after this time (s); default 5")
    add_cluster_options(pm)
    pm.add_argument("--out", required=True, type=out_folder, help="output folder")
    pm.set_defaults(func=cmd_push_margin)

    rw = sub.add_parser("rewalk", help="a learning run's final policy means re-walked with the plant step halved "
                        "and from 0.95 and 1.05 x the initiation speed, each against no window under the same "
                        "change, on Dask")
    rw.add_argument("--policy", required=True, help="the learning.json of drake-biped learn")
    add_cluster_options(rw)
    rw.add_argument("--out", required=True, type=out_folder, help="output folder")
    rw.set_defaults(func=cmd_rewalk)

    fl = sub.add_parser("floquet", help="the gait's periodic orbit (Newton on the full-state step map) and its "
                        "Floquet multipliers by central differences through Drake, on Dask")
    add_episode_options(fl)
    fl.add_argument("--t1", type=number("nonnegative"), help="torque-free start (s); default: the gait's window")
    fl.add_argument("--t2", type=number("positive"), help="torque-free end (s); default: the gait's window")
    fl.add_argument("--policy", default=None, help="a learning.json: analyse its best learned torque-free period")
    fl.add_argument("--settle-steps", type=count, default=8,
                    help="touchdowns walked from the initiation before the search starts (default 8)")
    fl.add_argument("--epsilons", type=positive_list, default=None,
                    help="perturbation sizes of the sweep, comma-separated (default 1e-8 to 3e-3, half decades)")
    add_cluster_options(fl)
    fl.add_argument("--out", required=True, type=out_folder, help="output folder")
    fl.set_defaults(func=cmd_floquet)

    grid = sub.add_parser("grid", help="grid search of CPG parameters and the initiation (Table IV), on Dask")
    add_episode_options(grid)
    grid.add_argument("--points-per-axis", type=count, default=None,
                      help="points per range (cell centres) of Table IV's five CPG parameters and the "
                      "initial hip angle (0-15.2 deg) and speed (0-0.35 m/s); default 2 (128 points)")
    grid.add_argument("--spec", default=None, help="a YAML grid spec: axes: {name: {min, max, points} | "
                      "{values: [...]}}, or a shipped one by name (around_default, slope_0.02, slope_2deg, tiny)")
    add_resumable_run_options(grid)
    grid.set_defaults(func=cmd_grid)

    sl = sub.add_parser("slope", help="slope adaptation: does the learned torque-free period climb, does none, "
                        "and does online GARB learning adapt it (Figs. 8-11), on Dask")
    add_episode_options(sl, slope_command=True)
    add_window_options(sl)
    sl.add_argument("--variance", type=number("positive"), default=0.04,
                    help="the policy's variance (s^2) when starting from --t1/--t2; default 0.04 as in the paper "
                    "(--policy carries its own)")
    sl.add_argument("--episodes", type=count, default=100, help="learning episodes per trial (default 100)")
    sl.add_argument("--trials", type=count, default=2, help="independent learning trials (default 2)")
    add_resumable_run_options(sl)
    sl.set_defaults(func=cmd_slope)

    rep = sub.add_parser("reproduce", help="every experiment of the paper and one report beside its numbers "
                         "(--quick: small settings, minutes)")
    rep.add_argument("--quick", action="store_true", help="small settings: the same report in minutes")
    add_resumable_run_options(rep)
    rep.set_defaults(func=cmd_reproduce)

    figs = sub.add_parser("figures", help="redraw a learning run's figures and Table V from its records")
    figs.add_argument("dir", help="the learning run's output folder")
    figs.set_defaults(func=cmd_figures)
    for command in sub.choices.values():  # every command that writes a folder can be told to replace it
        if any(a.dest == "out" for a in command._actions):
            command.add_argument("--overwrite", action="store_true",
                                 help="replace the records of another run (another command or other settings) "
                                      "in --out; without it such a folder is refused")
    return parser


# Counts a resumable command's run is extended by when given larger (never shortened).
_GROWABLE = {"learn": ("episodes", "trials"), "compare-learners": ("episodes", "trials"),
             "gait-search": ("generations",), "slope": ("episodes", "trials"), "stability": ("trials",)}

# The largest runs a command starts without --force, counted in what it walks: every size a user gives is bounded
# before any work (a day or more of 2 cores; the grid, the window map and the push-margin map have their own).
MAX_RUN_EPISODES = 100_000
_RUN_SIZES = {
    "learn": ("episodes", lambda a: a.trials * a.episodes, "--trials x --episodes"),
    "compare-learners": ("episodes", lambda a: len(a.learners) * a.trials * a.episodes,
                         "learners x --trials x --episodes"),
    "slope": ("episodes", lambda a: a.trials * a.episodes, "--trials x --episodes"),
    "stability": ("episodes", lambda a: 6 * a.trials, "6 cells x --trials"),
    "gait-search": ("candidates", lambda a: a.generations * a.offspring, "--generations x --offspring"),
    "time-step-study": ("walks", lambda a: len(a.steps) * (1 + (len(a.windows) if a.windows else 2)),
                        "--steps x walks"),
}
MAX_RUN_SIZE = {"episodes": MAX_RUN_EPISODES, "candidates": 2_000, "walks": 200}


def _check_run_size(args: argparse.Namespace) -> None:
    """ParameterError naming the options, the count and its limit when a run is larger than MAX_RUN_SIZE,
    unless --force."""
    if args.command not in _RUN_SIZES or getattr(args, "force", False):
        return
    unit, count, options = _RUN_SIZES[args.command]
    try:
        n = count(args)
    except (AttributeError, TypeError):
        return
    if n > MAX_RUN_SIZE[unit]:
        raise ParameterError(f"{options} = {n:,} {unit}, more than the limit of {MAX_RUN_SIZE[unit]:,} for one run; "
                             "give fewer, or --force to run it anyway")


# What does not change a run's records: where it runs and how it reports. Every other option is part of the
# settings an output folder is held for (records.claim_folder).
_NOT_SETTINGS = {"out", "workers", "scheduler", "force", "debug", "overwrite", "func", "command", "replot"}


def _settings_of(args: argparse.Namespace) -> dict:
    """The options of a command that decide its records, as JSON values."""
    def plain(value):
        if isinstance(value, Path):
            return str(value)
        if isinstance(value, (list, tuple)):
            return [plain(v) for v in value]
        if isinstance(value, (str, int, float, bool)) or value is None:
            return value
        return str(value)

    return {k: plain(v) for k, v in sorted(vars(args).items()) if k not in _NOT_SETTINGS}


@contextmanager
def _holding_the_out_folder(args: argparse.Namespace) -> Iterator[None]:
    """records.claim_folder on --out for a command that writes one (not a --replot, which redraws its own)."""
    out = getattr(args, "out", None)
    if out is None or getattr(args, "replot", False):
        yield
        return
    from drake_biped.records import claim_folder

    with claim_folder(Path(out), args.command, _settings_of(args), overwrite=getattr(args, "overwrite", False),
                      growable=_GROWABLE.get(args.command, ())):
        yield


DEBUG_ENV = "DRAKE_BIPED_DEBUG"


def _one_line(exc: BaseException) -> str:
    text = " ".join(str(exc).split()) or type(exc).__name__
    return text if len(text) <= 400 else text[:397] + "..."


def main(argv: list[str] | None = None) -> int:
    """Run one command. Exit codes: 0 done; 2 bad input (an option, a file, the model), one line naming it;
    1 a run that failed, one line; 130 interrupted (Ctrl-C), one line saying how to resume. A traceback
    only with --debug or DRAKE_BIPED_DEBUG=1."""
    parser = build_parser()
    args = parser.parse_args(argv)
    # tqdm's monitor thread, stopped by an atexit hook, prints a traceback of its own when a second Ctrl-C
    # arrives while the process exits; the bars need no monitor.
    from tqdm import tqdm

    tqdm.monitor_interval = 0
    debug = bool(getattr(args, "debug", False)) or os.environ.get(DEBUG_ENV, "") not in ("", "0")
    out = getattr(args, "out", None)
    again = ("run the same command again to resume: finished work is kept in " + str(out)
             if args.command in RESUMABLE and out else "run the same command again")
    with _failures_as_one_line(f"drake-biped {args.command}", debug, again):
        _check_run_size(args)
        with _holding_the_out_folder(args):
            return args.func(args)
    return 0  # not reached: a failure leaves by SystemExit


@contextmanager
def _failures_as_one_line(prefix: str, debug: bool, again: str,
                          traceback_hint: str = "rerun with --debug for the traceback") -> Iterator[None]:
    """The contract of `main` (and of `run_script`) around a command's work: every failure one line on
    standard error starting with `prefix`, and its exit code."""
    try:
        yield
    except KeyboardInterrupt:
        if debug:
            raise
        _exit(130, f"{prefix}: interrupted; {again}")
    except (ParameterError, ModelError) as exc:
        _remove_empty_made_folders()
        if debug:
            raise
        _exit(2, f"{prefix}: error: {_one_line(exc)}")
    except Exception as exc:  # a failed run: one line, the traceback on request
        if debug:
            raise
        _exit(1, f"{prefix}: failed: {type(exc).__name__}: {_one_line(exc)} ({traceback_hint})")
    except SystemExit as exc:  # pydrake raises a failed check inside Drake (DRAKE_DEMAND) as SystemExit
        from drake_biped.api_guard import drake_failure_message, is_drake_failure

        if debug or not is_drake_failure(exc):
            raise
        _exit(1, f"{prefix}: failed: DrakeFailure: a check inside Drake failed ({drake_failure_message(exc)}) "
                 f"({traceback_hint})")


def _remove_empty_made_folders() -> None:
    for folder in reversed(MADE):
        try:
            folder.rmdir()  # only an empty folder goes
        except OSError:
            pass
    MADE.clear()


def _exit(code: int, message: str) -> None:
    sys.stderr.flush()
    print(message, file=sys.stderr, flush=True)
    raise SystemExit(code)


if __name__ == "__main__":
    sys.exit(main())
