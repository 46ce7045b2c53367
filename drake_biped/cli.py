"""Command-line interface: `drake-biped walk | window-map | gait-search | time-step-study | learn | figures | landscape | stability | push-margin | grid | slope | reproduce`.

Every numeric option is validated here, at the boundary, with a message that names the option and value.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

from drake_biped.params import (
    EpisodeConfig,
    Ground,
    ParameterError,
    Push,
    SimulationParams,
    TorqueFreeWindow,
)


def _number(kind: str):
    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
        if not math.isfinite(value):
            raise argparse.ArgumentTypeError(f"{text!r} is not a finite number")
        if kind == "positive" and value <= 0:
            raise argparse.ArgumentTypeError(f"{text!r} must be > 0")
        if kind == "nonnegative" and value < 0:
            raise argparse.ArgumentTypeError(f"{text!r} must be >= 0")
        return value

    parse.__name__ = f"{kind} number"
    return parse


def _integer(minimum: int):
    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not an integer") from None
        if value < minimum:
            raise argparse.ArgumentTypeError(f"{text!r} must be >= {minimum}")
        return value

    parse.__name__ = f"integer >= {minimum}"
    return parse


_seed = _integer(0)
_count = _integer(1)


def _add_episode_options(p: argparse.ArgumentParser) -> None:
    p.add_argument("--params", type=Path, help="JSON file with EpisodeConfig fields (cpg, gait, initial, ...)")
    p.add_argument("--distance", type=_number("positive"), help="walk this far (m); default 10")
    p.add_argument("--max-time", type=_number("positive"), help="simulated time limit (s); default 60")
    p.add_argument("--time-step", type=_number("positive"), help="plant and control time step (s); default 0.001")
    p.add_argument("--slope", type=_number("finite"), help="ground slope (rad, > 0 ascends)")
    p.add_argument("--level-length", type=_number("nonnegative"),
                   help="level ground for this many metres, then the slope")
    p.add_argument("--seed", type=_seed, default=None, help="recorded with the result (default 0)")


def _episode_config(args: argparse.Namespace) -> EpisodeConfig:
    config = EpisodeConfig()
    if args.params is not None:
        from drake_biped.learning import read_json

        data = read_json(args.params, "--params")
        if isinstance(data, dict) and "config" in data:  # a result.json: reuse the config that made it
            data = data["config"]
        config = EpisodeConfig.from_dict(data)
    sim = config.sim
    if args.distance is not None or args.max_time is not None or args.time_step is not None:
        sim_d = sim.to_dict()
        if args.distance is not None:
            sim_d["distance_m"] = args.distance
            if args.max_time is None:
                sim_d["max_time_s"] = max(sim.max_time_s, 6.0 * args.distance)
        if args.max_time is not None:
            sim_d["max_time_s"] = args.max_time
        if args.time_step is not None:
            sim_d["time_step_s"] = args.time_step
            sim_d["control_period_s"] = args.time_step
        sim = SimulationParams(**sim_d)
    ground = config.ground
    if args.slope is not None or args.level_length is not None:
        ground = Ground(
            slope_rad=args.slope if args.slope is not None else ground.slope_rad,
            level_length_m=args.level_length if args.level_length is not None else ground.level_length_m,
            friction=ground.friction,
        )
    seed = args.seed if args.seed is not None else config.seed
    return config.replace(sim=sim, ground=ground, seed=seed)


def _progress_bar(total_m: float, desc: str):
    from tqdm import tqdm

    bar = tqdm(total=round(total_m, 2), desc=desc, unit="m", bar_format="{l_bar}{bar}| {n:.2f}/{total:.2f} m [{elapsed}<{remaining}{postfix}]")

    def update(t: float, d: float) -> None:
        d = min(max(d, 0.0), total_m)
        bar.n = round(d, 2)
        bar.set_postfix_str(f"t={t:.1f}s", refresh=False)
        bar.refresh()

    return bar, update


def cmd_walk(args: argparse.Namespace) -> int:
    from drake_biped.outputs import write_walk

    config = _episode_config(args)
    if (args.t1 is None) != (args.t2 is None):
        raise ParameterError("--t1 and --t2 go together: give both or neither")
    if args.t1 is not None:
        config = config.replace(window=TorqueFreeWindow(args.t1, args.t2))
    if args.push is not None:
        config = config.replace(push=Push(args.push, args.push_start, args.push_duration))
    out = Path(args.out)
    bar, update = _progress_bar(config.sim.distance_m, "walk")
    try:
        result = write_walk(config, out, animation=not args.no_animation, save_trajectory=args.save_trajectory,
                            progress=update)
    finally:
        bar.close()
    _print_summary(result)
    print(f"wrote {out}/")
    return 0


def _print_summary(result) -> None:
    status = f"FELL ({result.fall_reason})" if result.fell else f"ended: {result.termination}"
    cmt = "n/a" if result.cost_of_transport is None else f"{result.cost_of_transport:.3f}"
    cmt_kg = "n/a" if result.cost_of_transport_per_kg is None else f"{result.cost_of_transport_per_kg:.3f}"
    period = "n/a" if result.step_period_s is None else f"{result.step_period_s:.3f} s"
    length = "n/a" if result.step_length_m is None else f"{result.step_length_m:.3f} m"
    print(
        f"{status}: {result.distance_m:.2f} m in {result.duration_s:.2f} s ({result.mean_speed_mps:.3f} m/s), "
        f"{len(result.steps)} steps, step {period} / {length}\n"
        f"positive work {result.total_positive_work_j:.1f} J, C_mt {cmt} (E+/(m g d)), "
        f"{cmt_kg} J/(kg m) (paper's eq. 1)\n"
        f"wall {result.wall_time_s:.1f} s, real-time factor {result.real_time_factor:.2f}"
    )


def cmd_window_map(args: argparse.Namespace) -> int:
    from drake_biped.window_map import run_window_map

    config = _episode_config(args)
    run_window_map(config, Path(args.out), t1_step=args.step, t2_step=args.step, workers=args.workers,
                   t1_max=args.t1_max, t2_max=args.t2_max)
    return 0


def cmd_gait_search(args: argparse.Namespace) -> int:
    from drake_biped.gait_search import run_search

    config = _episode_config(args)
    result = run_search(config, Path(args.out), generations=args.generations, offspring=args.offspring,
                        sigma=args.sigma, seed=config.seed, distance_m=config.sim.distance_m
                        if args.distance is not None else 6.0, workers=args.workers)
    print(f"best score {result['score']:+.3f}; parameters in {args.out}/best_config.json (use --params)")
    return 0


def cmd_time_step_study(args: argparse.Namespace) -> int:
    from drake_biped.time_step import replot, run_study

    out = Path(args.out)
    if args.replot:
        if not (out / "time_step_study.json").is_file():
            raise ParameterError(f"--replot: no time_step_study.json in {out}")
        rec = replot(out)
    else:
        rec = run_study(out, args.steps, args.reference, args.distance, args.workers, args.scheduler)
    print((out / "time_step_study.md").read_text())
    chosen = rec["chosen_step_s"]
    print(f"chosen step: {chosen * 1e3:g} ms" if chosen else "no step passes", f"; wrote {out}/")
    return 0


def cmd_learn(args: argparse.Namespace) -> int:
    from drake_biped.learning import learn, make_settings

    config = _episode_config(args)
    _check_cluster_options(args)
    settings = make_settings(config, args.trials, args.episodes, args.seed if args.seed is not None else 0,
                             mean=tuple(args.initial_mean), variance=args.variance)
    out = Path(args.out)
    record = learn(out, settings, workers=args.workers, scheduler=args.scheduler)
    ev = record["evaluation"]
    print((out / "table_v.md").read_text())
    base = ev["no_window"]["cost_of_transport"]
    if ev.get("reduction") is not None:
        print(f"C_mt without a torque-free period {base:.3f}, with the learned ones "
              f"{ev['learned_mean_cost_of_transport']:.3f}: {100 * ev['reduction']:.1f} % lower")
    run = json.loads((out / "run.json").read_text())
    this = run["sessions"][-1]
    if this["episodes_per_min"]:
        print(f"{this['episodes']} episodes in {this['learning_wall_s']:.0f} s "
              f"({this['episodes_per_min']:.1f} episodes/min); the whole run so far: {run['episodes']} episodes, "
              f"{run['learning_wall_s'] / 60:.1f} min of learning over {len(run['sessions'])} session(s)")
    print(f"wrote {out}/learning.json, fig4_reward.png, fig5_cmt.png, fig6_times.png, table_v.md")
    return 0


def cmd_figures(args: argparse.Namespace) -> int:
    from analysis.figures import learning_figures
    from drake_biped.learning import read_json

    out = Path(args.dir)
    for p in learning_figures(read_json(out / "learning.json", "figures: learning record"), out):
        print(f"wrote {p}")
    return 0


def cmd_landscape(args: argparse.Namespace) -> int:
    from analysis.policy_landscape import WindowRewards, landscape, landscape_figure
    from drake_biped.learning import write_atomic
    from drake_biped.versions import versions

    source = Path(args.window_map)
    path = source / "window_map.json" if source.is_dir() else source
    if not path.is_file():
        raise ParameterError(f"landscape: no window map at {source} (run drake-biped window-map first)")
    try:
        wmap = json.loads(path.read_text())
        rewards = WindowRewards.from_window_map(wmap)
    except (json.JSONDecodeError, KeyError, TypeError) as exc:
        raise ParameterError(f"landscape: {path} is not a window map ({exc})") from None
    starts = [tuple(args.start)] if args.start else [(0.5, 0.5)]
    record = landscape(rewards, args.variance, samples=args.samples, seed=args.seed, starts=starts)
    record.update(window_map=str(path), samples=args.samples, seed=args.seed, versions=versions())
    out = Path(args.out) if args.out else path.parent
    out.mkdir(parents=True, exist_ok=True)
    write_atomic(out / "landscape.json", record)
    landscape_figure(record, out / "landscape.png")
    base = record["no_window_reward"]
    print(f"no window: reward {base:.3f}")
    for cell in record["variances"]:
        s = cell["starts"][0]
        print(f"variance {cell['variance']:g}: best policy mean ({cell['best_mean'][0]:.3f}, {cell['best_mean'][1]:.3f}) "
              f"expected reward {100 * cell['best_gain']:+.1f} % vs no window; at the start {tuple(s['mean'])} "
              f"{100 * s['gain']:+.1f} %")
    print(f"wrote {out}/landscape.json, landscape.png")
    return 0


def _policy_window(path: Path) -> tuple[float, float]:
    """The learned torque-free period of a learning.json (`learning.best_learned_trial`)."""
    from drake_biped.learning import best_learned_trial, read_json

    row = best_learned_trial(read_json(path, "--policy"), f"--policy {path}")
    return max(0.0, float(row["t1"])), max(0.0, float(row["t2"]))


def _chosen_window(args: argparse.Namespace) -> tuple[float, float]:
    """The torque-free period to compare against none: --policy, or --t1/--t2, or 0.2-0.5 s."""
    if args.policy is not None and args.t1 is not None:
        raise ParameterError("give either --policy or --t1/--t2, not both")
    if (args.t1 is None) != (args.t2 is None):
        raise ParameterError("--t1 and --t2 go together: give both or neither")
    if args.policy is not None:
        return _policy_window(Path(args.policy))
    if args.t1 is not None:
        if args.t2 <= args.t1:
            raise ParameterError(f"--t1 {args.t1} --t2 {args.t2}: need t1 < t2")
        return args.t1, args.t2
    return 0.2, 0.5


def _check_cluster_options(args: argparse.Namespace) -> None:
    from drake_biped.parallel import check_scheduler_address

    if args.scheduler is not None:
        check_scheduler_address(args.scheduler)
        if args.workers is not None:
            raise ParameterError("--workers sizes the local cluster; it cannot be combined with --scheduler")


def cmd_stability(args: argparse.Namespace) -> int:
    from analysis.stability_report import write_stability_outputs
    from drake_biped.learning import write_atomic
    from drake_biped.parallel import dask_client
    from drake_biped.stability import StabilitySettings, run_stability

    config = _episode_config(args)
    window = _chosen_window(args)
    _check_cluster_options(args)
    settings = StabilitySettings(window=window, trials=args.trials, push_force_n=args.push,
                                 spread=args.spread, seed=config.seed)
    out = Path(args.out)
    from tqdm import tqdm

    bar = tqdm(total=6 * settings.trials, desc="stability", unit="episode")

    def progress(done: int, total: int) -> None:
        bar.n = done
        bar.refresh()

    try:
        with dask_client(workers=args.workers, scheduler=args.scheduler) as client:
            record = run_stability(out, config, settings, client, progress)
    finally:
        bar.close()  # (the finite-difference Jacobian's 102 episodes follow the cells, without a bar)
    write_atomic(out / "stability.json", record)
    write_stability_outputs(record, out)
    print("\n".join(line for line in (out / "report.md").read_text().splitlines() if line.startswith("|")))
    print(f"wrote {out}/stability.json, fig7_return_map.png, report.md, report.html")
    return 0


def cmd_push_margin(args: argparse.Namespace) -> int:
    from drake_biped.learning import write_atomic
    from drake_biped.parallel import dask_client
    from drake_biped.stability import push_margin
    from drake_biped.versions import versions

    config = _episode_config(args)
    window = _chosen_window(args)
    _check_cluster_options(args)
    code = versions()
    with dask_client(workers=args.workers, scheduler=args.scheduler) as client:
        record = push_margin(config, window, client, max_force_n=args.max_force, tolerance_n=args.tolerance,
                             progress=lambda n: print(f"round {n}", file=sys.stderr))
    record.update(config=config.to_dict(), versions=code)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    write_atomic(out / "push_margin.json", record)
    lines = ["| | forward push survived (N) | backward push survived (N) |", "|---|---|---|"]
    for condition, name in (("without", "without torque-free period"),
                            ("with", f"with torque-free period {window[0]:.3f}-{window[1]:.3f} s")):
        m = record["margins"][condition]
        lines.append(f"| {name} | {m['forward']['survived_n']:.1f} | {m['backward']['survived_n']:.1f} |")
    text = "\n".join(lines) + (f"\n\nPush for {record['push_duration_s']:g} s from {record['push_start_s']:g} s; "
                               f"bisection to {args.tolerance:g} N, up to {args.max_force:g} N.\n")
    (out / "push_margin.md").write_text(text)
    print(text)
    print(f"wrote {out}/push_margin.json, push_margin.md")
    return 0


def cmd_grid(args: argparse.Namespace) -> int:
    from drake_biped.grid import load_spec, run_grid, table_iv_axes
    from drake_biped.learning import RunProgress
    from drake_biped.parallel import dask_client

    config = _episode_config(args)
    _check_cluster_options(args)
    if args.spec is not None and args.points_per_axis is not None:
        raise ParameterError("give either --spec or --points-per-axis, not both")
    axes = load_spec(Path(args.spec)) if args.spec is not None else table_iv_axes(args.points_per_axis or 2)
    out = Path(args.out)
    progress = RunProgress(out, args.workers, args.scheduler, "grid", "point")
    try:
        with dask_client(workers=args.workers, scheduler=args.scheduler) as client:
            record = run_grid(out, config, axes, client, progress)
    finally:
        progress.close()
    progress.log.update(progress.new, finished=True)
    best = record["best"]
    cmt = "n/a" if best["cost_of_transport"] is None else f"{best['cost_of_transport']:.3f}"
    print(f"{record['walked_the_distance']}/{record['points']} points walk {config.sim.distance_m:g} m; best "
          f"{', '.join(f'{k}={v:.4g}' for k, v in best['point'].items())}: {best['distance_m']:.2f} m, C_mt {cmt}")
    print(f"wrote {out}/grid.csv, grid.json, grid_slices.png, best_params.json (use --params)")
    return 0


def cmd_slope(args: argparse.Namespace) -> int:
    from drake_biped.learning import RunProgress
    from drake_biped.parallel import dask_client
    from drake_biped.slope import run_slope, slope_ground, start_from_learning, start_from_window

    if args.slope is None:
        raise ParameterError("--slope is required (rad, > 0: the ascending slope after the level part)")
    level = args.level_length if args.level_length is not None else 2.0
    args.level_length = None  # the slope ground is built below, not by the episode options
    slope, args.slope = args.slope, None
    config = _episode_config(args)
    ground = slope_ground(slope, level, config.ground.friction)
    _check_cluster_options(args)
    if args.policy is not None:
        if args.t1 is not None or args.t2 is not None:
            raise ParameterError("give either --policy or --t1/--t2, not both")
        state, source = start_from_learning(Path(args.policy))
    else:
        state, source = start_from_window(*_chosen_window(args), args.variance)
    out = Path(args.out)
    progress = RunProgress(out, args.workers, args.scheduler, "slope learning", "episode")
    try:
        with dask_client(workers=args.workers, scheduler=args.scheduler) as client:
            run_slope(out, config, ground, state, source, args.trials, args.episodes, config.seed,
                      client, progress)
    finally:
        progress.close()
    progress.log.update(progress.new, finished=True)
    print((out / "report.md").read_text())
    print(f"wrote {out}/slope.json, report.md, fig8_period.png, fig9_distance.png")
    return 0


def cmd_reproduce(args: argparse.Namespace) -> int:
    from drake_biped.reproduce import FULL, QUICK, Reproduction, check_out

    _check_cluster_options(args)
    profile = QUICK if args.quick else FULL
    out = Path(args.out)
    check_out(out, profile)
    hours = profile.expected_minutes / 60
    print(f"reproduce ({profile.name}): {len(Reproduction.STEPS)} experiments into {out}/, expected about "
          + (f"{profile.expected_minutes:.0f} min" if hours < 1.5 else f"{hours:.1f} h")
          + " on 2 cores; interrupt at any time and rerun the same command to resume", flush=True)
    Reproduction(out, profile, args.workers, args.scheduler).run_all()
    print("\n".join(line for line in (out / "report.md").read_text().splitlines()[:40] if line.startswith("|")))
    print(f"wrote {out}/report.md, report.html")
    return 0


def _steps(text: str) -> list[float]:
    parse = _number("positive")
    return [parse(t) for t in text.split(",")]


def _add_window_options(p: argparse.ArgumentParser) -> None:
    p.add_argument("--t1", type=_number("nonnegative"), help="torque-free start (s); default 0.2")
    p.add_argument("--t2", type=_number("positive"), help="torque-free end (s); default 0.5")
    p.add_argument("--policy", default=None, help="a learning.json: use its best learned torque-free period "
                   "(the trial with a window and the lowest C_mt)")


def _add_cluster_options(p: argparse.ArgumentParser) -> None:
    p.add_argument("--workers", type=_count, default=None, help="local Dask workers (default: one per core)")
    p.add_argument("--scheduler", default=None, help="use a running Dask scheduler, e.g. tcp://HOST:8786")


def _add_resumable_run_options(p: argparse.ArgumentParser) -> None:
    """The cluster options and --out of a command that resumes when rerun."""
    _add_cluster_options(p)
    p.add_argument("--out", required=True, help="output folder (rerun the same command to resume)")


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="drake-biped", description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)

    walk = sub.add_parser("walk", help="walk one episode and write its record, figures and animation")
    _add_episode_options(walk)
    walk.add_argument("--t1", type=_number("nonnegative"), help="torque-free start after each step start (s)")
    walk.add_argument("--t2", type=_number("nonnegative"), help="torque-free end (s); t2 <= t1: no window")
    walk.add_argument("--push", type=_number("finite"), help="horizontal push on the torso (N, + forward)")
    walk.add_argument("--push-start", type=_number("nonnegative"), default=0.4, help="push start (s); default 0.4")
    walk.add_argument("--push-duration", type=_number("positive"), default=0.1, help="push duration (s); default 0.1")
    walk.add_argument("--save-trajectory", action="store_true", help="also write trajectory.npz")
    walk.add_argument("--no-animation", action="store_true", help="skip walk.html and walk.gif")
    walk.add_argument("--out", required=True, help="output folder")
    walk.set_defaults(func=cmd_walk)

    wmap = sub.add_parser("window-map", help="C_mt of a grid of torque-free windows against no window")
    _add_episode_options(wmap)
    wmap.add_argument("--step", type=_number("positive"), default=0.1, help="grid spacing of t1 and t2 (s)")
    wmap.add_argument("--t1-max", type=_number("nonnegative"), default=0.6, help="largest start t1 (s); default 0.6")
    wmap.add_argument("--t2-max", type=_number("positive"), default=0.9, help="largest end t2 (s); default 0.9")
    wmap.add_argument("--workers", type=_count, default=2, help="parallel processes (default 2)")
    wmap.add_argument("--out", required=True, help="output folder")
    wmap.set_defaults(func=cmd_window_map)

    search = sub.add_parser("gait-search", help="evolve gait parameters for walking and torque-free savings")
    _add_episode_options(search)
    search.add_argument("--generations", type=_count, default=50, help="generations (default 50)")
    search.add_argument("--offspring", type=_count, default=4, help="children per generation (default 4)")
    search.add_argument("--sigma", type=_number("positive"), default=0.1, help="mutation scale (default 0.1)")
    search.add_argument("--workers", type=_count, default=2, help="parallel processes (default 2)")
    search.add_argument("--out", required=True, help="output folder (rerun to resume)")
    search.set_defaults(func=cmd_gait_search)

    ts = sub.add_parser("time-step-study", help="C_mt, speed and step period against the time step; the default")
    ts.add_argument("--steps", type=_steps, default=[0.00025, 0.0005, 0.001, 0.002, 0.005],
                    help="time steps (s), comma-separated (default 0.00025,0.0005,0.001,0.002,0.005)")
    ts.add_argument("--reference", type=_number("positive"), default=0.0005, help="reference step (s), one of --steps")
    ts.add_argument("--distance", type=_number("positive"), default=10.0, help="walk this far (m); default 10")
    _add_cluster_options(ts)
    ts.add_argument("--replot", action="store_true", help="redraw the table and figure from OUT's JSON")
    ts.add_argument("--out", required=True, help="output folder")
    ts.set_defaults(func=cmd_time_step_study)

    learn = sub.add_parser("learn", help="GARB learning of the torque-free period (Experiment 1), on Dask")
    _add_episode_options(learn)
    learn.add_argument("--trials", type=_count, default=5, help="independent trials (default 5)")
    learn.add_argument("--episodes", type=_count, default=500, help="episodes per trial (default 500)")
    learn.add_argument("--initial-mean", type=_number("nonnegative"), nargs=2, default=[0.5, 0.5],
                       metavar=("T1", "T2"), help="the policy's starting mean (s); default 0.5 0.5 as in the paper")
    learn.add_argument("--variance", type=_number("positive"), default=0.04,
                       help="the policy's variance per time (s^2); default 0.04 as in the paper")
    _add_resumable_run_options(learn)
    learn.set_defaults(func=cmd_learn)

    land = sub.add_parser("landscape", help="the expected reward GARB climbs, from a window map, for given variances")
    land.add_argument("window_map", help="a window-map output folder or its window_map.json")
    land.add_argument("--variance", type=_steps, default=[0.04, 0.01, 0.0025],
                      help="policy variances (s^2), comma-separated; default 0.04,0.01,0.0025")
    land.add_argument("--start", type=_number("nonnegative"), nargs=2, metavar=("T1", "T2"),
                      help="a policy start to evaluate (default 0.5 0.5)")
    land.add_argument("--samples", type=_count, default=2000, help="Monte Carlo samples per mean (default 2000)")
    land.add_argument("--seed", type=_seed, default=0, help="random seed (default 0)")
    land.add_argument("--out", default=None, help="output folder (default: the window map's)")
    land.set_defaults(func=cmd_landscape)

    stab = sub.add_parser("stability", help="pushes and Poincare return maps with and without a torque-free "
                          "period (Table VI, Fig. 7), on Dask")
    _add_episode_options(stab)
    _add_window_options(stab)
    stab.add_argument("--trials", type=_count, default=8, help="trials per cell (default 8)")
    stab.add_argument("--push", type=_number("positive"), default=20.0, help="push force (N); default 20")
    stab.add_argument("--spread", type=_number("nonnegative"), default=0.15,
                      help="trials' initial hip angle and speed within +-this fraction (default 0.15)")
    _add_resumable_run_options(stab)
    stab.set_defaults(func=cmd_stability)

    pm = sub.add_parser("push-margin", help="the largest forward and backward push the gait survives, "
                        "with and without a torque-free period (bisection, on Dask)")
    _add_episode_options(pm)
    _add_window_options(pm)
    pm.add_argument("--max-force", type=_number("positive"), default=200.0, help="largest push tried (N); default 200")
    pm.add_argument("--tolerance", type=_number("positive"), default=1.0, help="bisection tolerance (N); default 1")
    _add_cluster_options(pm)
    pm.add_argument("--out", required=True, help="output folder")
    pm.set_defaults(func=cmd_push_margin)

    grid = sub.add_parser("grid", help="grid search of CPG parameters and the initiation (Table IV), on Dask")
    _add_episode_options(grid)
    grid.add_argument("--points-per-axis", type=_count, default=None,
                      help="points per range (cell centres) of Table IV's five CPG parameters and the "
                      "initial hip angle (0-15.2 deg) and speed (0-0.35 m/s); default 2 (128 points)")
    grid.add_argument("--spec", default=None, help="a YAML grid spec: axes: {name: {min, max, points} | "
                      "{values: [...]}}; see grids/")
    _add_resumable_run_options(grid)
    grid.set_defaults(func=cmd_grid)

    sl = sub.add_parser("slope", help="slope adaptation: does the learned torque-free period climb, does none, "
                        "and does online GARB learning adapt it (Figs. 8-11), on Dask")
    _add_episode_options(sl)
    _add_window_options(sl)
    sl.add_argument("--variance", type=_number("positive"), default=0.04,
                    help="the policy's variance (s^2) when starting from --t1/--t2; default 0.04 as in the paper "
                    "(--policy carries its own)")
    sl.add_argument("--episodes", type=_count, default=100, help="learning episodes per trial (default 100)")
    sl.add_argument("--trials", type=_count, default=2, help="independent learning trials (default 2)")
    _add_resumable_run_options(sl)
    sl.set_defaults(func=cmd_slope)

    rep = sub.add_parser("reproduce", help="every experiment of the paper and one report beside its numbers "
                         "(--quick: small settings, minutes)")
    rep.add_argument("--quick", action="store_true", help="small settings: the same report in minutes")
    _add_resumable_run_options(rep)
    rep.set_defaults(func=cmd_reproduce)

    figs = sub.add_parser("figures", help="redraw a learning run's figures and Table V from its records")
    figs.add_argument("dir", help="the learning run's output folder")
    figs.set_defaults(func=cmd_figures)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return args.func(args)
    except ParameterError as exc:
        parser.exit(2, f"drake-biped {args.command}: error: {exc}\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
