"""One walk and every file it writes: its record, the Drake diagram as DOT/SVG/PNG, a standalone Meshcat HTML
recording, the walk figure and GIF (`run` writes them all; `drake-biped walk` is this module)."""

from __future__ import annotations

import argparse
import logging
import shutil
import subprocess
import sys
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from pydrake.math import RigidTransform
from pydrake.systems.framework import Diagram

from drake_biped.analysis.cost_of_transport import format_cost, format_cost_interval
from drake_biped.common.options import (
    add_episode_options,
    add_window_options,
    episode_config,
    number,
    out_folder,
    print_lines,
)
from drake_biped.legacy import config_of_record
from drake_biped.params import (
    TOTAL_MASS_KG,
    EpisodeConfig,
    ParameterError,
    Push,
    TorqueFreeWindow,
    check_settings,
    check_window_given,
    walked_the_distance,
)
from drake_biped.records import read_kept, warn, write_atomic, write_text_atomic


class GraphvizMissingError(RuntimeError):
    """The Graphviz `dot` program is not installed."""


def export_diagram(diagram: Diagram, out_dir: Path, stem: str = "diagram", max_depth: int = 2) -> list[Path]:
    """Write `stem`.dot always, and `stem`.svg / `stem`.png through Graphviz `dot`.

    Raises GraphvizMissingError (after writing the .dot file) when `dot` is not on PATH."""
    out_dir = Path(out_dir)
    dot_path = out_dir / f"{stem}.dot"
    write_text_atomic(dot_path, diagram.GetGraphvizString(max_depth=max_depth))
    dot = shutil.which("dot")
    if dot is None:
        raise GraphvizMissingError(
            f"Graphviz 'dot' is not installed, so {stem}.svg/.png were not drawn ({dot_path} was written). "
            "Install it (Debian/Ubuntu: apt-get install graphviz) and run again."
        )
    written = [dot_path]
    for fmt in ("svg", "png"):
        path = out_dir / f"{stem}.{fmt}"
        subprocess.run([dot, f"-T{fmt}", str(dot_path), "-o", str(path)], check=True, timeout=60)
        written.append(path)
    return written


class _DropMeshcatAddress(logging.Filter):
    """Drake's "Meshcat listening for connections at http://..." line: the server lives only while the walk
    records, so its address is gone when the command ends; the saved walk.html is what to open."""

    def filter(self, record: logging.LogRecord) -> bool:
        return not record.getMessage().startswith("Meshcat listening for connections at")


def start_meshcat():
    """A headless Meshcat server on a loopback port (7000 upward), used only to record the walk: its
    address is not announced (see _DropMeshcatAddress)."""
    from pydrake.geometry import Meshcat, MeshcatParams

    params = MeshcatParams()
    params.host = "localhost"
    drop = _DropMeshcatAddress()
    logger = logging.getLogger("drake")
    logger.addFilter(drop)
    try:
        return Meshcat(params)
    finally:
        logger.removeFilter(drop)


def animation_lines(out: Path) -> list[str]:
    """Where the saved animation is (the Meshcat server that recorded it ends with the walk)."""
    return [f"animation: {Path(out) / 'walk.html'} (a standalone Meshcat recording: open it in a browser, no server "
            f"needed) and {Path(out) / 'walk.gif'}"]


# The recording's camera: this far in front of the walker's sagittal plane (m), this high, looking at the hip
# height: the robot fills about a third of the window's height.
CAMERA_DISTANCE_M = 2.2
CAMERA_HEIGHT_M = 0.55
CAMERA_TARGET_Z_M = 0.45


def write_meshcat_html(meshcat, path: Path, follow: tuple[np.ndarray, np.ndarray] | None = None,
                       ground_height=None) -> None:
    """Publish the recording and save Meshcat's self-contained HTML page.

    follow: (times (s), x (m)) of the walker. The camera then looks at it from the side while the scene (the
    robot and its ground) is shifted back by the walker's progress in every frame of the recording, as on a
    treadmill: the robot stays in view at a readable size over the whole walk, whatever its length (press
    play under "Open Controls" > Animations to replay it; the fixed grid is hidden, the ground moves).
    ground_height(x): the ground's height under the walker (default level)."""
    if follow is not None:
        times, xs = (np.asarray(a, dtype=float) for a in follow)
        recording = meshcat.get_mutable_recording()
        fps = recording.frames_per_second()
        z_of = ground_height or (lambda x: 0.0)
        for frame in range(int(np.floor(times[-1] * fps)) + 1):
            x = float(np.interp(frame / fps, times, xs))
            recording.SetTransform(frame, "/drake", RigidTransform([-x, 0.0, -z_of(x)]))
        x0 = float(xs[0])
        meshcat.SetTransform("/drake", RigidTransform([-x0, 0.0, -z_of(x0)]))
        meshcat.SetProperty("/Grid", "visible", False)
        meshcat.SetProperty("/Axes", "visible", False)
        meshcat.SetCameraPose(np.array([0.0, -CAMERA_DISTANCE_M, CAMERA_HEIGHT_M]),
                              np.array([0.0, 0.0, CAMERA_TARGET_Z_M]))
    meshcat.StopRecording()
    meshcat.PublishRecording()
    write_text_atomic(Path(path), meshcat.StaticHtml())


@dataclass(frozen=True)
class WalkSettings:
    """The episode, and which of the optional files to write."""

    config: EpisodeConfig = field(default_factory=EpisodeConfig)
    animation: bool = True  # walk.html (Meshcat recording) and walk.gif
    save_trajectory: bool = False  # trajectory.npz


def run(settings: WalkSettings, out: Path, client=None, progress: bool = True):
    """Walk one episode (in this process: Meshcat records it; `client` is not used) and write its files into
    `out` (see `write_walk`), with a progress bar in metres. The EpisodeResult."""
    check_settings(settings, WalkSettings, "walk.run")
    update, bars = None, []
    if progress:
        from tqdm import tqdm

        total = settings.config.sim.distance_m

        def update(t: float, d: float) -> None:
            if not bars:  # the bar starts with the walk, once the model is built
                bars.append(tqdm(total=round(total, 2), desc="walk", unit="m",
                                 bar_format="{l_bar}{bar}| {n:.2f}/{total:.2f} m [{elapsed}<{remaining}{postfix}]"))
            bar = bars[0]
            bar.n = round(min(max(d, 0.0), total), 2)
            bar.set_postfix_str(f"t={t:.1f}s", refresh=False)
            bar.refresh()

    try:
        return write_walk(settings.config, out, animation=settings.animation,
                          save_trajectory=settings.save_trajectory, progress=update)
    finally:
        for bar in bars:
            bar.close()


def summary_lines(result) -> list[str]:
    """What `drake-biped walk` prints after its walk (the gait and the plant step are named before it,
    `options.gait_line`): how the walk ended, its steps, its energy, its speed of simulation."""
    status = ((f"DIVERGED ({result.fall_reason})" if result.termination == "diverged" else f"FELL ({result.fall_reason})")
              if result.fell else f"ended: {result.termination}")
    cmt, cmt_kg = format_cost(result.cost_of_transport), format_cost(result.cost_of_transport_per_kg)
    if result.step_period_s is None or result.step_length_m is None:  # they need three touchdowns
        gait = "too few for a step period and length (3 touchdowns needed)"
    else:
        gait = f"step {result.step_period_s:.3f} s / {result.step_length_m:.3f} m"
    return [
        f"{status}: {result.distance_m:.2f} m in {result.duration_s:.2f} s ({result.mean_speed_mps:.3f} m/s), "
        f"{len(result.steps)} steps, {gait}",
        f"positive work {result.total_positive_work_j:.1f} J, C_mt {cmt} (E+/(m g d)), "
        f"{cmt_kg} J/(kg m) (paper's eq. 1)",
        *long_run_lines(result),
        f"wall {result.wall_time_s:.1f} s, real-time factor {result.real_time_factor:.2f}",
    ]


# A model whose total mass is more than this factor from Table I's (heavier or lighter) is noted after its walk:
# C_mt = E+/(m g d) divides by the model's own mass while the motors' work changes little with it, so a C_mt far
# from the shipped robot's is then the mass's doing (docs/MODEL.md, "A robot of your own").
MASS_NOTE_FACTOR = 2.0


def mass_note(mass_kg: float) -> str | None:
    """The note `walk` prints on standard error when the model's total mass is more than MASS_NOTE_FACTOR from
    Table I's (params.TOTAL_MASS_KG); None otherwise."""
    ratio = mass_kg / TOTAL_MASS_KG
    if 1.0 / MASS_NOTE_FACTOR <= ratio <= MASS_NOTE_FACTOR:
        return None
    times = f"{ratio:,.0f}" if ratio >= 100 else f"{ratio:.3g}"
    return (f"note: the model's total mass is {mass_kg:.6g} kg, {times} x Table I's {TOTAL_MASS_KG:g} kg; C_mt = "
            "E+/(m g d) divides by the model's own mass while the motors' work changes little with it "
            "(docs/MODEL.md, 'A robot of your own')")


def long_run_lines(result) -> list[str]:
    """The long-run line of a walk that went at least TRANSIENT_M + LONG_RUN_M (110 m) without falling: its C_mt
    after the initiation's transient, with the 95 % interval, and the kept steps' period; none for a shorter walk
    (its C_mt is mostly the initiation's)."""
    from drake_biped.analysis.long_run import LONG_RUN_M, TRANSIENT_M

    if not walked_the_distance(result.fell, result.distance_m, TRANSIENT_M + LONG_RUN_M):
        return []
    lr = result.long_run()
    if lr["cost_of_transport"] is None:
        return []
    return [f"long-run C_mt {format_cost_interval(lr['cost_of_transport'], lr['half_width'])} (95 %) over the "
            f"{lr['distance_m']:.1f} m after the first {TRANSIENT_M:g} m ({lr['steps']} steps of "
            f"{lr['step_period_mean_s']:.3f} ± {lr['step_period_std_s']:.3f} s)"]


def record_comparison_lines(params, config: EpisodeConfig, result) -> list[str]:
    """Where --params is a walk's record (a result.json: its "config" and its "cost_of_transport"), how this walk's
    C_mt compares with the record's (versions.compare_with_record: to the last digit on the record's machine,
    within a stated tolerance on another); none for a gait or a parameter file."""
    from drake_biped.records import read_json
    from drake_biped.resources import gait_path
    from drake_biped.versions import compare_with_record

    if params is None:
        return []
    path = gait_path(params)
    record = read_json(path, "--params")
    if not (isinstance(record, dict) and isinstance(record.get("config"), dict)
            and isinstance(record.get("cost_of_transport"), (int, float))):
        return []
    if config_of_record(record["config"]).to_dict() != config.to_dict():
        return [f"record {path}: not compared, this walk's configuration is not the record's (options changed it)"]
    comparison = compare_with_record(record["cost_of_transport"], result.cost_of_transport, record.get("versions"))
    return [f"record {path}: {comparison.text}"]


def write_walk(config: EpisodeConfig, out: Path, animation: bool = True, save_trajectory: bool = False,
               progress=None):
    """Walk one episode of `config` and write into `out`: result.json, diagram.svg/.png (when Graphviz is
    installed; a warning otherwise), walk.png, and with `animation` walk.html (Meshcat recording) and
    walk.gif; trajectory.npz with `save_trajectory`. progress(t, distance) as it walks. The EpisodeResult."""
    from drake_biped.analysis.figures import walk_animation, walk_figure
    from drake_biped.diagram import build_diagram
    from drake_biped.episode import run_episode

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    meshcat = None
    if animation:
        meshcat = start_meshcat()
        meshcat.StartRecording(frames_per_second=30.0, set_visualizations_while_recording=False)
    result = run_episode(config, meshcat=meshcat, record_trajectory=True, progress=progress)
    if progress is not None:
        progress(result.duration_s, result.distance_m)  # the last report came up to 0.25 s before the end
    result.to_json(out / "result.json")
    if save_trajectory:
        result.save_trajectory(out / "trajectory.npz")
    try:
        export_diagram(build_diagram(config).diagram, out)
    except GraphvizMissingError as exc:
        warn(str(exc))
    window = config.window
    title = (
        f"C_mt {format_cost(result.cost_of_transport)}"
    ) + (f", torque-free {window.start_s:g}-{window.end_s:g} s" if window.active else ", no torque-free window")
    walk_figure(result.trajectory, out / "walk.png", title=title)
    write_energy(result.trajectory, out, title)
    if meshcat is not None:
        write_meshcat_html(meshcat, out / "walk.html", follow=(result.trajectory["time"],
                                                             result.trajectory["positions"][:, 0]),
                           ground_height=config.ground.height)
        from drake_biped.model import body_of_model

        walk_animation(result.trajectory, out / "walk.gif", ground_height=config.ground.height,
                       body=body_of_model(config.model))
    return result


def write_energy(trajectory, out: Path, title: str = "") -> dict | None:
    """Where the walk's energy goes, its initiation left out (`analysis.energy`: from the first touchdown at or
    after INITIATION_S): out/energy.json ({"from_s", "work_by_role", "shares"}) and out/energy.png (work by role,
    power over the time since touchdown). None, and nothing written, for a walk with no touchdown after it."""
    from drake_biped.analysis import energy

    try:
        by_role = energy.work_by_role(trajectory)
        shares = energy.shares(by_role)
    except ValueError:
        return None
    record = {"from_s": energy.INITIATION_S, "work_by_role": by_role, "shares": shares}
    write_atomic(out / "energy.json", record)
    energy.energy_figure(by_role, energy.power_by_phase(trajectory), out / "energy.png",
                         title=f"the motors' work by role after the first {energy.INITIATION_S:g} s"
                         + (f" ({title})" if title else ""))
    return record


def energy_line(record: dict | None) -> str | None:
    """The energy audit in a line: each role's share of the positive work after the initiation, the swing hip's
    braking beside it. None without an audit."""
    if not record:
        return None
    by_role, shares = record["work_by_role"], record["shares"]
    parts = [f"{role.replace('_', ' ')} {100 * share:.0f} %" for role, share in
             sorted(shares.items(), key=lambda kv: -kv[1]) if share >= 0.005]
    hip = by_role["swing_hip"]
    return (f"positive work by role after the first {record['from_s']:g} s: {', '.join(parts)}; the swing hip "
            f"{hip['positive_j']:.1f} J driving, {hip['negative_j']:.1f} J braking (energy.json, energy.png)")


COMMAND = "walk"
PARSER = dict(help="walk one episode and write its record, figures and animation")


def add_arguments(p: argparse.ArgumentParser) -> None:
    """`drake-biped walk`'s options."""
    add_episode_options(p)
    add_window_options(p, default="none", policy=False)
    p.add_argument("--push", type=number("finite"), help="horizontal push on the torso (N, + forward) "
                   "(default: none)")
    p.add_argument("--push-start", type=number("nonnegative"), default=0.4, help="push start (s)")
    p.add_argument("--push-duration", type=number("positive"), default=0.1, help="push duration (s)")
    p.add_argument("--save-trajectory", action="store_true", help="also write trajectory.npz")
    p.add_argument("--no-animation", action="store_true", help="skip walk.html and walk.gif")
    p.add_argument("--out", required=True, type=out_folder, help="output folder")


def settings_from_args(args: argparse.Namespace) -> WalkSettings:
    """The walk's settings from the command's options."""
    config = episode_config(args)
    if args.level_length is not None and config.ground.slope_rad == 0.0:
        raise ParameterError(f"--level-length {args.level_length:g}: the ground is level (no --slope), so a level "
                             "stretch before it changes nothing; give --slope too")
    if args.push is not None and args.push == 0.0:
        raise ParameterError("--push 0: a push of no force changes nothing; give a force (N, + forward)")
    if (args.t1 is None) != (args.t2 is None):
        raise ParameterError("--t1 and --t2 go together: give both or neither")
    if args.t1 is not None:
        check_window_given(args.t1, args.t2, ("--t1", "--t2"))
        config = config.replace(window=TorqueFreeWindow(args.t1, args.t2))
    if args.push is not None:
        config = config.replace(push=Push(args.push, args.push_start, args.push_duration))
    elif args.push_start != 0.4 or args.push_duration != 0.1:
        raise ParameterError("--push-start and --push-duration shape a push: give --push N too")
    return WalkSettings(config, animation=not args.no_animation, save_trajectory=args.save_trajectory)


def command(args: argparse.Namespace) -> int:
    """Run the command of `args` (its options parsed by add_arguments); the exit code."""
    settings = settings_from_args(args)
    config = settings.config
    out = Path(args.out)
    result = run(settings, out)
    print_lines(summary_lines(result))
    line = energy_line(read_kept(out / "energy.json"))
    if line is not None:
        print(line)
    print_lines(record_comparison_lines(args.params, config, result))
    note = mass_note(result.mass_kg)
    if note is not None:
        print(note, file=sys.stderr)
    if not args.no_animation:
        print_lines(animation_lines(out))
    if config.push is not None and result.duration_s <= config.push.start_s:
        print(f"note: the episode ended at {result.duration_s:.2f} s, before the push at {config.push.start_s:g} s "
              "started: it walked unpushed", file=sys.stderr)
    print(f"wrote {out}/")
    return 0
