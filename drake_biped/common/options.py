"""The options the commands share and the types that check them, for `drake_biped.cli` and the experiments'
own command-line parts: every numeric option validated at the boundary with a message that names the option
and the value; the episode options that build an EpisodeConfig; the window options; the cluster options."""

from __future__ import annotations

import argparse
import dataclasses
import math
import os
import sys
from contextlib import contextmanager
from pathlib import Path

from drake_biped.params import (
    EpisodeConfig,
    ParameterError,
    SimulationParams,
    check_declared,
    check_window_given,
    with_time_step,
)
from drake_biped.resources import gait_identity, gait_names, gait_text, load_gait

# The sizes a run may be given, bounded before any work (`check_size`, `check_memory`). A run beyond a count
# limit is refused unless forced (--force, force=True); one whose memory estimate exceeds half this machine's
# memory is refused even then: it would be killed, leaving its folder locked.
MAX_EPISODES = 100_000  # learning episodes of one run (trials x episodes, over every learner): ~8 h at 200/min
MAX_WALKS = 2_000  # the walks of one analysis (stability cells, time-step study, ...)
MAX_CANDIDATES = 2_000  # gait-search candidates (generations x offspring)
EPISODE_RECORD_BYTES = 8_192  # what one episode's kept record holds in memory, at most (its touchdown rows)


def check_size(what: str, count: int, limit: int, unit: str, force: bool | None = False,
               advice: str = "give fewer") -> None:
    """ParameterError naming `what` (the options and values that set the size) when `count` `unit` exceed
    `limit`, unless `force` (None: a limit that nothing lifts): one line, before any work."""
    if count > limit and not force:
        lift = "" if force is None else ", or give --force (force=True) to run it anyway"
        raise ParameterError(f"{what}: {count:,} {unit}, more than the limit of {limit:,}; {advice}{lift}")


def machine_memory_bytes() -> int:
    """This machine's physical memory (bytes)."""
    try:
        return int(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    except (ValueError, OSError, AttributeError):
        return 8 << 30


def check_memory(what: str, nbytes: float, advice: str = "give fewer") -> None:
    """ParameterError naming `what` when its memory estimate `nbytes` exceeds half this machine's memory,
    --force or not."""
    limit = machine_memory_bytes() / 2
    if nbytes > limit:
        raise ParameterError(f"{what}: would hold about {nbytes / 2**30:,.1f} GiB in memory, more than half of "
                             f"this machine's {2 * limit / 2**30:.0f} GiB; {advice}")


def check_learning_size(what: str, episodes: int, force: bool = False) -> None:
    """A learning run of `episodes` episodes in all, bounded before any work: MAX_EPISODES unless `force`, and
    what its records hold in memory, always."""
    check_size(what, episodes, MAX_EPISODES, "episodes", force)
    check_memory(what, episodes * EPISODE_RECORD_BYTES)


def check_walks(what: str, walks: int, force: bool = False, advice: str = "give fewer") -> None:
    """An analysis of `walks` walks, bounded before any work: MAX_WALKS unless `force`, and what their records
    hold in memory, always."""
    check_size(what, walks, MAX_WALKS, "walks", force, advice)
    check_memory(what, walks * EPISODE_RECORD_BYTES, advice)


def check_reaches_touchdown(config: EpisodeConfig, touchdown: int, why: str) -> None:
    """ParameterError naming --distance, before any walk, when `config`'s walks may end before touchdown
    `touchdown` (counted from 0) whatever the gait: shorter than that many of the robot's longest steps
    (`kinematics.longest_step_m`) and a leg. `why`: what needs that touchdown."""
    from drake_biped.kinematics import leg_length_m, longest_step_m
    from drake_biped.model import body_of_model

    body = body_of_model(config.model)
    step = longest_step_m(body)
    need = (touchdown + 1) * step + leg_length_m(body)
    if config.sim.distance_m < need:
        raise ParameterError(f"--distance {config.sim.distance_m:g}: {why} needs touchdown {touchdown}, which a walk "
                             f"shorter than {need:.1f} m may not reach (a step of this robot is at most {step:.2f} m); "
                             f"walk at least {math.ceil(need):g} m")


def why_unchanged(config: EpisodeConfig, name: str, values) -> str:
    """Why every value in `values` of the field `name`, set alone in `config`, walks the same episode
    (`EpisodeConfig.as_walked`), in words for a refusal: the reason that holds, not a list of guesses."""
    from drake_biped.params import resolve_field

    section, attr = resolve_field(name)
    configs = [config.override({name: float(v)}, sampled=True) for v in values]
    if section == "gait" and attr in config.gait.unread():
        g = config.gait
        reading = (f"phase reading {g.phase_reading!r}" if attr in g.UNREAD_BY_ENTRAINED
                   and g.phase_reading == "entrained" else f"hip drive {g.hip_drive!r}")
        return f"gait.{attr} is unread under this gait's {reading} (GaitParams.unread): no walk reads it"
    if section == "window" and not any(c.window.active for c in configs):
        return "the torque-free window never opens at any value (t2 <= t1 at each): every walk is the one without"
    if section == "ground" and attr == "level_length_m" and all(c.ground.slope_rad == 0.0 for c in configs):
        return "a level stretch on level ground is no change of ground"
    if section == "push" and all(c.as_walked().push is None for c in configs):
        return "the push never acts (no force, no duration, or it starts after the walk's time limit)"
    return "every value walks the same episode (EpisodeConfig.as_walked)"


def number(kind: str):
    """An option's type: a finite number, and for `kind` "positive" > 0, "nonnegative" >= 0 ("finite": any);
    argparse reports a refusal as one line naming the option and the value."""

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


def integer(minimum: int):
    """An option's type: an integer >= `minimum`."""

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


def out_folder(text: str) -> Path:
    """--out: a folder that exists or can be made, and can be written; refused by name otherwise."""
    if not text.strip():
        raise argparse.ArgumentTypeError("an empty path; name a folder (it is made if missing)")
    path = Path(text)
    if path.exists() and not path.is_dir():
        raise argparse.ArgumentTypeError(f"{text!r} is a file, not a folder")
    new = [p for p in (path, *path.parents) if not p.exists()]
    MADE.extend(reversed(new))  # removed again, if still empty, when the command refuses its input
    try:
        check_writable(path, repr(text))
    except ParameterError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None
    return path


def check_writable(folder: Path, what: str) -> None:
    """ParameterError naming `what` (the option and the folder) unless `folder` exists or can be made, and a file can be written in it:
    asked before any work by every command that writes (--out is checked so as it is parsed; a command that
    writes elsewhere, beside a record it reads, asks this of that folder)."""
    try:
        folder.mkdir(parents=True, exist_ok=True)
        probe = folder / ".drake-biped-write-test"
        probe.write_text("")
        probe.unlink()
    except OSError as exc:
        raise ParameterError(f"{what}: cannot write there ({exc.strerror or exc})") from None


MADE: list[Path] = []  # folders --out made in this invocation
seed_type = integer(0)
count = integer(1)


def add_episode_options(p: argparse.ArgumentParser, slope_command: bool = False) -> None:
    p.add_argument("--params", help=f"a shipped gait by name ({', '.join(gait_names())}) or a JSON file of "
                   "EpisodeConfig fields (cpg, gait, initial, ...) or a result.json")
    p.add_argument("--distance", type=number("positive"), help="walk this far (m) (default: 10, or the --params file's)")
    p.add_argument("--max-time", type=number("positive"),
                   help="simulated time limit (s) (default: 60, or 6 s per metre of --distance if longer)")
    p.add_argument("--time-step", type=number("positive"),
                   help="plant time step (s) (default: 0.001); the controller acts at every step (the paper's "
                        "clock) unless --control-period fixes its rate")
    add_clock_option(p)
    if slope_command:
        p.add_argument("--slope", type=number("finite"), required=True,
                       help="the ascending slope after the level part (rad, > 0)")
        p.add_argument("--level-length", type=number("nonnegative"), default=2.0,
                       help="level ground before the slope (m)")
    else:
        p.add_argument("--slope", type=number("finite"), help="ground slope (rad, > 0 ascends) (default: 0, level)")
        p.add_argument("--level-length", type=number("nonnegative"),
                       help="level ground for this many metres, then the slope (default: none, the slope everywhere)")
    p.add_argument("--seed", type=seed_type, default=None, help="recorded with the result (default: 0)")
    add_model_option(p)


def add_clock_option(p: argparse.ArgumentParser) -> None:
    p.add_argument("--control-period", type=number("positive"),
                   help="the controller as a fixed-rate loop of this period (s), a whole multiple of the plant "
                        "step: a robot whose loop runs at 1/PERIOD Hz (default: the controller acts at every plant "
                        "step, as the paper's ODE motors do, or the --params file's clock)")


def with_clock(config: EpisodeConfig, time_step_s: float | None, control_period_s: float | None) -> EpisodeConfig:
    """`config` at the --time-step and with the --control-period given (None: kept), checked together and named
    by option: a fixed-rate loop must be a whole multiple of the plant step; each value within its field's
    declaration."""
    if control_period_s is not None:
        check_declared(SimulationParams, "control_period_s", control_period_s, f"--control-period {control_period_s:g}")
        step = config.sim.time_step_s if time_step_s is None else time_step_s
        ratio = control_period_s / step
        if abs(ratio - round(ratio)) > 1e-6 or round(ratio) < 1:
            raise ParameterError(f"--control-period {control_period_s!r}: not a whole multiple of the plant step "
                                 f"{step!r} s")
        try:
            config = config.replace(sim=dataclasses.replace(config.sim, time_step_s=step,
                                                            control_period_s=control_period_s))
        except ParameterError as exc:
            given = f"--control-period {control_period_s:g}" + ("" if time_step_s is None else
                                                                f" --time-step {time_step_s:g}")
            raise ParameterError(f"{given}: {exc}") from None
    if time_step_s is not None:
        try:
            config = config.replace(sim=with_time_step(config.sim, time_step_s, "--time-step"))
        except ParameterError as exc:
            text = str(exc)
            raise ParameterError(text if text.startswith("--time-step") else
                                 f"--time-step {time_step_s:g}: {text}") from None
    return config


def add_model_option(p: argparse.ArgumentParser) -> None:
    p.add_argument("--model", help="the robot: a URDF or SDFormat file with the shipped model's link and joint "
                   "names (default: the shipped biped, or the --params file's); its content travels with the "
                   "episodes and result.json records its name and SHA-256")


def with_model(config: EpisodeConfig, model_file: str | None) -> EpisodeConfig:
    """`config` with the --model file's robot, checked (parsed and its body read) before any work starts."""
    from drake_biped.model import body_of_model
    from drake_biped.params import RobotModel

    if model_file is not None:
        config = config.replace(model=RobotModel.from_file(model_file))
    if config.model is not None:
        body_of_model(config.model)  # ModelError: one line, exit 2
    return config


# The longest plant step at which the default gait's long-run C_mt without a window stays within 1 % of the
# finest step's (the time-step study, docs/RESULTS.md): 2 ms is 2.4 % off. The full run's learned window, whose
# gait is chaotic, is 3.8 % low already at 1 ms (its saving 1.7 points high); docs/RESULTS.md says why 1 ms stays.
CONVERGED_TIME_STEP_S = 0.001


def episode_config(args: argparse.Namespace) -> EpisodeConfig:
    config = EpisodeConfig() if args.params is None else load_gait(args.params)
    changes: dict[str, float] = {}
    given: list[str] = []  # the options, as a refusal names them: each value is checked by its field's declaration
    if args.distance is not None:
        changes["sim.distance_m"] = args.distance
        changes["sim.max_time_s"] = max(config.sim.max_time_s, 6.0 * args.distance)
        given.append(f"--distance {args.distance:g}")
    if args.max_time is not None:
        changes["sim.max_time_s"] = args.max_time
        given.append(f"--max-time {args.max_time:g}")
    if args.slope is not None:
        changes["ground.slope_rad"] = args.slope
        given.append(f"--slope {args.slope:g}")
    if args.level_length is not None:
        changes["ground.level_length_m"] = args.level_length
        given.append(f"--level-length {args.level_length:g}")
    try:
        config = config.override(changes)
    except ParameterError as exc:
        raise ParameterError(f"{' '.join(given)}: {exc}") from None
    config = with_clock(config, args.time_step, args.control_period)
    config = with_model(config, args.model)
    if args.time_step is not None and args.time_step > CONVERGED_TIME_STEP_S:  # accepted, but say what it means
        print(f"warning: --time-step {args.time_step:g} is above {1e3 * CONVERGED_TIME_STEP_S:g} ms, coarser than "
              "any shipped gait's step and than the steps at which their walks converge (docs/RESULTS.md, 'Physics "
              "with a continuous limit', 'Its plant step, refined past 0.25 ms'); from 5 ms the control loop "
              "diverges, which ends an episode as 'diverged'", file=sys.stderr)
    config = config if args.seed is None else config.replace(seed=args.seed)
    print(gait_line(config))
    return config


def gait_line(config: EpisodeConfig) -> str:
    """The line every command that walks a gait prints before its work: which gait (its shipped name, or
    "another gait", and the SHA-256 of its CPG, gains and initiation) at which plant step."""
    return f"gait: {gait_text(gait_identity(config))}, plant step {1e3 * config.sim.time_step_s:g} ms"


@contextmanager
def cluster(args: argparse.Namespace):
    """The Dask client of the cluster options: --scheduler ADDR, or a LocalCluster of --workers N."""
    from drake_biped.common.executor import dask_client

    with dask_client(workers=args.workers, scheduler=args.scheduler,
                     force=args.force) as client:  # it checks the options first
        yield client


def run_command(args: argparse.Namespace, settings_from_args, run) -> dict:
    """A command's run: its settings read from `args` (bad input refused before any cluster starts), then
    `run(settings, out, client)` on the cluster the options name, writing under --out; the record."""
    settings = settings_from_args(args)
    with cluster(args) as client:
        return run(settings, Path(args.out), client)


def print_lines(lines) -> None:
    print("\n".join(lines))


def policy_window(path: Path) -> tuple[float, float]:
    """The learned torque-free period of a learning.json (`learning_record.best_learned_trial`)."""
    from drake_biped.common.learning_record import best_learned_trial
    from drake_biped.records import read_json

    row = best_learned_trial(read_json(path, "--policy"), f"--policy {path}")
    return max(0.0, float(row["t1"])), max(0.0, float(row["t2"]))


def default_window(config: EpisodeConfig, params: str | None = None) -> tuple[tuple[float, float], str]:
    """The window a command compares with none when none is given, and where it comes from: the gait's own
    where it carries one, else the one its gait file declares (`resources.gait_compare_window`; `params`: the
    --params given, None for the default, the paper's walker). ParameterError naming --params where the gait declares none:
    another gait's window is no comparison for it, so the command needs --t1 and --t2 (or --policy)."""
    from drake_biped.resources import gait_compare_window

    w = config.window
    if w.active:
        return (w.start_s, w.end_s), "the gait's own window (its window section)"
    name = "paper" if params is None else params
    declared = gait_compare_window(name)
    if declared is None:
        raise ParameterError(f"--params {name}: the gait declares no window to compare with none (its own never "
                             "opens and its file has no compare_window); give one with --t1 and --t2, or --policy")
    window, source = declared
    return window, f"{source} (gait file {name})"


def chosen_window_and_source(args: argparse.Namespace,
                             config: EpisodeConfig | None = None) -> tuple[tuple[float, float], str]:
    """The torque-free period to compare against none and where it comes from: --policy, or --t1/--t2, or
    `default_window` of the gait (`config`, of --params)."""
    if args.policy is not None and args.t1 is not None:
        raise ParameterError("give either --policy or --t1/--t2, not both")
    if (args.t1 is None) != (args.t2 is None):
        raise ParameterError("--t1 and --t2 go together: give both or neither")
    if args.policy is not None:
        return policy_window(Path(args.policy)), f"--policy {args.policy} (its best learned trial)"
    if args.t1 is not None:
        check_window_given(args.t1, args.t2, ("--t1", "--t2"))
        return (args.t1, args.t2), "--t1/--t2"
    return default_window(config if config is not None else EpisodeConfig(), getattr(args, "params", None))


def chosen_window(args: argparse.Namespace, config: EpisodeConfig | None = None) -> tuple[float, float]:
    """The torque-free period to compare against none (`chosen_window_and_source`)."""
    return chosen_window_and_source(args, config)[0]


def window_line(window: tuple[float, float], source: str) -> str:
    """The line a command prints of the window it compares with none: its ends and where it comes from."""
    return f"window {window[0]:g}-{window[1]:g} s: {source}"


def steps(text: str) -> list[float]:
    parse = number("positive")
    return [parse(t) for t in text.split(",")]


def windows(text: str) -> list[tuple[float, float]]:
    """An option's type: torque-free windows T1-T2 (s), comma-separated, each with 0 <= T1 < T2."""
    parse = number("nonnegative")
    out = []
    for t in text.split(","):
        ends = t.split("-")
        if len(ends) != 2:
            raise argparse.ArgumentTypeError(f"{t!r}: a window is T1-T2 in seconds, e.g. 0.3-0.7")
        t1, t2 = parse(ends[0]), parse(ends[1])
        if t2 <= t1:
            raise argparse.ArgumentTypeError(f"{t!r}: T2 <= T1 is no window; give T1 < T2, e.g. 0.3-0.7")
        out.append((t1, t2))
    return out


def learner_names(text: str) -> list[str]:
    from drake_biped.learners.registry import LEARNERS

    names = [t.strip() for t in text.split(",")]
    unknown = [n for n in names if n not in LEARNERS]
    if unknown or not names or len(set(names)) != len(names):
        raise argparse.ArgumentTypeError(f"{text!r}: a comma-separated list of distinct learners from "
                                         f"{sorted(LEARNERS)}")
    return names


def positive_list(text: str) -> list[float]:
    try:
        values = [float(t) for t in text.split(",")]
    except ValueError:
        values = []
    if len(values) < 3 or not all(math.isfinite(v) and v > 0 for v in values):
        raise argparse.ArgumentTypeError(f"{text!r}: at least three positive numbers, comma-separated")
    return values


# What a command walks when neither --t1/--t2 nor --policy is given (`add_window_options`).
WINDOW_DEFAULTS = {
    "learned": "the gait's own window, else the one its gait file declares (compare_window; the default gait's: "
               "its learned 0.3672-0.8629 s); a gait that declares none needs --t1/--t2",
    "gait": "the gait's own window (none when it has none)",
    "none": "no window",
}


def add_window_options(p: argparse.ArgumentParser, default: str = "learned", policy: bool = True) -> None:
    """The torque-free window's options, declared once for every command: --t1 and --t2 (s after each step's
    start), and --policy (a learning run's best learned window) where the command takes one; `default` names
    what is walked without them (WINDOW_DEFAULTS)."""
    p.add_argument("--t1", type=number("nonnegative"),
                   help=f"torque-free start after each step's start (s), with --t2; default: {WINDOW_DEFAULTS[default]}")
    p.add_argument("--t2", type=number("positive"), help="torque-free end (s), after --t1")
    if policy:
        p.add_argument("--policy", default=None, help="a learning.json: use its best learned torque-free period "
                       "(the trial with a window and the lowest C_mt)")


def add_cluster_options(p: argparse.ArgumentParser) -> None:
    from drake_biped.common.executor import MAX_LOCAL_WORKERS_PER_CORE

    p.add_argument("--workers", type=count, default=None,
                   help=f"local Dask workers (default: one per core; at most {MAX_LOCAL_WORKERS_PER_CORE} per core "
                   "without --force)")
    p.add_argument("--scheduler", default=None, help="use a running Dask scheduler, e.g. tcp://HOST:8786")
    p.add_argument("--force", action="store_true",
                   help="run what is refused as beyond this machine: more --workers than its limit, a grid "
                   "over its point limit, a push-margin map over its episode limit")


def add_resumable_run_options(p: argparse.ArgumentParser) -> None:
    """The cluster options and --out of a command that resumes when rerun."""
    add_cluster_options(p)
    p.add_argument("--out", required=True, type=out_folder, help="output folder (rerun the same command to resume)")
