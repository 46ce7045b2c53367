"""Where walks from different starts end (`drake-biped basins`): a slice of initial conditions (the initiation's
hip angle x its speed), each start walked long and read by what it settles on (`common.walks.attractor_of_walk`:
period-k, irregular, or a fall), with and without a torque-free window. Coexisting gaits show as regions of
different attractors, or of different step periods, in the same slice. Walks are kept in `walks/` as each
finishes: a rerun of the same command resumes.
"""

from __future__ import annotations

import argparse
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from drake_biped.analysis.attractor import step_period_label
from drake_biped.analysis.basins_report import figure, markdown
from drake_biped.analysis.long_run import TRANSIENT_M
from drake_biped.common.options import (
    add_cluster_options,
    add_episode_options,
    add_window_options,
    chosen_window,
    episode_config,
    number,
    out_folder,
)
from drake_biped.common.walks import (
    CONDITIONS,
    JITTER_MAX_PERIOD,
    JITTER_TOLERANCE_S,
    attractor_of_walk,
    condition_window,
)
from drake_biped.params import DEFAULT_WINDOW_S, EpisodeConfig, ParameterError, check_settings
from drake_biped.records import write_record
from drake_biped.versions import versions

__all__ = ["BasinSettings", "basins", "run"]

MAX_WALKS = 800


@dataclass(frozen=True)
class BasinSettings:
    """The gait, the window compared with none, the grid of starts and the transient dropped."""

    config: EpisodeConfig = field(default_factory=lambda: EpisodeConfig().override({"sim.distance_m": 30.0,
                                                                                    "sim.max_time_s": 180.0}))
    window: tuple[float, float] = DEFAULT_WINDOW_S
    hip_angles_rad: tuple[float, ...] = (0.10, 0.13, 0.16)
    speeds_mps: tuple[float, ...] = (0.15, 0.175, 0.20)
    transient_m: float = TRANSIENT_M
    force: bool = False

    def __post_init__(self) -> None:
        for name in ("hip_angles_rad", "speeds_mps"):
            values = getattr(self, name)
            if not values or any(not (isinstance(v, (int, float)) and math.isfinite(v)) for v in values):
                raise ParameterError(f"basins: {name} must be finite numbers, got {values!r}")
        if not (0 <= self.transient_m < self.config.sim.distance_m):
            raise ParameterError(f"--transient {self.transient_m:g} m must lie below --distance "
                                 f"{self.config.sim.distance_m:g} m")
        if self.walks > MAX_WALKS and not self.force:
            raise ParameterError(f"basins: {self.walks} walks is above {MAX_WALKS}; coarsen the grid, or give --force")

    @property
    def walks(self) -> int:
        return len(CONDITIONS) * len(self.hip_angles_rad) * len(self.speeds_mps)


def start_config(settings: BasinSettings, condition: str, hip_angle: float, speed: float) -> EpisodeConfig:
    """The walk from one start, without or with the settings' window."""
    config = settings.config.override({"initial.hip_angle_rad": float(hip_angle), "initial.speed_mps": float(speed)})
    return config.replace(window=condition_window(condition, settings.window))


def basins(settings: BasinSettings, out: Path, client, progress=None) -> dict[str, Any]:
    """The record of `settings` on `client`: per condition, a grid [hip angle][speed] of what each start ends on."""
    from drake_biped.common.executor import run_kept

    jobs = {}
    for condition in CONDITIONS:
        for i, a in enumerate(settings.hip_angles_rad):
            for j, v in enumerate(settings.speeds_mps):
                path = out / "walks" / f"{condition}-{i:02d}-{j:02d}.json"
                jobs[(condition, i, j)] = (path, start_config(settings, condition, a, v).to_dict())
    results = run_kept(client, jobs, progress)
    distance = settings.config.sim.distance_m
    grids: dict[str, list[list[dict]]] = {}
    for condition in CONDITIONS:
        grid = []
        for i in range(len(settings.hip_angles_rad)):
            row = []
            for j in range(len(settings.speeds_mps)):
                label = attractor_of_walk(results[(condition, i, j)], distance, settings.transient_m)
                periods = label["step_periods_s"][-20:]
                coarse = step_period_label(label["step_periods_s"], fell=label["fell"], tolerance_s=JITTER_TOLERANCE_S,
                                           max_period=JITTER_MAX_PERIOD)
                row.append({"attractor": label["attractor"], "within_jitter": coarse["attractor"],
                            "fell": label["fell"], "distance_m": label["distance_m"],
                            "step_period_mean_s": float(np.mean(periods)) if periods else None,
                            "spread_s": label["spread_s"], "cost_of_transport": label["cost_of_transport"]})
            grid.append(row)
        grids[condition] = grid
    return {"window": list(settings.window), "hip_angles_rad": list(settings.hip_angles_rad),
            "speeds_mps": list(settings.speeds_mps), "distance_m": distance, "transient_m": settings.transient_m,
            "jitter_tolerance_s": JITTER_TOLERANCE_S, "grids": grids}








def run(settings: BasinSettings, out: Path, client=None, progress: bool = True) -> dict[str, Any]:
    """The slice on `client` (a LocalCluster when None); writes basins.json, basins.md and basins.png into `out`
    (the walks kept in out/walks). The record."""
    check_settings(settings, BasinSettings, "basins.run")
    from drake_biped.common.executor import client_or_local
    from drake_biped.common.progress import progress_bar

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    with progress_bar(settings.walks, "basins", "walk", progress) as tick, client_or_local(client) as c:
        record = basins(settings, out, c, tick)
    record.update(config=settings.config.to_dict(), versions=versions())
    write_record(out, "basins", record, markdown, figure)
    return record


COMMAND = "basins"
PARSER = dict(help="a slice of starts (initial hip angle x speed) coloured by what each walk ends on, with and "
              "without a torque-free period (on Dask, resumable)")


def _grid(text: str) -> tuple[float, ...]:
    """A:B:N, N values from A to B."""
    try:
        a, b, n = text.split(":")
        values = tuple(float(x) for x in np.linspace(float(a), float(b), int(n)))
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not A:B:N (N values from A to B)") from None
    if int(n) < 1 or not all(math.isfinite(x) for x in values):
        raise argparse.ArgumentTypeError(f"{text!r} is not A:B:N with N >= 1 and finite A, B")
    return values


def add_arguments(p: argparse.ArgumentParser) -> None:
    """`drake-biped basins`'s options."""
    p.add_argument("--hip-angles", type=_grid, default=(0.10, 0.13, 0.16),
                   help="initial hip angles A:B:N (rad)")
    p.add_argument("--speeds", type=_grid, default=(0.15, 0.175, 0.20), help="initiation speeds A:B:N (m/s)")
    add_episode_options(p)
    add_window_options(p)
    p.add_argument("--transient", type=number("nonnegative"), default=TRANSIENT_M,
                   help="steps within this distance of the first touchdown are dropped (m)")
    add_cluster_options(p)
    p.add_argument("--out", required=True, type=out_folder, help="output folder (rerun the same command to resume)")


def settings_from_args(args: argparse.Namespace) -> BasinSettings:
    config = episode_config(args)
    if args.distance is None:
        config = config.override({"sim.distance_m": 30.0, "sim.max_time_s": max(config.sim.max_time_s, 180.0)})
    return BasinSettings(config, chosen_window(args, config), tuple(args.hip_angles), tuple(args.speeds),
                         transient_m=args.transient, force=args.force)


def command(args: argparse.Namespace) -> int:
    """Run the command of `args` (its options parsed by add_arguments); the exit code."""
    from drake_biped.common.options import run_command

    record = run_command(args, settings_from_args, run)
    print(markdown(record))
    print(f"wrote {args.out}/basins.json, basins.md, basins.png")
    return 0
