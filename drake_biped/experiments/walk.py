"""One walk and every file it writes: its record, the Drake diagram as DOT/SVG/PNG, a standalone Meshcat HTML
recording, the walk figure and GIF (`run` writes them all; `drake-biped walk` is this module)."""

from __future__ import annotations

import shutil
import subprocess
import sys
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from pydrake.systems.framework import Diagram

from drake_biped.params import EpisodeConfig


class GraphvizMissingError(RuntimeError):
    """The Graphviz `dot` program is not installed."""


def export_diagram(diagram: Diagram, out_dir: Path, stem: str = "diagram", max_depth: int = 2) -> list[Path]:
    """Write `stem`.dot always, and `stem`.svg / `stem`.png through Graphviz `dot`.

    Raises GraphvizMissingError (after writing the .dot file) when `dot` is not on PATH."""
    out_dir = Path(out_dir)
    dot_path = out_dir / f"{stem}.dot"
    dot_path.write_text(diagram.GetGraphvizString(max_depth=max_depth))
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


def start_meshcat():
    """A headless Meshcat server on a loopback port (7000 upward)."""
    from pydrake.geometry import Meshcat, MeshcatParams

    params = MeshcatParams()
    params.host = "localhost"
    return Meshcat(params)


def write_meshcat_html(meshcat, path: Path, x_range: tuple[float, float] | None = None) -> None:
    """Publish the recording and save Meshcat's self-contained HTML page.

    x_range: the stretch of ground the walk covered (m); the camera looks at it from the side, so the
    whole walk is in view (press play under "Open Controls" > Animations to watch it)."""
    meshcat.StopRecording()
    meshcat.PublishRecording()
    if x_range is not None:
        x_mid = 0.5 * (x_range[0] + x_range[1])
        distance = 0.65 * abs(x_range[1] - x_range[0]) + 2.0
        meshcat.SetCameraPose(np.array([x_mid, -distance, 0.9]), np.array([x_mid, 0.0, 0.35]))
    Path(path).write_text(meshcat.StaticHtml())


@dataclass(frozen=True)
class WalkSettings:
    """The episode, and which of the optional files to write."""

    config: EpisodeConfig = field(default_factory=EpisodeConfig)
    animation: bool = True  # walk.html (Meshcat recording) and walk.gif
    save_trajectory: bool = False  # trajectory.npz


def run(settings: WalkSettings, out: Path, client=None, progress: bool = True):
    """Walk one episode (in this process: Meshcat records it; `client` is not used) and write its files into
    `out` (see `write_walk`), with a progress bar in metres. The EpisodeResult."""
    update, bar = None, None
    if progress:
        from tqdm import tqdm

        total = settings.config.sim.distance_m
        bar = tqdm(total=round(total, 2), desc="walk", unit="m",
                   bar_format="{l_bar}{bar}| {n:.2f}/{total:.2f} m [{elapsed}<{remaining}{postfix}]")

        def update(t: float, d: float) -> None:
            bar.n = round(min(max(d, 0.0), total), 2)
            bar.set_postfix_str(f"t={t:.1f}s", refresh=False)
            bar.refresh()

    try:
        return write_walk(settings.config, out, animation=settings.animation,
                          save_trajectory=settings.save_trajectory, progress=update)
    finally:
        if bar is not None:
            bar.close()


def summary_lines(result) -> list[str]:
    """What `drake-biped walk` prints: how the walk ended, its gait, its energy, its speed of simulation."""
    status = f"FELL ({result.fall_reason})" if result.fell else f"ended: {result.termination}"
    cmt = "n/a" if result.cost_of_transport is None else f"{result.cost_of_transport:.3f}"
    cmt_kg = "n/a" if result.cost_of_transport_per_kg is None else f"{result.cost_of_transport_per_kg:.3f}"
    period = "n/a" if result.step_period_s is None else f"{result.step_period_s:.3f} s"
    length = "n/a" if result.step_length_m is None else f"{result.step_length_m:.3f} m"
    return [
        f"{status}: {result.distance_m:.2f} m in {result.duration_s:.2f} s ({result.mean_speed_mps:.3f} m/s), "
        f"{len(result.steps)} steps, step {period} / {length}",
        f"positive work {result.total_positive_work_j:.1f} J, C_mt {cmt} (E+/(m g d)), "
        f"{cmt_kg} J/(kg m) (paper's eq. 1)",
        f"wall {result.wall_time_s:.1f} s, real-time factor {result.real_time_factor:.2f}",
    ]


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
        f"C_mt {result.cost_of_transport:.3f}" if result.cost_of_transport is not None else "C_mt n/a"
    ) + (f", torque-free {window.start_s:g}-{window.end_s:g} s" if window.active else ", no torque-free window")
    walk_figure(result.trajectory, out / "walk.png", title=title)
    if meshcat is not None:
        x = result.trajectory["positions"][:, 0]
        write_meshcat_html(meshcat, out / "walk.html", x_range=(float(x.min()), float(x.max())))
        walk_animation(result.trajectory, out / "walk.gif", ground_height=config.ground.height)
    return result


def warn(message: str) -> None:
    print(f"drake-biped: warning: {message}", file=sys.stderr)
