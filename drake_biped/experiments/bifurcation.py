"""What the gait settles on as one parameter changes: a bifurcation diagram (`drake-biped bifurcation`).

For each value of the parameter (a window's t1 or t2, the slope, the initiation, any EpisodeConfig field), one
long walk: the steps within `transient_m` of the first touchdown are dropped, and the step periods and section
states (hip angle and rate at touchdown) of the rest are kept and read by `analysis.attractor`: period-k where
every k-th of the last step periods varies by less than 2 ms, irregular, or a fall. Garcia et al. (1998) drew
the simplest walker's period doubling this way.

The 1 kHz controller sees a touchdown only at its next update, so even a regular gait's step periods jitter by a
few milliseconds (the full-state section map is discontinuous on that scale, which leaves Newton's method and
central-difference multipliers without a meaning there). Each point is therefore also read at the jitter's
scale (period 1 or 2 to within `jitter_tolerance_s`), and an irregular walk gets a finite-size Lyapunov exponent: a
neighbour walk, its swing hip's rate kicked by NEIGHBOUR_KICK_RADPS early in the first step after the
transient, and the rate at which their sections part (`attractor.lyapunov_from_neighbours`) until they are half
the attractor's size apart. A second plant step may be given to show what the discretisation does. Walks are
kept in `walks/` as each finishes: a rerun of the same command resumes.
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from drake_biped.analysis.attractor import (
    MAX_PERIOD,
    NEIGHBOUR_KICK_RADPS,
    PERIOD_TOLERANCE_S,
    PERIOD_WINDOW,
    lyapunov_from_neighbours,
    step_period_label,
)
from drake_biped.analysis.bifurcation_report import figure, markdown
from drake_biped.analysis.long_run import TRANSIENT_M
from drake_biped.common.options import (
    EPISODE_RECORD_BYTES,
    add_cluster_options,
    add_episode_options,
    check_memory,
    count,
    episode_config,
    number,
    out_folder,
    why_unchanged,
)
from drake_biped.common.walks import JITTER_MAX_PERIOD, JITTER_TOLERANCE_S, attractor_of_walk
from drake_biped.experiments.slope import check_reaches_slope
from drake_biped.params import (
    EpisodeConfig,
    ParameterError,
    check_settings,
    resolve_field,
)
from drake_biped.records import write_record
from drake_biped.versions import versions

__all__ = ["BifurcationSettings", "premise", "run", "walked_up_to"]

# At most this many walks without --force.
MAX_WALKS = 400
# The neighbour walk of an irregular one: its swing hip's rate kicked by NEIGHBOUR_KICK_RADPS
# (analysis.attractor), this long after the first kept touchdown (the swing foot in the air); their sections'
# distance followed until it reaches this fraction of the attractor's spread.
KICK_AFTER_TOUCHDOWN_S = 0.1
LYAPUNOV_SATURATION = 0.5


@dataclass(frozen=True)
class BifurcationSettings:
    """The gait (its window, slope and plant step), the parameter and its values, an optional second plant
    step, the transient dropped, the jitter's tolerance and whether irregular walks get a neighbour."""

    config: EpisodeConfig = field(default_factory=lambda: EpisodeConfig().override({"sim.distance_m": 60.0,
                                                                                    "sim.max_time_s": 360.0}))
    param: str = "t1"
    values: tuple[float, ...] = (0.30, 0.38, 0.46)
    second_time_step_s: float | None = None
    transient_m: float = TRANSIENT_M
    jitter_tolerance_s: float = JITTER_TOLERANCE_S
    lyapunov: bool = True
    force: bool = False

    def __post_init__(self) -> None:
        resolve_field(self.param)  # ParameterError naming an unknown parameter
        if not self.values or any(not (isinstance(v, (int, float)) and math.isfinite(v)) for v in self.values):
            raise ParameterError(f"bifurcation: values must be finite numbers, got {self.values!r}")
        twice = sorted({float(v) for v in self.values if list(self.values).count(v) > 1})
        if twice:  # a value given twice walks the same walk twice: two identical rows
            raise ParameterError(f"bifurcation: --param {self.param} value {twice[0]:g} is given twice; each value "
                                 "walks once")
        if self.second_time_step_s is not None and not (math.isfinite(self.second_time_step_s)
                                                        and self.second_time_step_s > 0):
            raise ParameterError(f"--second-time-step must be positive, got {self.second_time_step_s!r}")
        if not (math.isfinite(self.transient_m) and 0 <= self.transient_m < self.config.sim.distance_m):
            raise ParameterError(f"--transient {self.transient_m:g} m must lie below --distance "
                                 f"{self.config.sim.distance_m:g} m")
        if self.walks > MAX_WALKS and not self.force:
            raise ParameterError(f"bifurcation: {self.walks} walks is above {MAX_WALKS}; lower --num, or give --force")
        check_memory(f"--num {len(self.values)}", self.walks * EPISODE_RECORD_BYTES)
        if self.second_time_step_s is not None and self.second_time_step_s == self.config.sim.time_step_s:
            raise ParameterError(f"--second-time-step {self.second_time_step_s:g} is the gait's own plant step: it "
                                 "walks every value again to the same result")
        for v in self.values:  # over the slope, the envelope is the steepest slope climbed: the walks must reach it
            check_reaches_slope(self.config.override({self.param: float(v)}, sampled=True), f"--param {self.param} {v:g}: ")
        walked = [self.config.override({self.param: float(v)}, sampled=True).as_walked() for v in self.values]
        if len(self.values) > 1 and all(w == walked[0] for w in walked):
            span = f"--param {self.param} --from {min(self.values):g} --to {max(self.values):g}"
            why = why_unchanged(self.config, self.param, self.values)
            hint = "; give --t2 (or --t1) so that a window opens" if "never opens" in why else ""
            raise ParameterError(f"{span}: changes nothing: {why}{hint}")

    @property
    def time_steps(self) -> tuple[float, ...]:
        first = self.config.sim.time_step_s
        return (first,) if self.second_time_step_s is None else (first, self.second_time_step_s)

    @property
    def walks(self) -> int:
        return len(self.values) * len(self.time_steps) * (2 if self.lyapunov else 1)


def point_config(settings: BifurcationSettings, value: float, time_step_s: float) -> EpisodeConfig:
    """The walk of one point: the settings' gait with the parameter at `value`, at plant step `time_step_s`
    (the controller's clock kept: refined with the plant under the paper's clock, a fixed-rate loop kept)."""
    from drake_biped.params import with_time_step

    config = settings.config.override({settings.param: float(value)}, sampled=True)
    if time_step_s != config.sim.time_step_s:
        config = config.replace(sim=with_time_step(config.sim, time_step_s, "--second-time-step"))
    return config




def walked_up_to(points: list[dict[str, Any]]) -> float | None:
    """The envelope of a sweep (points in the order of their values, one plant step): the last value up to
    which every walk, from the first value on, walks its distance (None when the first falls). Over the slope:
    the steepest slope the gait climbs."""
    last = None
    for p in points:
        if p["fell"]:
            break
        last = p["value"]
    return last


def premise(without: list[dict[str, Any]], with_window: list[dict[str, Any]]) -> dict[str, Any]:
    """The paper's slope premise read off two sweeps over the same slopes, without and with a window: each
    one's envelope, and the band of slopes where the window's walk falls and the walk without one climbs (the
    paper's story needs it: "unable to climb with the torque-free period ... able without")."""
    if [p["value"] for p in without] != [p["value"] for p in with_window]:
        raise ValueError("premise: the two sweeps must cover the same values")
    band = [a["value"] for a, b in zip(without, with_window) if b["fell"] and not a["fell"]]
    last = without[-1]["value"] if without else None
    up = {"without_up_to": walked_up_to(without), "with_up_to": walked_up_to(with_window)}
    # an envelope at the sweep's last value is a bound: steeper slopes were not tried
    return {**up, **{f"{k}_is_bound": v is not None and v == last for k, v in up.items()}, "band": band,
            "holds": bool(band)}


def _walk_path(out: Path, i: int, time_step_s: float, neighbour: bool = False) -> Path:
    return out / "walks" / f"{i:03d}-{time_step_s * 1e3:g}ms{'-neighbour' if neighbour else ''}.json"


def walks(settings: BifurcationSettings, out: Path, client, progress: Callable[[int, int], None] | None = None
          ) -> dict[tuple[int, float, bool], dict[str, Any]]:
    """Every point's walk, and the neighbour walk of each irregular one, kept in out/walks as each finishes;
    results by (index, time step, neighbour)."""
    from drake_biped.common.executor import run_kept

    jobs: dict[Any, tuple] = {(i, h, False): (_walk_path(out, i, h), point_config(settings, value, h).to_dict())
                              for i, value in enumerate(settings.values) for h in settings.time_steps}
    results = run_kept(client, jobs, progress)
    if not settings.lyapunov:
        return results
    kicked = {}
    for (i, h, _), (_, config) in jobs.items():
        walk = results[(i, h, False)]
        label = attractor_of_walk(walk, settings.config.sim.distance_m, settings.transient_m)
        if label["attractor"] != "irregular":
            continue
        kick = {"time_s": walk["steps"][label["first_kept_step"]]["touchdown_time_s"] + KICK_AFTER_TOUCHDOWN_S,
                "hip_rate_radps": NEIGHBOUR_KICK_RADPS}
        kicked[(i, h, True)] = (_walk_path(out, i, h, True), config, kick)
    results.update(run_kept(client, kicked, progress))
    return results


def bifurcation(settings: BifurcationSettings, out: Path, client, progress=None) -> dict[str, Any]:
    """The record of `settings` on `client` (module text): one point per value and plant step."""
    results = walks(settings, out, client, progress)
    distance = settings.config.sim.distance_m
    points = []
    for h in settings.time_steps:
        for i, value in enumerate(settings.values):
            walk = results[(i, h, False)]
            point = {"value": float(value), "time_step_s": h,
                     **attractor_of_walk(walk, distance, settings.transient_m)}
            jittered = step_period_label(point["step_periods_s"], fell=point["fell"],
                                         tolerance_s=settings.jitter_tolerance_s, max_period=JITTER_MAX_PERIOD)
            point["within_jitter"] = {"attractor": jittered["attractor"], "period": jittered["period"],
                                      "tolerance_s": settings.jitter_tolerance_s}
            point["lyapunov"] = None
            neighbour = results.get((i, h, True))
            if neighbour is not None:
                other = attractor_of_walk(neighbour, distance, settings.transient_m)
                n = min(len(point["sections"]), len(other["sections"]))
                if n >= 3 and not other["fell"]:
                    point["lyapunov"] = {**lyapunov_from_neighbours(np.array(point["sections"][:n]),
                                                                    np.array(other["sections"][:n]),
                                                                    saturation=LYAPUNOV_SATURATION),
                                         "kick_hip_rate_radps": NEIGHBOUR_KICK_RADPS}
            points.append(point)
    return {"param": settings.param, "values": [float(v) for v in settings.values],
            "time_steps_s": list(settings.time_steps), "transient_m": settings.transient_m,
            "distance_m": distance, "period_window": PERIOD_WINDOW, "period_tolerance_s": PERIOD_TOLERANCE_S,
            "jitter_tolerance_s": settings.jitter_tolerance_s, "max_period": MAX_PERIOD, "points": points,
            "lyapunov": settings.lyapunov,
            "walked_up_to": walked_up_to([p for p in points if p["time_step_s"] == settings.time_steps[0]])}






def run(settings: BifurcationSettings, out: Path, client=None, progress: bool = True) -> dict[str, Any]:
    """The diagram on `client` (a LocalCluster when None); writes bifurcation.json, bifurcation.md and
    bifurcation.png into `out` (the walks and orbits kept in out/walks and out/orbits). The record."""
    check_settings(settings, BifurcationSettings, "bifurcation.run")
    from drake_biped.common.executor import client_or_local
    from drake_biped.common.progress import progress_bar

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    walks_count = len(settings.values) * len(settings.time_steps)
    with progress_bar(walks_count, "bifurcation", "walk", progress) as tick, client_or_local(client) as c:
        record = bifurcation(settings, out, c, tick)
    record.update(config=settings.config.to_dict(), versions=versions())
    write_record(out, "bifurcation", record, markdown, figure)
    return record


COMMAND = "bifurcation"
PARSER = dict(help="long walks over a range of one parameter: the attractor each settles on (period-k, irregular, "
              "fall), read at 2 ms and at the controller's jitter, irregular ones with a Lyapunov exponent (on Dask, "
              "resumable)")


def add_arguments(p: argparse.ArgumentParser) -> None:
    """`drake-biped bifurcation`'s options."""
    from drake_biped.common.options import add_window_options

    p.add_argument("--param", required=True,
                   help="the parameter: t1, t2, slope, speed, hip_angle, u_a, u_r, kappa, or any section.field")
    p.add_argument("--from", dest="start", required=True, type=number("finite"), help="first value")
    p.add_argument("--to", dest="stop", required=True, type=number("finite"), help="last value")
    p.add_argument("--num", required=True, type=count, help="values from --from to --to, evenly spaced")
    add_episode_options(p)
    add_window_options(p)
    p.add_argument("--transient", type=number("nonnegative"), default=TRANSIENT_M,
                   help="steps within this distance of the first touchdown are dropped (m)")
    p.add_argument("--second-time-step", type=number("positive"), default=None,
                   help="walk every value at this plant step too (s)")
    p.add_argument("--jitter-tolerance", type=number("positive"), default=JITTER_TOLERANCE_S,
                   help="the second reading's tolerance on every k-th step period (s)")
    p.add_argument("--no-lyapunov", action="store_true", help="no neighbour walks (no Lyapunov exponents)")
    add_cluster_options(p)
    p.add_argument("--out", required=True, type=out_folder, help="output folder (rerun the same command to resume)")


def settings_from_args(args: argparse.Namespace) -> BifurcationSettings:
    """The settings of `args`: the window of --policy or --t1/--t2 (either may be given alone, the other taken
    from --params; the swept one is set point by point), the walk 60 m unless --distance says otherwise."""
    config = episode_config(args)
    if args.distance is None:
        config = config.override({"sim.distance_m": 60.0, "sim.max_time_s": max(config.sim.max_time_s, 360.0)})
    if args.policy is not None:
        if args.t1 is not None or args.t2 is not None:
            raise ParameterError("give either --policy or --t1/--t2, not both")
        from drake_biped.common.options import policy_window

        t1, t2 = policy_window(Path(args.policy))
        config = config.override({"window.start_s": t1, "window.end_s": t2})
    named = {"window.start_s": args.t1, "window.end_s": args.t2}
    # one end of the window may be given alone: --param sweeps the other, and a sweep that never opens it is
    # refused as changing nothing
    config = config.override({k: v for k, v in named.items() if v is not None}, sampled=True)
    if args.num == 1 and args.stop != args.start:
        raise ParameterError(f"--num 1 --from {args.start:g} --to {args.stop:g}: one value walks --from alone and "
                             "--to would change nothing; give --num >= 2, or --to equal to --from")
    values = tuple(float(v) for v in np.linspace(args.start, args.stop, args.num))
    return BifurcationSettings(config, args.param, values, second_time_step_s=args.second_time_step,
                               transient_m=args.transient, jitter_tolerance_s=args.jitter_tolerance,
                               lyapunov=not args.no_lyapunov, force=args.force)


def command(args: argparse.Namespace) -> int:
    """Run the command of `args` (its options parsed by add_arguments); the exit code."""
    from drake_biped.common.options import run_command

    record = run_command(args, settings_from_args, run)
    print(markdown(record))
    print(f"wrote {args.out}/bifurcation.json, bifurcation.md, bifurcation.png")
    return 0
