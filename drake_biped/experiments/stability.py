"""Pushes and Poincaré return maps (the paper's Experiment 2: Table VI, Fig. 7), on Dask.

Six cells: the gait without and with a torque-free period, each undisturbed, pushed forward and pushed
backward (20 N on the torso for 0.1 s, 0.4 s into the trial). Each cell runs `trials` episodes; trial 0
starts from the paper's initiation, trial k > 0 from it with the initial hip angle and speed scaled by
independent factors in [1 - spread, 1 + spread] (seeded), so that the cells hold different transients
and the fit is not carried by one trajectory. Every touchdown gives a section state x_n = (inter-leg hip
angle, its rate) (`StepRecord`); a cell's return map is fitted to the pairs of consecutive touchdowns of
each trial (never across trials) about x* = the mean undisturbed steady section state of its condition
(touchdowns from `steady_from_step` on, of the undisturbed cell of the same condition). A trial that
falls gives the touchdowns it made.

Nothing lost: each finished episode's result is written to OUT/episodes/ (atomically), the finite-difference
Jacobian's walks to OUT/episodes/jacobian_CONDITION_KICK/, and with --floquet the step map's evaluations to
OUT/floquet_CONDITION/step_map/; a rerun with the same settings reads them back and runs only what is missing.
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np

from drake_biped.analysis.return_map import complex_list, fit_return_map, least_squares_map
from drake_biped.common.options import (
    add_episode_options,
    add_resumable_run_options,
    add_window_options,
    check_reaches_touchdown,
    check_size,
    check_walks,
    chosen_window_and_source,
    count,
    episode_config,
    number,
    run_command,
    window_line,
)
from drake_biped.common.walks import CONDITIONS, condition_window
from drake_biped.paper import TABLE_VI
from drake_biped.params import (
    DEFAULT_WINDOW_S,
    EpisodeConfig,
    InitialConditions,
    ParameterError,
    Push,
    check_settings,
)
from drake_biped.versions import versions

DISTURBANCES = ("undisturbed", "forward", "backward")

TABLE_VI_PAPER = TABLE_VI  # eigenvalues of the return map, as (real, imaginary) pairs


JACOBIAN_KICKS_RAD = (0.005, 0.01, 0.02)
JACOBIAN_STEP = 8  # the touchdown before which the Jacobian's kicks act (the map is to the next)
MAX_BOOTSTRAP = 100_000  # bootstrap resamples of the return maps' eigenvalues  # swing-hip angle kicks; rate kicks are 10x (rad/s)


@dataclass(frozen=True)
class StabilitySettings:
    """What a stability run depends on besides the episode configuration."""

    window: tuple[float, float] = DEFAULT_WINDOW_S
    trials: int = 8
    push_force_n: float = 20.0
    push_start_s: float = 0.4
    push_duration_s: float = 0.1
    spread: float = 0.15
    steady_from_step: int = 6
    bootstrap: int = 1000
    seed: int = 0
    # The gait (None: the default one), the finite-difference Jacobian's kicks (empty: none) and whether the
    # periodic orbit's Floquet multipliers are added to the report: how the run is made, kept out of to_dict
    # (the record holds the configuration itself).
    config: EpisodeConfig | None = None
    jacobian_kicks: tuple[float, ...] = JACOBIAN_KICKS_RAD
    floquet: bool = False
    force: bool = False  # run more than MAX_WALKS walks
    window_source: str | None = None  # where the window comes from, in words (the record's window_source)

    def __post_init__(self) -> None:
        t1, t2 = self.window
        if not (math.isfinite(t1) and math.isfinite(t2) and 0 <= t1 < t2):
            raise ParameterError(f"window {self.window!r}: need 0 <= t1 < t2 (a torque-free period to compare)")
        if not isinstance(self.trials, int) or self.trials < 1:
            raise ParameterError(f"trials {self.trials!r}: must be an integer >= 1")
        if not (math.isfinite(self.push_force_n) and self.push_force_n > 0):
            raise ParameterError(f"push_force_n {self.push_force_n!r}: must be > 0 (its sign is the direction)")
        if not (self.push_start_s >= 0 and self.push_duration_s > 0):
            raise ParameterError(f"push start {self.push_start_s!r} / duration {self.push_duration_s!r}: "
                                 "need start >= 0 and duration > 0")
        if not 0 <= self.spread < 0.5:
            raise ParameterError(f"spread {self.spread!r}: must be in [0, 0.5)")
        if not isinstance(self.steady_from_step, int) or self.steady_from_step < 1:
            raise ParameterError(f"steady_from_step {self.steady_from_step!r}: must be an integer >= 1")
        if not isinstance(self.bootstrap, int) or isinstance(self.bootstrap, bool) or self.bootstrap < 0:
            raise ParameterError(f"bootstrap {self.bootstrap!r}: must be an integer >= 0")
        check_walks(f"--trials {self.trials}", len(CONDITIONS) * len(DISTURBANCES) * self.trials, self.force)

    def check_walks_reach(self) -> None:
        """ParameterError naming --distance, before any walk, when the gait's walks may end before the
        touchdowns the analysis needs (`options.check_reaches_touchdown`): the furthest of them, so that the
        distance it names is enough for all."""
        config = self.config if self.config is not None else EpisodeConfig()
        needs = [(self.steady_from_step, "the return map's equilibrium (the undisturbed sections from step "
                                         f"{self.steady_from_step} on)")]
        if self.jacobian_kicks:
            needs.append((JACOBIAN_STEP + 1, f"the finite-difference Jacobian (kicked before touchdown {JACOBIAN_STEP})"))
        touchdown = max(n for n, _ in needs)
        check_reaches_touchdown(config, touchdown, " and ".join(why for n, why in needs if n == touchdown))
        check_size(f"bootstrap {self.bootstrap}", self.bootstrap, MAX_BOOTSTRAP, "resamples", self.force)

    def to_dict(self) -> dict[str, Any]:
        d = asdict(self)
        for name in ("config", "jacobian_kicks", "floquet", "force", "window_source"):
            d.pop(name)
        d["window"] = list(self.window)
        return d




def trial_initial(base: InitialConditions, seed: int, trial: int, spread: float) -> InitialConditions:
    """Trial 0: `base`; trial k: its hip angle and speed scaled by seeded factors in [1 - spread, 1 + spread]."""
    if trial == 0 or spread == 0:
        return base
    u = np.random.default_rng(np.random.SeedSequence([seed, trial])).uniform(-1.0, 1.0, 2)
    return InitialConditions(hip_angle_rad=base.hip_angle_rad * (1 + spread * u[0]),
                             speed_mps=base.speed_mps * (1 + spread * u[1]))


def cell_configs(base: EpisodeConfig, settings: StabilitySettings) -> list[tuple[str, str, int, EpisodeConfig]]:
    """(condition, disturbance, trial, config) for every episode of the six cells."""
    out = []
    signs = {"undisturbed": 0.0, "forward": 1.0, "backward": -1.0}
    for condition in CONDITIONS:
        window = condition_window(condition, settings.window)
        for kind in DISTURBANCES:
            push = None
            if signs[kind]:
                push = Push(signs[kind] * settings.push_force_n, settings.push_start_s, settings.push_duration_s)
            for k in range(settings.trials):
                initial = trial_initial(base.initial, settings.seed, k, settings.spread)
                out.append((condition, kind, k,
                            base.replace(window=window, push=push, initial=initial, seed=settings.seed)))
    return out


def section_sequence(result: dict[str, Any], push_start_s: float | None) -> tuple[np.ndarray, np.ndarray]:
    """The trial's section states (n x 2) and, for each, the number of touchdowns since the push (0 = the
    first touchdown after the push began; -1 before it; all -1 without a push)."""
    steps = result["steps"]
    x = np.array([[s["hip_angle_rad"], s["hip_rate_radps"]] for s in steps], dtype=float).reshape(-1, 2)
    since = np.full(len(steps), -1, dtype=int)
    if push_start_s is not None:
        after = [i for i, s in enumerate(steps) if s["touchdown_time_s"] >= push_start_s]
        if after:
            since[after[0]:] = np.arange(len(steps) - after[0])
    return x, since


def equilibrium(results: list[dict[str, Any]], steady_from_step: int) -> np.ndarray:
    """Mean section state of undisturbed trials over their touchdowns from `steady_from_step` on."""
    steady = np.vstack([section_sequence(r, None)[0][[s["index"] >= steady_from_step for s in r["steps"]]]
                        for r in results])
    if not len(steady):
        raise ValueError(f"no undisturbed touchdowns from step {steady_from_step} on: walk further")
    return steady.mean(axis=0)


def analyse(results: dict[tuple[str, str, int], dict[str, Any]], settings: StabilitySettings) -> dict[str, Any]:
    """Fit the six cells' return maps; the record that stability.json holds (besides settings and versions)."""

    cells: dict[str, dict[str, Any]] = {}
    for condition in CONDITIONS:
        undisturbed = [results[(condition, "undisturbed", k)] for k in range(settings.trials)]
        x_star = equilibrium(undisturbed, settings.steady_from_step)
        cells[condition] = {}
        for kind in DISTURBANCES:
            push_start = None if kind == "undisturbed" else settings.push_start_s
            seqs, sinces, falls = [], [], 0
            for k in range(settings.trials):
                r = results[(condition, kind, k)]
                falls += bool(r["fell"])
                x, since = section_sequence(r, push_start)
                if push_start is not None:
                    x, since = x[since >= 0], since[since >= 0]
                seqs.append(x)
                sinces.append(since)
            cell: dict[str, Any] = {"trials": settings.trials, "falls": falls,
                                    "sequences": [s.tolist() for s in seqs],
                                    "steps_since_push": [s.tolist() for s in sinces]}
            try:
                fit = fit_return_map(seqs, equilibrium=x_star, bootstrap=settings.bootstrap, seed=settings.seed)
                cell.update(fit.to_dict())
                # Stable: the linearised return map contracts and no trial fell (a push that topples the
                # robot is outside any linear map's reach, whatever the touchdowns before it say).
                cell["spectral_radius_below_one"] = bool(fit.spectral_radius < 1.0)
                cell["stable"] = bool(fit.spectral_radius < 1.0 and falls == 0)
            except ValueError as exc:
                cell.update(error=str(exc), stable=None)
            paper = np.array([complex(a, b) for a, b in TABLE_VI_PAPER[condition][kind]])
            cell["paper_eigenvalues"] = complex_list(paper)
            cell["paper_spectral_radius"] = float(np.max(np.abs(paper)))
            cells[condition][kind] = cell
        cells[condition]["equilibrium"] = x_star.tolist()
    return cells


def _result_path(out: Path, condition: str, kind: str, trial: int) -> Path:
    return out / "episodes" / f"{condition}_{kind}_{trial}.json"




def run_stability(out: Path, base: EpisodeConfig, settings: StabilitySettings, client,
                  progress: Callable[[int, int], None] | None = None,
                  jacobian_kicks: tuple[float, ...] = JACOBIAN_KICKS_RAD) -> dict[str, Any]:
    """Run (or finish) the six cells on Dask, then the finite-difference Jacobian of each condition's step
    map at each kick size, and return the stability record. Finished parts are read back on a rerun."""
    from drake_biped.common.executor import run_kept
    from drake_biped.records import read_kept, write_atomic

    code = versions()  # recorded at the start: the code this process runs
    (out / "episodes").mkdir(parents=True, exist_ok=True)
    jobs = {(c, kind, k): (_result_path(out, c, kind, k), config.to_dict())
            for c, kind, k, config in cell_configs(base, settings)}
    results = run_kept(client, jobs, progress)
    jacobian: dict[str, list[dict[str, Any]]] = {}
    for condition in CONDITIONS:
        window = condition_window(condition, settings.window)
        config = base.replace(window=window, seed=settings.seed)
        jacobian[condition] = []
        for size in jacobian_kicks:
            path = out / "episodes" / f"jacobian_{condition}_{size:g}.json"
            saved = read_kept(path)
            if isinstance(saved, dict):
                if saved.get("config") == config.to_dict():
                    jacobian[condition].append(saved["jacobian"])
                    continue
            try:
                fd = finite_difference_jacobian(config, client, angle_rad=size, rate_radps=10 * size,
                                                seed=settings.seed, keep=path.with_suffix(""))
            except (RuntimeError, ParameterError) as exc:
                fd = {"angle_rad": size, "rate_radps": 10 * size, "error": str(exc)}
            write_atomic(path, {"config": config.to_dict(), "jacobian": fd})
            jacobian[condition].append(fd)
    return {
        "settings": settings.to_dict(),
        "config": base.to_dict(),
        "versions": code,
        "cells": analyse(results, settings),
        "jacobian": jacobian,
    }


def _section(result: dict[str, Any], index: int) -> np.ndarray | None:
    for s in result["steps"]:
        if s["index"] == index:
            return np.array([s["hip_angle_rad"], s["hip_rate_radps"]])
    return None


def finite_difference_jacobian(base: EpisodeConfig, client, step: int = JACOBIAN_STEP, angle_rad: float = 0.005,
                               rate_radps: float = 0.05, lead_s: float = 0.03, kicks: int = 16,
                               seed: int = 0, keep: Path | None = None) -> dict[str, Any]:
    """The step-to-step Jacobian of the gait at touchdown `step`, by finite differences in Drake.

    The unperturbed walk gives touchdown n = `step` at T_n. `kicks` more walks kick the swing hip `lead_s`
    before T_n, while the swing foot is still in the air, by (a·angle_rad, b·rate_radps) with (a, b) evenly
    spread around the unit circle (a random phase from `seed`). Each kick moves the section state at
    touchdown n (Δx_n, measured: the controller's touchdown logic forms the section as it always does) and
    at touchdown n + 1 (Δx_n+1); J is the least-squares solution of Δx_n+1 = J Δx_n over the kicks.

    Least squares rather than two central differences: the controller is a sampled-data system (the step
    clock, phase reset and torque-free window start on the 1 ms update grid), so the step map carries small
    jumps where a touchdown moves across an update; a pair of kicks can land on either side of one, and many
    kicks average them out, as the regression does with pushes. The residual says how large they are.

    `keep`: a folder where each walk is kept as it finishes (KEEP/reference.json, KEEP/kick_K.json), read back
    by a rerun; None keeps nothing.
    """
    from drake_biped.common.executor import episode_task, run_kept

    if not isinstance(step, int) or step < 2:
        raise ParameterError(f"step {step!r}: must be an integer >= 2")
    if not (angle_rad > 0 and rate_radps > 0 and lead_s > 0):
        raise ParameterError("angle_rad, rate_radps and lead_s must be > 0")
    if not isinstance(kicks, int) or kicks < 3:
        raise ParameterError(f"kicks {kicks!r}: must be an integer >= 3")
    cfg = base.to_dict()
    if keep is None:
        ref = client.submit(episode_task, cfg, pure=False).result()
    else:
        ref = run_kept(client, {0: (Path(keep) / "reference.json", cfg)})[0]
    x0, y0 = _section(ref, step), _section(ref, step + 1)
    if x0 is None or y0 is None:
        raise ParameterError(f"the unperturbed walk has no touchdowns {step} and {step + 1}: walk further "
                             f"(it made {len(ref['steps'])}, fell={ref['fell']})")
    times = {s["index"]: s["touchdown_time_s"] for s in ref["steps"]}
    t_kick = times[step] - lead_s
    if t_kick <= times[step - 1]:
        raise ParameterError(f"lead_s {lead_s!r} reaches back past touchdown {step - 1}")
    phase = np.random.default_rng(seed).uniform(0, 2 * np.pi)
    angles = phase + 2 * np.pi * np.arange(kicks) / kicks
    plan = [{"time_s": t_kick, "hip_angle_rad": float(np.cos(a) * angle_rad),
             "hip_rate_radps": float(np.sin(a) * rate_radps)} for a in angles]
    if keep is None:
        runs = client.gather([client.submit(episode_task, cfg, k, pure=False) for k in plan])
    else:
        kept = run_kept(client, {i: (Path(keep) / f"kick_{i}.json", cfg, k) for i, k in enumerate(plan)})
        runs = [kept[i] for i in range(len(plan))]
    dx, dy, lost = [], [], 0
    for r in runs:
        x, y = _section(r, step), _section(r, step + 1)
        if x is None or y is None:
            lost += 1
            continue
        dx.append(x - x0)
        dy.append(y - y0)
    if len(dx) < 3:
        raise RuntimeError(f"{lost} of {kicks} kicks ended the walk before touchdown {step + 1}: use smaller kicks")
    dx, dy = np.array(dx), np.array(dy)
    jac = least_squares_map(dx, dy)
    res = dy - dx @ jac.T
    eig = np.linalg.eigvals(jac)

    return {
        "jacobian": jac.tolist(),
        "eigenvalues": complex_list(eig),
        "spectral_radius": float(np.max(np.abs(eig))),
        "section_state": x0.tolist(),
        "next_section_state": y0.tolist(),
        "step": step,
        "kick_time_s": t_kick,
        "angle_rad": angle_rad,
        "rate_radps": rate_radps,
        "lead_s": lead_s,
        "kicks": kicks,
        "kicks_lost": lost,
        "relative_residual": float(np.linalg.norm(res) / max(np.linalg.norm(dy), 1e-300)),
        "dx_condition_number": float(np.linalg.cond(dx)),
    }


def run(settings: StabilitySettings, out: Path, client=None, progress: bool = True) -> dict[str, Any]:
    """The six cells and the Jacobians of the settings' gait (the default gait when None) on `client` (a
    LocalCluster when None), with a progress bar; writes episodes/, stability.json, fig7_return_map.png,
    report.md and report.html into `out`. `settings.floquet`: also the periodic orbit's Floquet multipliers
    without and with the window (common/floquet_runs.py; floquet_without/, floquet_with/ and a report
    section). The record."""
    check_settings(settings, StabilitySettings, "stability.run")
    settings.check_walks_reach()
    from drake_biped.analysis.stability_report import write_stability_outputs
    from drake_biped.common.executor import client_or_local
    from drake_biped.common.progress import progress_bar
    from drake_biped.records import write_atomic

    out = Path(out)
    config = settings.config or EpisodeConfig()
    with client_or_local(client) as c:
        with progress_bar(6 * settings.trials, "stability", "episode", progress) as tick:
            record = run_stability(out, config, settings, c, tick,
                                   jacobian_kicks=settings.jacobian_kicks)
        if settings.floquet:  # (the finite-difference Jacobian's episodes follow the cells, without a bar)
            record["floquet"] = _floquet(config, settings.window, out, c)
    if settings.window_source is not None:
        record["window_source"] = settings.window_source
    write_atomic(out / "stability.json", record)
    write_stability_outputs(record, out)
    return record


def _floquet(config: EpisodeConfig, window: tuple[float, float], out: Path, client) -> dict[str, Any]:
    """The Floquet analysis (common/floquet_runs.py) without and with the window, into floquet_CONDITION/;
    what the report shows of each."""
    from drake_biped.analysis.floquet_report import markdown
    from drake_biped.common import floquet_runs as floquet

    found = {}
    for condition in CONDITIONS:
        gait = config.replace(window=condition_window(condition, window))
        f = floquet.run(floquet.FloquetSettings(gait), out / f"floquet_{condition}", client)
        found[condition] = {k: f[k] for k in ("spectral_radius", "multipliers", "converged_epsilon",
                                              "fixed_point_residual")}
        found[condition]["markdown"] = markdown(f)
    return found


COMMAND = "stability"
# Rerunning the command on the same --out resumes it from its records, and these counts may be given larger to extend the run (never smaller).
RESUMABLE = True
GROWABLE = ("trials",)
PARSER = dict(help="pushes and Poincare return maps with and without a torque-free "
              "period (Table VI, Fig. 7), on Dask")


def add_arguments(p: argparse.ArgumentParser) -> None:
    """`drake-biped stability`'s options."""
    add_episode_options(p)
    add_window_options(p)
    p.add_argument("--trials", type=count, default=8, help="trials per cell")
    p.add_argument("--push", type=number("positive"), default=20.0, help="push force (N)")
    p.add_argument("--floquet", action="store_true",
                   help="also the periodic orbit's Floquet multipliers without and with the window (about a "
                   "minute each on 2 cores), in the report beside the regression")
    p.add_argument("--spread", type=number("nonnegative"), default=0.15,
                   help="trials' initial hip angle and speed within +-this fraction (default 0.15)")
    add_resumable_run_options(p)


def settings_from_args(args: argparse.Namespace) -> StabilitySettings:
    """The stability study's settings from the command's options."""
    config = episode_config(args)
    window, source = chosen_window_and_source(args, config)
    settings = StabilitySettings(window=window, trials=args.trials, push_force_n=args.push,
                                 spread=args.spread, seed=config.seed, config=config, floquet=args.floquet,
                                 force=args.force, window_source=source)
    settings.check_walks_reach()
    print(window_line(window, source))
    return settings


def command(args: argparse.Namespace) -> int:
    """Run the command of `args` (its options parsed by add_arguments); the exit code."""
    run_command(args, settings_from_args, run)
    out = Path(args.out)
    print("\n".join(line for line in (out / "report.md").read_text().splitlines() if line.startswith("|")))
    print(f"wrote {out}/stability.json, fig7_return_map.png, report.md, report.html")
    return 0
