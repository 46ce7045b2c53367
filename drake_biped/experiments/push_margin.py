"""Push margins measured in steady state: a survival map over push force and the phase of the step, without
and with a torque-free period, and the margin read from it (beyond the paper, which pushes with 20 N only).

Survival is not monotone in the force (a push may fall at 60 N and be survived at 90 N), so the margin is not
bisected: every force of a grid (`force_step_n` apart, up to `max_force_n`) is applied in each direction at
`phases` phases of one steady-state step, each push for `push_duration_s`. The step: the first whole step that
starts at or after `settle_s` in the unpushed walk of the same condition (after the initiation's transient;
with the window acting, since it acts from the first touchdown on). A push at phase p starts at
T_k + p (T_k+1 - T_k). A pushed walk survives when it still walks its whole distance. The margin of a
condition and direction is the largest grid force at and below which every force survives at every phase
(0 when the smallest falls somewhere).
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from drake_biped.analysis.push_margin_report import figure, markdown
from drake_biped.common.options import (
    add_cluster_options,
    add_episode_options,
    add_window_options,
    chosen_window_and_source,
    count,
    episode_config,
    number,
    out_folder,
    run_command,
    window_line,
)
from drake_biped.common.walks import CONDITIONS, condition_window, steady_step
from drake_biped.paper import PUSH_DURATION_S
from drake_biped.params import (
    DEFAULT_WINDOW_S,
    EpisodeConfig,
    ParameterError,
    Push,
    check_settings,
    walked_the_distance,
)
from drake_biped.records import write_record
from drake_biped.versions import versions

__all__ = ["PushMarginSettings", "margin_of", "push_margin", "run"]

# At most this many pushed walks without --force.
MAX_EPISODES = 5000


@dataclass(frozen=True)
class PushMarginSettings:
    """The gait, the torque-free period compared with none, the force grid, the phases and the timing."""

    config: EpisodeConfig = field(default_factory=lambda: EpisodeConfig().override({"sim.distance_m": 12.0}))
    window: tuple[float, float] = DEFAULT_WINDOW_S
    max_force_n: float = 100.0
    force_step_n: float = 5.0
    phases: int = 12
    settle_s: float = 5.0
    push_duration_s: float = PUSH_DURATION_S
    force: bool = False
    window_source: str | None = None  # where the window comes from, in words (the record's window_source)

    def __post_init__(self) -> None:
        for name in ("max_force_n", "force_step_n", "settle_s", "push_duration_s"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
                raise ParameterError(f"push margin: {name} must be a positive number, got {value!r}")
        if self.force_step_n > self.max_force_n:
            raise ParameterError(f"--force-step {self.force_step_n:g} is above --max-force {self.max_force_n:g}")
        if not isinstance(self.phases, int) or isinstance(self.phases, bool) or self.phases < 1:
            raise ParameterError(f"--phases must be an integer >= 1, got {self.phases!r}")
        if self.episodes > MAX_EPISODES and not self.force:
            raise ParameterError(f"push margin: {self.episodes} pushed walks ({len(self.forces)} forces x 2 "
                                 f"directions x {self.phases} phases x 2 conditions) is above {MAX_EPISODES}; "
                                 "coarsen --force-step or --phases, or give --force")
        if self.settle_s + 2.0 >= self.config.sim.max_time_s:
            raise ParameterError(f"--settle {self.settle_s:g} s leaves no time to walk on before the time limit "
                                 f"{self.config.sim.max_time_s:g} s")

    @property
    def forces(self) -> list[float]:
        n = int(math.floor(self.max_force_n / self.force_step_n + 1e-9))
        return [round(self.force_step_n * k, 9) for k in range(1, n + 1)]

    @property
    def episodes(self) -> int:
        return 2 * len(self.forces) * 2 * self.phases






def margin_of(forces: list[float], survived: list[list[bool]]) -> float:
    """The largest force of `forces` (ascending) at and below which every phase survived; survived[i][j] is
    force i at phase j. 0.0 when the smallest force falls at some phase."""
    margin = 0.0
    for force, row in zip(forces, survived):
        if not all(row):
            break
        margin = force
    return margin


def push_margin(settings: PushMarginSettings, client, progress: Callable[[int, int], None] | None = None,
                keep: Path | None = None) -> dict[str, Any]:
    """The survival maps and margins of `settings` on `client`; the record (see the module's text). `keep`: a
    folder where each walk is kept as it finishes (a rerun resumes); None keeps nothing."""
    from drake_biped.common.executor import map_episodes

    def paths(names: list[str]) -> list[Path] | None:
        return None if keep is None else [Path(keep) / f"{name}.json" for name in names]

    base, forces, phases = settings.config, settings.forces, settings.phases
    distance = base.sim.distance_m
    unpushed = map_episodes(client, [base.replace(window=condition_window(c, settings.window), push=None).to_dict()
                                     for c in CONDITIONS], paths([f"{c}-unpushed" for c in CONDITIONS]))
    out: dict[str, Any] = {"window": list(settings.window), "max_force_n": settings.max_force_n,
                           "force_step_n": settings.force_step_n, "forces_n": forces, "phases": phases,
                           "settle_s": settings.settle_s, "push_duration_s": settings.push_duration_s,
                           "distance_m": distance, "margins": {}}
    jobs, keys = [], []
    for condition, result in zip(CONDITIONS, unpushed):
        walks = walked_the_distance(result["fell"], result["distance_m"], distance)
        step = steady_step(result, settings.settle_s) if walks else None
        out["margins"][condition] = {"unpushed_walks": walks,
                                     "step_s": None if step is None else list(step)}
        if step is None:
            continue
        window = condition_window(condition, settings.window)
        for direction, sign in (("forward", 1.0), ("backward", -1.0)):
            for i, force in enumerate(forces):
                for j in range(phases):
                    start = step[0] + (j / phases) * (step[1] - step[0])
                    push = Push(sign * force, start, settings.push_duration_s)
                    jobs.append(base.replace(window=window, push=push).to_dict())
                    keys.append((condition, direction, i, j))
    names = [f"{c}-{d}-{forces[i]:g}N-phase{j}" for c, d, i, j in keys]
    results = map_episodes(client, jobs, paths(names), progress)
    for m in out["margins"].values():
        for direction in ("forward", "backward"):
            m[direction] = {"margin_n": None, "survived": [[None] * phases for _ in forces],
                            "distance_m": [[None] * phases for _ in forces]}
    for (condition, direction, i, j), r in zip(keys, results):
        cell = out["margins"][condition][direction]
        cell["survived"][i][j] = walked_the_distance(r["fell"], r["distance_m"], distance)
        cell["distance_m"][i][j] = r["distance_m"]
    for m in out["margins"].values():
        for direction in ("forward", "backward"):
            cell = m[direction]
            if m["step_s"] is not None:
                cell["margin_n"] = margin_of(forces, cell["survived"])
                # every force tried survived: the margin is a lower bound, not where the walker fails
                cell["at_grid_top"] = bool(forces) and cell["margin_n"] == forces[-1]
                cell["impulse_ns"] = cell["margin_n"] * settings.push_duration_s
                cell["phases_s"] = [m["step_s"][0] + (j / phases) * (m["step_s"][1] - m["step_s"][0])
                                    for j in range(phases)]
    return out






def run(settings: PushMarginSettings, out: Path, client=None, progress: bool = True) -> dict[str, Any]:
    """The survival maps on `client` (a LocalCluster when None); writes push_margin.json, push_margin.md and
    push_margin.png into `out`, each walk kept in `out`/walks as it finishes (a rerun resumes). The record."""
    check_settings(settings, PushMarginSettings, "push_margin.run")
    from drake_biped.common.executor import client_or_local
    from drake_biped.common.progress import progress_bar

    out = Path(out)
    code = versions()
    with progress_bar(settings.episodes, "push margin", "episode", progress) as tick, \
            client_or_local(client) as c:
        record = push_margin(settings, c, progress=tick, keep=out / "walks")
    record.update(config=settings.config.to_dict(), versions=code)
    if settings.window_source is not None:
        record["window_source"] = settings.window_source
    write_record(out, "push_margin", record, markdown, figure)
    return record


COMMAND = "push-margin"
PARSER = dict(help="pushes in steady state over a grid of forces and phases of the step, "
              "with and without a torque-free period: the survival map and the margins (on Dask)")


def add_arguments(p: argparse.ArgumentParser) -> None:
    """`drake-biped push-margin`'s options."""
    add_episode_options(p)
    add_window_options(p)
    p.add_argument("--max-force", type=number("positive"), default=100.0, help="largest push tried (N)")
    p.add_argument("--force-step", type=number("positive"), default=5.0,
                   help="spacing of the force grid (N); default 5")
    p.add_argument("--phases", type=count, default=12, help="phases of the step pushed")
    p.add_argument("--settle", type=number("positive"), default=5.0,
                   help="the step pushed is the first to start at or after this time (s); default 5")
    add_cluster_options(p)
    p.add_argument("--out", required=True, type=out_folder, help="output folder")


def settings_from_args(args: argparse.Namespace) -> PushMarginSettings:
    """The map's settings from the command's options: 12 m walks unless --distance."""
    config = episode_config(args)
    if args.distance is None:  # a push at --settle s (about 6 m), then room to recover or fall
        config = config.override({"sim.distance_m": 12.0, "sim.max_time_s": max(config.sim.max_time_s, 72.0)})
    window, source = chosen_window_and_source(args, config)
    settings = PushMarginSettings(config, window, max_force_n=args.max_force, force_step_n=args.force_step,
                                  phases=args.phases, settle_s=args.settle, force=args.force, window_source=source)
    print(window_line(window, source))
    return settings


def command(args: argparse.Namespace) -> int:
    """Run the command of `args` (its options parsed by add_arguments); the exit code."""
    run_command(args, settings_from_args, run)
    out = Path(args.out)
    print((out / "push_margin.md").read_text())
    print(f"wrote {out}/push_margin.json, push_margin.md, push_margin.png")
    return 0
